// The paper's evaluation metrics, on the core's point-to-mesh distances.
#include "lodrefine/eval/eval.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"

namespace lodrefine {

namespace {

// Shared vertices for identical coordinates; consecutive repeats and collapsed faces dropped.
Mesh weld_identical(const Mesh& mesh) {
  Mesh out;
  out.id = mesh.id;
  std::map<std::array<double, 3>, int> index;
  std::vector<int> remap(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    const auto [it, inserted] = index.emplace(std::array<double, 3>{v.x(), v.y(), v.z()}, int(out.vertices.size()));
    if (inserted) out.vertices.push_back(v);
    remap[i] = it->second;
  }
  for (const Face& f : mesh.faces) {
    Face g = f;
    for (int& v : g.v) v = remap.at(v);
    drop_repeats(g.v);
    if (g.v.size() >= 3) out.faces.push_back(std::move(g));
  }
  return out;
}

Vec3 area_centroid(const Mesh& mesh) {
  Vec3 acc = Vec3::Zero();
  double area = 0.0;
  const Vec3 o = mesh.vertices.empty() ? Vec3::Zero() : mesh.vertices.front();
  for_each_triangle(mesh, [&](const Vec3& a, const Vec3& b, const Vec3& c, int) {
    const double w = 0.5 * (b - a).cross(c - a).norm();
    acc += w * ((a - o) + (b - o) + (c - o)) / 3.0;
    area += w;
  });
  return area > 0 ? Vec3(o + acc / area) : o;
}

// Signed tetrahedra against the first vertex; orientation-independent as long as it is
// consistent. nullopt for a (near) zero volume.
std::optional<Vec3> volume_centroid(const Mesh& mesh) {
  if (mesh.vertices.empty()) return std::nullopt;
  const Vec3 o = mesh.vertices.front();
  Vec3 acc = Vec3::Zero();
  double vol = 0.0;
  for_each_triangle(mesh, [&](const Vec3& a, const Vec3& b, const Vec3& c, int) {
    const double v = (a - o).dot((b - o).cross(c - o)) / 6.0;
    acc += v * ((a - o) + (b - o) + (c - o)) / 4.0;
    vol += v;
  });
  if (std::abs(vol) < 1e-9) return std::nullopt;
  return Vec3(o + acc / vol);
}

// c_init / c_ref: the volume centroid; an open model (typical for exported originals) is
// measured as the volume it describes, i.e. after repair, before falling back to its area.
Vec3 model_centroid(const Mesh& mesh, const RepairConfig& params) {
  if (is_watertight(mesh))
    if (auto c = volume_centroid(mesh)) return *c;
  try {
    const Mesh repaired = repair_model(mesh, params.weld_tolerance);
    if (is_watertight(repaired))
      if (auto c = volume_centroid(repaired)) return *c;
  } catch (const InputError&) {
  }
  return area_centroid(mesh);
}

Vec3 mean_point(const std::vector<Vec3>& pts) {
  Vec3 c = Vec3::Zero();
  for (const auto& p : pts) c += p;
  return pts.empty() ? c : Vec3(c / double(pts.size()));
}

std::vector<int> faces_with(const Mesh& mesh, Semantic sem) {
  std::vector<int> out;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    if (mesh.faces[f].sem == sem) out.push_back(int(f));
  return out;
}

// Points sampled on the truth's scanned walls and on its roofs.
struct TruthSamples {
  std::vector<Vec3> facade, roof;
};

TruthSamples truth_samples(const Mesh& truth, const std::vector<Vec3>& facade_pts, const std::vector<int>* scanned,
                           std::vector<int>& scanned_out) {
  scanned_out = scanned ? *scanned : scanned_walls(truth, facade_pts);
  for (int f : scanned_out)
    if (f < 0 || std::size_t(f) >= truth.faces.size())
      throw InputError("scanned truth face " + std::to_string(f) + " is not a face of the truth model");
  constexpr double kSpacing = 0.1;  // 100 samples per m²: dense enough for cm-level statistics
  return {sample_faces(truth, scanned_out, kSpacing), sample_faces(truth, faces_with(truth, Semantic::Roof), kSpacing)};
}

std::optional<DistanceStats> stats_if_any(const std::vector<double>& d) {
  if (d.empty()) return std::nullopt;
  return summarize_distances(d);
}

// Fills the "after" side: C2M, watertightness, centroid and truth distances of the refined model.
void evaluate_refined(BuildingEval& e, const Mesh& refined, const std::vector<Vec3>& pts, const TruthSamples* samples,
                      const RepairConfig& params) {
  if (refined.faces.empty()) throw InputError("refined model has no faces");
  if (!pts.empty()) e.c2m_after = cloud_to_mesh(refined, pts);
  e.after = summarize_distances(e.c2m_after);
  e.watertight_after = is_watertight(refined);
  e.c_ref = model_centroid(refined, params);
  if (!pts.empty()) e.delta_d = (e.c_mls - e.c_init).norm() - (e.c_mls - e.c_ref).norm();
  if (!samples) return;
  e.truth_facade_d_after = unsigned_distances(refined, samples->facade);
  e.truth_roof_d_after = unsigned_distances(refined, samples->roof);
  e.truth_facade_after = stats_if_any(e.truth_facade_d_after);
  e.truth_roof_after = stats_if_any(e.truth_roof_d_after);
}

DistanceStats average_stats(const std::vector<const DistanceStats*>& all) {
  DistanceStats m;
  if (all.empty()) return m;
  for (const auto* s : all) {
    m.count += s->count;
    m.rmse += s->rmse, m.mae += s->mae, m.mean += s->mean, m.std += s->std;
    m.median += s->median, m.p95 += s->p95, m.max_abs += s->max_abs;
  }
  const double n = double(all.size());
  m.rmse /= n, m.mae /= n, m.mean /= n, m.std /= n, m.median /= n, m.p95 /= n, m.max_abs /= n;
  return m;
}

}  // namespace

double percentile_sorted(const std::vector<double>& s, double q) {
  if (s.empty()) return 0.0;
  const double pos = q * double(s.size() - 1);
  const std::size_t lo = std::size_t(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, s.size() - 1);
  return s[lo] + (pos - double(lo)) * (s[hi] - s[lo]);
}

double percentile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const double pos = q * double(values.size() - 1);
  const std::size_t lo = std::size_t(std::floor(pos));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(lo), values.end());
  const double a = values[lo];
  const double b =
      lo + 1 < values.size() ? *std::min_element(values.begin() + std::ptrdiff_t(lo) + 1, values.end()) : a;
  return a + (pos - double(lo)) * (b - a);
}

