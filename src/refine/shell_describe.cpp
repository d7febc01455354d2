// Stage 5, selection: the data for the program, what each candidate face is (shell_describe.h).
#include "shell_describe.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/refine/objective.h"
#include "occupancy.h"

namespace lodrefine::detail {
namespace {

// A parallel scanned facade at most this far (m) from a model face (in front or behind) says the
// facade is there, not on the model face: the scan saw past it, or it lies inside the building.
constexpr double kSeeThrough = 3.0;
// Planes of the starting shell within kSurfaceAngleDeg and kSurfaceDistance are one supporting
// plane (matching.h: the tolerance of a model surface).

// PolyFit's data-fitting term (its compute_confidences' supporting points): the scan points of
// a candidate's supporting plane that lie within it, each weighted by how well it fits that
// plane (objective.h: fit_weight within fit_tolerance). Counted
// as the area they stand for: the scanned area (kOccupancyCell cells holding a point, over all planes)
// over the points, so a candidate explaining its share of an evenly sampled scan is worth about
// its area, a sparsely sampled one less: PolyFit's share of the points, in the coverage term's
// units (m²) rather than the box's.
//
// Per plane: its points in the plane's frame, their fit weights, and the points in each kOccupancyCell
// cell; and the scanned area each point stands for (m²).
struct FitPoints {
  std::vector<std::vector<Vec2>> at;
  std::vector<std::vector<double>> weight;
  std::vector<std::unordered_map<std::int64_t, std::vector<int>>> cells;
  double area_per_point = 0.0;
};

FitPoints fit_points(const Supports& s, const std::vector<Frame2>& frames, const RefineConfig& prm) {
  FitPoints fp;
  const int np = int(s.planes.size());
  fp.at.resize(np), fp.weight.resize(np), fp.cells.resize(np);
  const double tol = fit_tolerance(prm);
  long long points = 0, occupied = 0;
  for (int k = 0; k < np; ++k) {
    for (const auto& p : s.points[k]) {
      const Vec2 q = frames[k](p);
      fp.cells[k]
              [cell_key((long long)std::floor(q.x() / kOccupancyCell), (long long)std::floor(q.y() / kOccupancyCell))]
                  .push_back(int(fp.at[k].size()));
      fp.at[k].push_back(q);
      fp.weight[k].push_back(fit_weight(s.planes[k].plane.distance(p), tol));
    }
    points += (long long)s.points[k].size();
    occupied += (long long)fp.cells[k].size();
  }
  if (points > 0) fp.area_per_point = double(occupied) * kOccupancyCell * kOccupancyCell / double(points);
  return fp;
}

// The area (m²) of the points of plane k within the convex polygon `poly` (its frame).
double fitted_area(const FitPoints& fp, int k, const std::vector<Vec2>& poly) {
  if (fp.at[k].empty()) return 0.0;
  double sum = 0.0;
  for_box_cells(poly, [&](long long i, long long j) {
    const auto it = fp.cells[k].find(cell_key(i, j));
    if (it == fp.cells[k].end()) return;
    for (int idx : it->second)
      if (point_in_polygon_2d(fp.at[k][idx], poly)) sum += fp.weight[k][idx];
  });
  return sum * fp.area_per_point;
}

}  // namespace

FaceProps describe_candidates(CandidateSet& cs, const Mesh& start, const Supports& s, const RefineConfig& prm) {
  const int np = int(s.planes.size());
  std::vector<Frame2> frames;
  for (const auto& sp : s.planes) frames.push_back(frame_of(sp.plane, cs.region.center));
  // Own occupancy and the cells where another parallel scanned facade lies near.
  std::vector<CellSet> own(np), other(np);
  for (int k = 0; k < np; ++k) mark_scanned(own[k], s.points[k], frames[k]);
  for (int k = 0; k < np; ++k) {
    if (!near_vertical(s.planes[k].plane, prm.plane.facade_max_tilt_deg)) continue;
    for (int j = 0; j < np; ++j) {
      if (j == k || s.points[j].empty() ||
          unoriented_angle_deg(s.planes[k].plane.n, s.planes[j].plane.n) > prm.selection.merge_angle_deg)
        continue;
      double sum = 0.0;
      for (const auto& p : s.points[j]) sum += std::abs(s.planes[k].plane.distance(p));
      const double d = sum / double(s.points[j].size());
      if (d <= prm.selection.merge_distance || d > kSeeThrough) continue;
      mark_scanned(other[k], s.points[j], frames[k]);
    }
  }
  // The start's faces per plane, in that plane's frame.
  std::vector<std::vector<std::pair<int, std::vector<Vec2>>>> start_faces(np);
  for (int f = 0; f < int(start.faces.size()); ++f) {
    const int k = s.face_plane[f];
    if (k < 0) continue;
    std::vector<Vec2> poly;
    for (int v : start.faces[f].v) poly.push_back(frames[k](start.vertices[v]));
    start_faces[k].emplace_back(f, std::move(poly));
  }
  // The evidence zone: each scanned plane's points' box (region axes), grown horizontally by the
  // reach of the evidence (a wall the scan moves takes the roof edge above it along: the zone
  // spans the whole height). Candidates with a vertex in it are free; the others stay as the
  // starting shell has them (the program grows with the region: keep it to the evidence).
  const double margin = prm.scan_reach();
  std::vector<Eigen::AlignedBox3d> zones;
  for (const auto& pts : s.points) {
    if (pts.empty()) continue;
    Eigen::AlignedBox3d b;
    for (const auto& p : pts) b.extend(cs.region.axes.transpose() * p);
    const Vec3 grow(margin, margin, std::numeric_limits<double>::infinity());
    zones.emplace_back(b.min() - grow, b.max() + grow);
  }

  FaceProps props = FaceProps::add(cs.mesh);
  auto& in_start = props.in_start;
  auto& source = props.source;
  auto& confidence = props.confidence;
  auto& in_zone = props.in_zone;
  auto& fit = props.fit;
  const FitPoints fp = fit_points(s, frames, prm);
  const auto support = cs.supports();
  const auto centroid = cs.centroids();
  for (int f = 0; f < cs.size(); ++f) {
    const FaceIndex fi(f);
    const int k = support[fi];
    const std::vector<int> corners = cs.corners(f);
    std::vector<Vec2> poly;
    for (int v : corners) poly.push_back(frames[k](cs.vertices[v]));
    const Vec2 c = frames[k](centroid[fi]);
    for (const auto& [sf, sp] : start_faces[k])
      if (point_in_polygon_2d(c, sp)) {
        in_start[fi] = true;
        source[fi] = start.faces[sf].source;
        break;
      }
    const double contradicted = in_start[fi] ? scanned_share(poly, other[k]) : 0.0;
    confidence[fi] = face_confidence(scanned_share(poly, own[k]), contradicted, in_start[fi]);
    // On a plane of the starting shell only its own faces are credited: points running on along
    // it past its outline are no evidence that it runs on (a flush neighbour's facade; corners.h).
    if (s.planes[k].from_scan || in_start[fi]) fit[fi] = fitted_area(fp, k, poly);
    std::vector<Vec3> pts{centroid[fi]};
    for (int v : corners) pts.push_back(cs.vertices[v]);
    bool reached = false;
    for (const auto& z : zones)
      for (const auto& p : pts) reached = reached || z.contains(cs.region.axes.transpose() * p);
    in_zone[fi] = reached;
  }
  return props;
}

}  // namespace lodrefine::detail