DistanceStats summarize_distances(const std::vector<double>& d) {
  DistanceStats s;
  s.count = d.size();
  if (d.empty()) return s;
  double sum = 0, sum_abs = 0, sum_sq = 0;
  std::vector<double> abs_d(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    sum += d[i];
    sum_abs += std::abs(d[i]);
    sum_sq += d[i] * d[i];
    abs_d[i] = std::abs(d[i]);
    s.max_abs = std::max(s.max_abs, abs_d[i]);
  }
  const double n = double(d.size());
  s.mean = sum / n;
  s.mae = sum_abs / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0;  // two-pass: stable for small spreads around a large mean
  for (double x : d) var += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(var / n);
  std::vector<double> values = d;
  s.median = percentile(values, 0.5);
  s.p95 = percentile(abs_d, 0.95);
  return s;
}

Vec3 mesh_centroid(const Mesh& mesh) {
  if (is_watertight(mesh))
    if (auto c = volume_centroid(mesh)) return *c;
  return area_centroid(mesh);
}

bool is_watertight(const Mesh& mesh) {
  const Mesh welded = weld_identical(mesh);
  if (welded.faces.size() < 4) return false;
  // Planarity and self-intersections are not part of the paper's definition.
  const Validation v = validate_mesh(welded, std::numeric_limits<double>::max(), false);
  return v.watertight() && v.inconsistent_edges == 0;
}

std::vector<int> scanned_walls(const Mesh& truth, const std::vector<Vec3>& points, double distance, int min_points) {
  if (points.empty()) return {};
  const MeshDistance index(truth);
  std::vector<int> count(truth.faces.size(), 0);
  for (const auto& hit : index.nearest_all(points))
    if (hit.distance <= distance) ++count[std::size_t(hit.face)];
  std::vector<int> out;
  for (std::size_t f = 0; f < truth.faces.size(); ++f)
    if (truth.faces[f].sem == Semantic::Wall && count[f] >= min_points) out.push_back(int(f));
  return out;
}

// m: the facade points of a matched wall are its scan plane's inliers in front of it, grown by
// this in its plane (a plane may run on along a flush neighbour; the value matching used to
// share through --corner-gap, now the evaluation's own so tuning matching leaves it alone).
constexpr double kFacadeMargin = 0.6;

std::vector<int> select_facade_points(const Mesh& input, const PointCloud& cloud, const RefineConfig& prm) {
  Mesh mesh = input;
  try {
    mesh = repair_model(input, prm.repair.weld_tolerance);
  } catch (const InputError&) {
    // No closed shell: the soup's own faces still say where its walls are.
  }
  const auto planes = detect_planes(cloud, prm.plane);
  const auto surfaces = model_surfaces(mesh);
  const auto matched = match_surfaces(mesh, surfaces, cloud, planes, prm.match);
  return points_in_front(mesh, surfaces, planes, matched, cloud, kFacadeMargin);
}

BuildingEval evaluate_building(const Mesh& original, const Mesh& refined, const PointCloud& cloud, const Mesh* truth,
                               const RefineConfig& params) {
  return evaluate_building(original, refined, cloud, truth, params, nullptr);
}

BuildingEval evaluate_building(const Mesh& original, const Mesh& refined, const PointCloud& cloud, const Mesh* truth,
                               const RefineConfig& params, const std::vector<int>* scanned_truth_faces) {
  BuildingEval e;
  e.id = original.id.empty() ? refined.id : original.id;
  e.facade_index = select_facade_points(original, cloud, params);
  std::vector<Vec3> pts;
  pts.reserve(e.facade_index.size());
  for (int i : e.facade_index) pts.push_back(cloud.points.at(std::size_t(i)));
  e.facade_points = pts.size();
  e.c_mls = mean_point(pts);
  e.delta_d = std::numeric_limits<double>::quiet_NaN();

  if (!pts.empty()) e.c2m_before = cloud_to_mesh(original, pts);
  e.before = summarize_distances(e.c2m_before);
  e.watertight_before = is_watertight(original);
  e.c_init = model_centroid(original, params.repair);

  std::optional<TruthSamples> samples;
  if (truth) {
    samples = truth_samples(*truth, pts, scanned_truth_faces, e.scanned_truth_faces);
    e.truth_facade_d_before = unsigned_distances(original, samples->facade);
    e.truth_roof_d_before = unsigned_distances(original, samples->roof);
    e.truth_facade_before = stats_if_any(e.truth_facade_d_before);
    e.truth_roof_before = stats_if_any(e.truth_roof_d_before);
  }
  try {
    evaluate_refined(e, refined, pts, samples ? &*samples : nullptr, params.repair);
  } catch (const InputError& err) {
    e.error = err.what();
    e.watertight_after = false;
  }
  return e;
}

void PooledSeries::add(const BuildingEval& b) {
  if (!b.ok()) return;
  if (b.facade_points > 0) c2m_before.add(b.c2m_before), c2m_after.add(b.c2m_after);
  truth_facade_before.add(b.truth_facade_d_before), truth_facade_after.add(b.truth_facade_d_after);
  truth_roof_before.add(b.truth_roof_d_before), truth_roof_after.add(b.truth_roof_d_after);
}

void PooledSeries::merge(const PooledSeries& o) {
  c2m_before.merge(o.c2m_before), c2m_after.merge(o.c2m_after);
  truth_facade_before.merge(o.truth_facade_before), truth_facade_after.merge(o.truth_facade_after);
  truth_roof_before.merge(o.truth_roof_before), truth_roof_after.merge(o.truth_roof_after);
}

void drop_series(BuildingEval& b) {
  for (auto* v : {&b.c2m_before, &b.c2m_after, &b.truth_facade_d_before, &b.truth_facade_d_after,
                  &b.truth_roof_d_before, &b.truth_roof_d_after})
    std::vector<double>().swap(*v);
  std::vector<int>().swap(b.facade_index);
}

PooledEval pool_evaluations(const std::vector<BuildingEval>& buildings, const PooledSeries& series) {
  PooledEval p;
  p.buildings = buildings.size();
  std::vector<double> delta;
  std::vector<const DistanceStats*> per_before, per_after;
  std::size_t wt_before = 0, wt_after = 0;
  for (const auto& b : buildings) {
    wt_before += b.watertight_before;
    wt_after += b.ok() && b.watertight_after;
    if (!b.ok()) {
      ++p.failed;
      continue;
    }
    if (b.truth_facade_before || b.truth_roof_before) ++p.truth_buildings;
    if (b.facade_points == 0) continue;
    ++p.evaluated;
    per_before.push_back(&b.before), per_after.push_back(&b.after);
    if (std::isfinite(b.delta_d)) delta.push_back(b.delta_d);
  }
  p.before = pooled_stats(per_before, series.c2m_before);
  p.after = pooled_stats(per_after, series.c2m_after);
  p.mean_before = average_stats(per_before), p.mean_after = average_stats(per_after);
  if (!delta.empty()) {
    const DistanceStats s = summarize_distances(delta);
    p.delta_d_mean = s.mean, p.delta_d_median = s.median;
  }
  if (p.buildings > 0) {
    p.watertight_rate_before = double(wt_before) / double(p.buildings);
    p.watertight_rate_after = double(wt_after) / double(p.buildings);
  }
  // Truth samples of every building measured with both models.
  auto truth = [&](std::optional<DistanceStats> BuildingEval::*part, const DistanceHistogram& h) {
    std::vector<const DistanceStats*> parts;
    for (const auto& b : buildings)
      if (b.ok() && b.*part) parts.push_back(&*(b.*part));
    return h.count() ? std::optional(pooled_stats(parts, h)) : std::nullopt;
  };
  p.truth_facade_before = truth(&BuildingEval::truth_facade_before, series.truth_facade_before);
  p.truth_facade_after = truth(&BuildingEval::truth_facade_after, series.truth_facade_after);
  p.truth_roof_before = truth(&BuildingEval::truth_roof_before, series.truth_roof_before);
  p.truth_roof_after = truth(&BuildingEval::truth_roof_after, series.truth_roof_after);
  return p;
}

PooledEval pool_evaluations(const std::vector<BuildingEval>& buildings) {
  PooledSeries series;
  for (const auto& b : buildings) series.add(b);
  return pool_evaluations(buildings, series);
}

}  // namespace lodrefine
