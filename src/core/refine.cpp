// The pipeline (paper Sec. 3): repair -> planes -> matching -> per outdated wall a local
// candidate arrangement, confidence and GLPK selection -> validated closed shell.
#include "lodrefine/core/refine.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <optional>
#include <set>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/confidence.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/selection.h"
#include "lodrefine/core/substitute.h"
#include "lodrefine/core/corners.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/validate.h"

namespace lodrefine {
namespace {

namespace bg = boost::geometry;
using BPoint = bg::model::d2::point_xy<double>;
using BPolygon = bg::model::polygon<BPoint, false, false>;  // CCW, open
using BMulti = bg::model::multi_polygon<BPolygon>;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Moves each vertex onto the meet of the planes of its surfaces (least squares), so that the
// model is exactly consistent with the planes the arrangement uses. Moves beyond `max_move`
// (a warped input face) are not made.
void snap_to_surfaces(Mesh& mesh, const std::vector<ModelSurface>& surfaces, double max_move) {
  std::vector<std::vector<int>> vertex_surfaces(mesh.vertices.size());
  for (int s = 0; s < int(surfaces.size()); ++s)
    for (int f : surfaces[s].faces)
      for (int v : mesh.faces[f].v)
        if (vertex_surfaces[v].empty() || vertex_surfaces[v].back() != s) vertex_surfaces[v].push_back(s);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    auto& ss = vertex_surfaces[v];
    std::sort(ss.begin(), ss.end());
    ss.erase(std::unique(ss.begin(), ss.end()), ss.end());
    if (ss.empty()) continue;
    // Minimise |x - p|^2 * eps + sum (n.x + d)^2: the small regulariser picks the nearest
    // point when fewer than three independent planes meet here.
    Eigen::Matrix3d a = 1e-9 * Eigen::Matrix3d::Identity();
    Vec3 b = 1e-9 * mesh.vertices[v];
    for (int s : ss) {
      const Plane& pl = surfaces[s].plane;
      a += pl.n * pl.n.transpose();
      b -= pl.d * pl.n;
    }
    const Vec3 x = a.fullPivLu().solve(b);
    if (x.allFinite() && (x - mesh.vertices[v]).norm() <= max_move) mesh.vertices[v] = x;
  }
}

// Sutherland–Hodgman of a 3D polygon against the region (area test only).
double area_inside(std::vector<Vec3> poly, const Region& r) {
  for (const auto& pl : r.planes()) {
    std::vector<Vec3> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec3& p = poly[i];
      const Vec3& q = poly[(i + 1) % poly.size()];
      const double dp = pl.distance(p), dq = pl.distance(q);
      if (dp <= 0) out.push_back(p);
      if ((dp < 0) != (dq < 0) && dp != dq) out.push_back(p + (q - p) * (dp / (dp - dq)));
    }
    poly.swap(out);
    if (poly.size() < 3) return 0.0;
  }
  return polygon_area(poly);
}

// Everything one wall replacement needs and produces.
struct Replacement {
  std::vector<int> surfaces;  // model surfaces replaced by the scan plane
  Plane plane;                // the scan plane, oriented like the wall (outward)
  std::vector<Vec3> points;   // its inliers
};

Region replacement_region(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const Replacement& rep,
                          const Params& prm) {
  const auto [u, v] = rep.plane.basis();
  Eigen::Matrix3d axes;
  axes.col(0) = u;
  axes.col(1) = v;
  axes.col(2) = rep.plane.n;
  std::vector<Vec3> pts;
  for (int s : rep.surfaces)
    for (int f : surfaces[s].faces)
      for (int vi : mesh.faces[f].v) {
        pts.push_back(mesh.vertices[vi]);
        pts.push_back(rep.plane.project(mesh.vertices[vi]));
      }
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& p : pts) {
    const Vec3 q = axes.transpose() * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Vec3 ext = hi - lo;
  Vec3 margin;
  margin.x() = std::max(prm.bbox_margin, prm.bbox_expand * ext.x());
  margin.y() = std::max(prm.bbox_margin, prm.bbox_expand * ext.y());
  margin.z() = prm.bbox_margin;
  Region r;
  r.axes = axes;
  Vec3 qlo = lo - margin, qhi = hi + margin;
  // Keep the model's vertices off the region's faces, and the points where its edges cross a
  // face off the region's edges: no model feature may run (almost) along the boundary, or
  // slivers make the outside surface ambiguous there.
  std::vector<std::pair<Vec3, Vec3>> edges;
  for (const auto& f : mesh.faces)
    for (std::size_t k = 0; k < f.v.size(); ++k)
      edges.emplace_back(axes.transpose() * mesh.vertices[f.v[k]], axes.transpose() * mesh.vertices[f.v[(k + 1) % f.v.size()]]);
  constexpr double kClear = 0.02, kStep = 0.05;
  auto near_bound = [&](const Vec3& q, int k) {  // pushes the bound of axis k that q is close to
    if (std::abs(q[k] - qlo[k]) < kClear) { qlo[k] -= kStep; return true; }
    if (std::abs(q[k] - qhi[k]) < kClear) { qhi[k] += kStep; return true; }
    return false;
  };
  for (int iter = 0; iter < 60; ++iter) {
    bool moved = false;
    for (const auto& [a, b] : edges)
      for (int k = 0; k < 3; ++k) {
        moved = near_bound(a, k) || moved;
        for (double bound : {qlo[k], qhi[k]}) {
          if ((a[k] - bound) * (b[k] - bound) >= 0) continue;
          const Vec3 x = a + (b - a) * ((bound - a[k]) / (b[k] - a[k]));
          for (int j = 0; j < 3; ++j)
            if (j != k) moved = near_bound(x, j) || moved;
        }
      }
    if (!moved) break;
  }
  r.center = axes * (0.5 * (qlo + qhi));
  r.half = 0.5 * (qhi - qlo);
  return r;
}

struct StepResult {
  bool ok = false;
  std::string reason;
  Mesh mesh;
  json info;
};

// Polygon minus the region's section, in the polygon's plane; false if a hole would appear.
bool subtract_region(const std::vector<Vec3>& poly, const Plane& plane, const Region& r,
                     std::vector<std::vector<Vec3>>& pieces) {
  const auto section = region_section(plane, r);
  if (section.size() < 3) {
    pieces.push_back(poly);
    return true;
  }
  const auto uv = plane.basis();  // named, not bound: clang-14 lambdas cannot capture bindings
  const Vec3 u = uv.first, v = uv.second;
  const Vec3 o = plane.project(poly.front());
  auto to2 = [&](const std::vector<Vec3>& pts) {
    BPolygon bp;
    for (const auto& p : pts) bp.outer().emplace_back((p - o).dot(u), (p - o).dot(v));
    bg::correct(bp);
    return bp;
  };
  BMulti out;
  bg::difference(to2(poly), to2(section), out);
  for (const auto& bp : out) {
    if (!bp.inners().empty()) return false;
    std::vector<Vec3> piece;
    for (const auto& q : bp.outer()) piece.push_back(o + q.x() * u + q.y() * v);
    if (piece.size() >= 3 && polygon_area(piece) > 1e-8) pieces.push_back(std::move(piece));
  }
  return true;
}

StepResult replace_walls(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, Replacement rep,
                         const Params& prm) {
  StepResult res;
  const auto t0 = Clock::now();

  // Model walls that the scan plane makes coplanar with it are replaced together.
  Region region = replacement_region(mesh, surfaces, rep, prm);
  for (int iter = 0; iter < 3; ++iter) {
    bool grew = false;
    for (int s = 0; s < int(surfaces.size()); ++s) {
      if (surfaces[s].sem != Semantic::Wall ||
          std::find(rep.surfaces.begin(), rep.surfaces.end(), s) != rep.surfaces.end())
        continue;
      if (unoriented_angle_deg(surfaces[s].plane.n, rep.plane.n) > prm.merge_angle_deg) continue;
      bool near = true, inside = false;
      for (int f : surfaces[s].faces) {
        for (int vi : mesh.faces[f].v) near = near && std::abs(rep.plane.distance(mesh.vertices[vi])) <= prm.merge_distance;
        inside = inside || area_inside(face_points(mesh, mesh.faces[f]), region) > 1e-8;
      }
      if (near && inside) {
        rep.surfaces.push_back(s);
        grew = true;
      }
    }
    if (!grew) break;
    region = replacement_region(mesh, surfaces, rep, prm);
  }
  const std::set<int> replaced(rep.surfaces.begin(), rep.surfaces.end());
  std::set<int> replaced_faces;
  for (int s : rep.surfaces) replaced_faces.insert(surfaces[s].faces.begin(), surfaces[s].faces.end());

  // Supporting planes: the scan plane and every kept surface reaching into the region.
  std::vector<SupportPlane> planes{{rep.plane, Semantic::Wall, true, -1}};
  std::vector<int> face_plane(mesh.faces.size(), -1);
  std::vector<char> face_in_region(mesh.faces.size(), 0);
  for (int f = 0; f < int(mesh.faces.size()); ++f)
    face_in_region[f] = !replaced_faces.count(f) && area_inside(face_points(mesh, mesh.faces[f]), region) > 1e-8;
  for (int s = 0; s < int(surfaces.size()); ++s) {
    if (replaced.count(s)) continue;
    bool in = false;
    for (int f : surfaces[s].faces) in = in || face_in_region[f];
    if (!in) continue;
    // Surfaces on the very same plane (split by other faces, or a repaired hole labelled
    // otherwise) share one supporting plane, named after the larger surface.
    int idx = -1;
    for (int k = 1; k < int(planes.size()) && idx < 0; ++k)
      if (planes[k].plane.n.dot(surfaces[s].plane.n) > 1.0 - 1e-9 && std::abs(planes[k].plane.d - surfaces[s].plane.d) < 1e-6)
        idx = k;
    if (idx < 0) {
      idx = int(planes.size());
      planes.push_back({surfaces[s].plane, surfaces[s].sem, false, s});
    } else if (surfaces[s].area > surfaces[planes[idx].source].area) {
      planes[idx].sem = surfaces[s].sem;
      planes[idx].source = s;
    }
    for (int f : surfaces[s].faces) face_plane[f] = idx;
  }

  const CandidateSet cs = build_candidates(planes, region);
  res.info["supporting_planes"] = planes.size();
  res.info["candidates"] = cs.faces.size();
  res.info["edges"] = cs.edges.size();

  // Boundary edges: does the kept surface continue outside the region across them?
  std::vector<int> outside(cs.edges.size(), 0);
  const auto box = region.planes();
  for (int e = 0; e < int(cs.edges.size()); ++e) {
    const auto& edge = cs.edges[e];
    if (edge.box_plane < 0) continue;
    std::set<int> edge_planes;
    for (int f : edge.faces) edge_planes.insert(cs.faces[f].plane);
    const Vec3 a = cs.vertices[edge.a], b = cs.vertices[edge.b];
    for (int pi : edge_planes) {
      const Plane& pl = cs.planes[pi].plane;
      Vec3 t = pl.n.cross(b - a);
      if (t.norm() < 1e-12) continue;
      t.normalize();
      const double along = t.dot(box[edge.box_plane].n);
      if (std::abs(along) < 1e-3) continue;
      if (along < 0) t = -t;
      const Vec3 q = 0.5 * (a + b) + 0.01 * t;
      const auto [u, v] = pl.basis();
      const Vec2 q2((q - a).dot(u), (q - a).dot(v));
      for (int f = 0; f < int(mesh.faces.size()); ++f) {
        if (face_plane[f] != pi) continue;
        std::vector<Vec2> poly2;
        for (int vi : mesh.faces[f].v) poly2.emplace_back((mesh.vertices[vi] - a).dot(u), (mesh.vertices[vi] - a).dot(v));
        if (point_in_polygon_2d(q2, poly2)) {
          ++outside[e];
          break;
        }
      }
    }
  }

  // Confidence against the kept model faces near the region and the scan plane's points.
  std::vector<ModelReference> model_refs;
  Region near_region = region;
  near_region.half += Vec3::Constant(prm.conf_model_distance);
  for (int f = 0; f < int(mesh.faces.size()); ++f)
    if (!replaced_faces.count(f) && area_inside(face_points(mesh, mesh.faces[f]), near_region) > 1e-8)
      model_refs.push_back({face_points(mesh, mesh.faces[f])});
  CloudReference cloud_ref;
  for (const auto& p : rep.points)
    if (region.contains(p)) cloud_ref.points.push_back(p);
  const auto conf = candidate_confidence(cs, model_refs, {cloud_ref}, prm);
  std::vector<double> cost(cs.faces.size());
  for (std::size_t f = 0; f < cs.faces.size(); ++f) cost[f] = coverage_cost(cs.faces[f].area, conf[f].value, prm.tau_cov);

  // Only the slab between the old and the new wall changes: outside it, candidates that the
  // kept model fully covers stay and unsupported ones stay out. Fixing them leaves the solver
  // the slab alone, which keeps regions crossed by many roof planes tractable.
  std::vector<int> fixed(cs.faces.size(), -1);
  constexpr double kSlabTolerance = 0.05;
  auto in_slab = [&](const Vec3& x) {
    const double dp = rep.plane.distance(x);
    if (std::abs(dp) < kSlabTolerance) return true;
    for (int s : rep.surfaces) {
      const double ds = surfaces[s].plane.distance(x);
      if (std::abs(ds) < kSlabTolerance || (ds > 0) != (dp > 0)) return true;
    }
    return false;
  };
  for (std::size_t f = 0; f < cs.faces.size(); ++f) {
    if (cs.planes[cs.faces[f].plane].from_scan) continue;
    bool touches = false;
    for (int vi : cs.faces[f].v) touches = touches || in_slab(cs.vertices[vi]);
    if (touches) continue;
    if (conf[f].value >= 0.99 && conf[f].model_ref >= 0) {
      // Covered by a kept face on this very plane (confidence also accepts nearby parallels).
      const Plane ref = polygon_plane(model_refs[conf[f].model_ref].polygon);
      bool coplanar = true;
      for (int vi : cs.faces[f].v) coplanar = coplanar && std::abs(ref.distance(cs.vertices[vi])) < 0.01;
      if (coplanar) fixed[f] = 1;
    } else if (conf[f].value <= 0.01) {
      fixed[f] = 0;
    }
  }
  SelectionResult sel = select_faces(cs, cost, outside, prm, &fixed);
  if (sel.status == SolveStatus::Infeasible && sel.fixed > 0 && prm.mip_time_limit > sel.seconds) {
    // A model only approximately consistent with its planes (warped faces, snapped vertices)
    // can make the fixed cells contradict each other: then the whole region is free.
    Params rest = prm;
    rest.mip_time_limit = prm.mip_time_limit - sel.seconds;
    const double first = sel.seconds;
    sel = select_faces(cs, cost, outside, rest);
    sel.seconds += first;
    res.info["fixing_dropped"] = true;
  }
  res.info["mip"] = {{"variables", sel.variables}, {"constraints", sel.constraints}, {"nonzeros", sel.nonzeros},
                     {"fixed_candidates", sel.fixed},
                     {"status", sel.status_text()},       {"objective", sel.objective},     {"seconds", sel.seconds}};
  if (!sel.ok) {
    res.reason = "face selection " + sel.status_text();
    return res;
  }

  // Assemble: kept faces (clipped to outside the region) + selected candidates.
  Mesh soup;
  soup.id = mesh.id;
  auto add_polygon = [&soup](const std::vector<Vec3>& poly, Semantic sem, int source) {
    Face f;
    for (const auto& p : poly) {
      f.v.push_back(int(soup.vertices.size()));
      soup.vertices.push_back(p);
    }
    f.sem = sem;
    f.source = source;
    soup.faces.push_back(std::move(f));
  };
  for (int f = 0; f < int(mesh.faces.size()); ++f) {
    if (replaced_faces.count(f)) continue;
    const auto poly = face_points(mesh, mesh.faces[f]);
    if (!face_in_region[f]) {
      add_polygon(poly, mesh.faces[f].sem, mesh.faces[f].source);
      continue;
    }
    std::vector<std::vector<Vec3>> pieces;
    if (!subtract_region(poly, cs.planes[face_plane[f]].plane, region, pieces)) {
      res.reason = "the change region lies inside a kept face";
      return res;
    }
    for (const auto& piece : pieces) add_polygon(piece, mesh.faces[f].sem, mesh.faces[f].source);
  }
  int selected = 0;
  for (int f = 0; f < int(cs.faces.size()); ++f) {
    if (!sel.selected[f]) continue;
    ++selected;
    add_polygon(cs.polygon(f), cs.planes[cs.faces[f].plane].sem, -1);
  }
  res.info["selected"] = selected;

  RepairReport rr;
  Mesh closed;
  try {
    closed = repair_model(soup, 1e-3, &rr);
  } catch (const InputError& e) {
    res.reason = std::string("assembled shell is not closed: ") + e.what();
    return res;
  }
  if (rr.filled_holes > 0) {
    res.reason = "assembled shell had " + std::to_string(rr.filled_holes) + " hole(s)";
    return res;
  }
  res.mesh = merge_coplanar_faces(closed);
  const Validation val = validate_mesh(res.mesh, prm.planarity_tolerance);
  if (!val.valid()) {
    res.reason = "refined shell invalid: " + val.problem;
    return res;
  }
  res.ok = true;
  res.info["seconds"] = seconds_since(t0);
  return res;
}

// Largest deviation of a surface's vertices from a plane.
double deviation(const Mesh& mesh, const ModelSurface& s, const Plane& pl) {
  double d = 0.0;
  for (int f : s.faces)
    for (int v : mesh.faces[f].v) d = std::max(d, std::abs(pl.distance(mesh.vertices[v])));
  return d;
}

json validation_json(const Validation& v) {
  return {{"watertight", v.watertight()}, {"valid", v.valid()}, {"problem", v.problem},
          {"boundary_edges", v.boundary_edges}, {"nonmanifold_edges", v.nonmanifold_edges},
          {"outward", v.outward}, {"volume", v.volume}, {"max_planarity_error", v.max_planarity_error},
          {"self_intersecting", v.self_intersecting}};
}

}  // namespace

Vec3 local_origin(const Mesh& model) {
  Vec3 lo = Vec3::Constant(1e300);
  for (const auto& v : model.vertices) lo = lo.cwiseMin(v);
  if (!lo.allFinite() || model.vertices.empty()) return Vec3::Zero();
  return Vec3(std::floor(lo.x() / 100.0) * 100.0, std::floor(lo.y() / 100.0) * 100.0, std::floor(lo.z() / 100.0) * 100.0);
}

namespace {

// Vertices moved by the repair's weld are allowed to snap onto their surfaces' plane meet by at
// most this, so that the arrangement's planes and the kept model agree (warped input faces
// keep their vertices).
constexpr double kSnapMove = 0.05;

// The repaired input. Exports whose corners disagree by a little more than the weld tolerance
// (roof jitter) are welded a little coarser across faces; detailed models with features finer
// than it, finer. The first weld whose shell is valid wins; else the first that closed at all.
// Warped faces come back split into triangles (counted in the report).
Mesh repair_input(const Mesh& local_model, const Params& prm, RepairReport& rr) {
  struct Step {
    double weld, gap;  // relative to weld_tolerance
  };
  constexpr Step kSteps[] = {{1.0, 1.0}, {1.0, 1.5}, {1.0, 2.0}, {0.1, 0.1}, {0.01, 0.01}};
  std::optional<std::pair<Mesh, RepairReport>> first;
  std::string error;
  for (const auto& [weld, gap] : kSteps) {
    RepairReport r;
    try {
      Mesh m = repair_model(local_model, prm.weld_tolerance * weld, &r, prm.weld_tolerance * gap);
      if (weld != 1.0 || gap != 1.0)
        r.notes.push_back("welded at " + std::to_string(prm.weld_tolerance * weld) + " m, gaps up to " +
                          std::to_string(prm.weld_tolerance * gap) + " m");
      r.split_warped_faces = split_warped_faces(m, prm.planarity_tolerance);
      if (validate_mesh(m, prm.planarity_tolerance).valid()) {
        rr = r;
        return m;
      }
      if (!first) first.emplace(std::move(m), r);
    } catch (const InputError& e) {
      if (error.empty()) error = e.what();
    }
  }
  if (!first) throw InputError(error);
  rr = first->second;
  return first->first;
}

// RMS distance of points to a mesh.
double rms_distance(const Mesh& mesh, const std::vector<Vec3>& pts) {
  if (pts.empty()) return 0.0;
  double s = 0.0;
  for (double d : cloud_to_mesh(mesh, pts)) s += d * d;
  return std::sqrt(s / double(pts.size()));
}

// Whether `after` keeps every roof part of `before` that lies away from a wall moving from
// plane `from` to `to`: the arrangement keeps roof planes, so a roof dropped, flattened or
// replaced there shows as roof samples off the new model.
bool roof_kept_away_from(const Mesh& before, const Mesh& after, const Plane& from, const Plane& to) {
  constexpr double kZone = 1.0;      // m beyond the slab between the old and new wall
  constexpr double kSpacing = 0.5;   // m between roof samples
  constexpr double kOff = 0.05;      // m: a kept roof sample farther off the new model is damage
  std::vector<int> roofs;
  for (int f = 0; f < int(before.faces.size()); ++f)
    if (before.faces[f].sem == Semantic::Roof) roofs.push_back(f);
  const double reach = std::abs(to.distance(from.project(Vec3::Zero()))) + kZone;
  std::vector<Vec3> far;
  for (const auto& p : sample_faces(before, roofs, kSpacing))
    if (std::abs(from.distance(p)) > reach && std::abs(to.distance(p)) > reach) far.push_back(p);
  if (far.empty()) return true;
  for (double d : cloud_to_mesh(after, far))
    if (std::abs(d) > kOff) return false;
  return true;
}

// Whether the scan shows a moved wall's eave where its pitched roof's plane meets the new wall
// (the roof plane was right) rather than at the old eave height (the roof outline was right):
// the top of the wall's own points decides, and only where it clearly does.
bool eave_follows_roof(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const Match& m, const Plane& plane,
                       const PointCloud& cloud) {
  // m: the two eaves must differ by kDiffer; the scan's top must lie within kAgree of the
  // followed one and closer to it than to the kept one by kMargin (a scan may stop short of
  // the eave under an overhang).
  constexpr double kDiffer = 0.2, kAgree = 0.3, kMargin = 0.15;
  constexpr double kTopQuantile = 0.99;          // the wall's points' top, robust to a few strays
  if (m.owned.empty()) return false;
  auto top = [&](bool follow) {
    const auto sub = substitute_walls(mesh, surfaces, {{m.surface, plane, follow}}, 1e300);
    double z = -1e300;
    if (!sub.ok) return z;
    for (int f : surfaces[m.surface].faces)
      for (int v : mesh.faces[f].v) z = std::max(z, sub.mesh.vertices[v].z());
    return z;
  };
  const double keep = top(false), follow = top(true);
  if (std::abs(keep - follow) < kDiffer) return false;
  std::vector<double> z;
  for (int i : m.owned) z.push_back(cloud.points[i].z());
  const std::size_t k = std::size_t(kTopQuantile * double(z.size() - 1));
  std::nth_element(z.begin(), z.begin() + long(k), z.end());
  const double scan_top = z[k];
  return std::abs(scan_top - follow) <= kAgree && std::abs(scan_top - follow) + kMargin < std::abs(scan_top - keep);
}

}  // namespace

RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const Params& prm) {
  prm.validate();
  const auto t_start = Clock::now();
  RefineResult out;
  json& rep = out.report;
  rep["id"] = model.id;
  json timing;

  const Vec3 origin = local_origin(model);
  rep["origin"] = {origin.x(), origin.y(), origin.z()};
  auto finish = [&](const std::string& outcome, const std::string& reason, const Mesh& local_mesh,
                    bool single_shell = true) {
    out.outcome = outcome;
    out.reason = reason;
    const Validation vf = validate_mesh(local_mesh, prm.planarity_tolerance, true, single_shell);
    out.valid = vf.valid();
    out.refined = outcome == "refined";
    rep["outcome"] = outcome;
    rep["reason"] = reason;
    rep["refined"] = out.refined;
    rep["output_validation"] = validation_json(vf);
    rep["faces"] = local_mesh.faces.size();
    timing["total"] = seconds_since(t_start);
    rep["seconds"] = timing;
    out.mesh = translated(local_mesh, origin);
    out.mesh.id = model.id;
    return out;
  };

  // Repair the exported soup into a closed shell; a model that cannot be made one is written as
  // read (kept-invalid) with the reason.
  auto t = Clock::now();
  const Mesh local_model = translated(model, -origin);
  RepairReport rr;
  Mesh kept;
  try {
    kept = repair_input(local_model, prm, rr);
  } catch (const InputError& e) {
    timing["repair"] = seconds_since(t);
    return finish("kept-invalid", e.what(), local_model);
  }
  kept.id = model.id;
  rep["repair"] = {{"welded_vertices", rr.welded_vertices},
                   {"removed_degenerate_faces", rr.removed_degenerate_faces},
                   {"removed_duplicate_faces", rr.removed_duplicate_faces},
                   {"split_t_junctions", rr.split_t_junctions},
                   {"flipped_faces", rr.flipped_faces},
                   {"filled_holes", rr.filled_holes},
                   {"split_warped_faces", rr.split_warped_faces},
                   {"notes", rr.notes}};
  const Validation v0 = validate_mesh(kept, prm.planarity_tolerance);
  rep["input_validation"] = validation_json(v0);
  timing["repair"] = seconds_since(t);
  if (!v0.valid() && v0.components > 1 && validate_mesh(kept, prm.planarity_tolerance, true, false).valid())
    // Several closed shells (a multi-part export): each valid, the building kept whole.
    return finish("kept", std::to_string(v0.components) + " separate closed shells: kept whole", kept, false);
  if (!v0.valid()) return finish("kept-invalid", "the input is no valid solid: " + v0.problem, local_model);
  Mesh current = merge_coplanar_faces(kept);
  current.id = model.id;

  // Only the cloud near the model matters (crops may carry whole streets).
  t = Clock::now();
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& v : current.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vec3 pad = Vec3::Constant(prm.match_distance + prm.bbox_margin) + prm.bbox_expand * (hi - lo);
  PointCloud local;
  for (const auto& p : cloud.points) {
    const Vec3 q = p - origin;
    if ((q.array() >= (lo - pad).array()).all() && (q.array() <= (hi + pad).array()).all()) local.points.push_back(q);
  }
  rep["cloud"] = {{"points", cloud.points.size()}, {"points_near_model", local.points.size()}};
  const auto planes = detect_planes(local, prm);
  timing["planes"] = seconds_since(t);
  json jplanes = json::array();
  for (const auto& p : planes)
    jplanes.push_back({{"normal", {p.plane.n.x(), p.plane.n.y(), p.plane.n.z()}}, {"d", p.plane.d},
                       {"inliers", p.inliers.size()}, {"rms", p.rms}, {"area", p.hull_area}, {"facade", p.facade}});
  rep["planes"] = jplanes;
  if (planes.empty()) return finish("kept", "no planes found in the cloud near the model", kept);

  // Matching on the input: which walls the scan sees, where, and by which points.
  t = Clock::now();
  const auto surfaces = model_surfaces(current);
  const MatchResult mr = match_surfaces(current, surfaces, local, planes, prm);
  std::vector<Vec3> facade_points;  // the matched walls' own points: the fit is judged on them
  std::vector<WallMove> moves;
  std::vector<ScannedWall> scanned;
  json jm = json::array();
  for (const auto& m : mr.matches) {
    Plane pl = planes[m.scan_plane].plane;
    if (pl.n.dot(surfaces[m.surface].plane.n) < 0) pl = pl.flipped();
    scanned.push_back({m.surface, m.scan_plane, pl});
    const double dev = deviation(current, surfaces[m.surface], pl);
    if (dev > prm.change_tolerance) moves.push_back({m.surface, pl, eave_follows_roof(current, surfaces, m, pl, local)});
    for (int i : m.owned) facade_points.push_back(local.points[i]);
    jm.push_back({{"scan_plane", m.scan_plane}, {"surface", m.surface}, {"s_normal", m.s_normal},
                  {"d_centroid", m.d_centroid}, {"c_bbox", m.c_bbox}, {"s_match", m.s_match}, {"points", m.owned.size()},
                  {"deviation", dev}, {"faces", surfaces[m.surface].faces}});
  }
  rep["matches"] = jm;
  rep["rejected_matches"] = mr.rejected;
  rep["q_model"] = mr.q_model;
  const auto corners = prm.arrangement_only ? std::vector<CornerMove>{} : corner_moves(current, surfaces, scanned, local, planes, prm);
  timing["matching"] = seconds_since(t);
  if (moves.empty() && corners.empty())
    return finish("kept", mr.matches.empty() ? "no wall matched a scan plane" : "every matched wall agrees with the scan", kept);

  // First choice: every outdated wall takes its scan plane at once, the model's topology kept;
  // unscanned walls at a scanned facade's end move to where the scan shows the corner.
  t = Clock::now();
  json jfacades = json::array();
  // A moved wall for the report, on the mesh (and its surfaces) the move was made on.
  auto describe_on = [&](const Mesh& mesh, const std::vector<ModelSurface>& ss, const WallMove& mv,
                         const char* evidence) {
    const ModelSurface& s = ss[mv.surface];
    double mean = 0.0, n = 0.0;
    for (int f : s.faces)
      for (int v : mesh.faces[f].v) mean += std::abs(mv.plane.distance(mesh.vertices[v])), n += 1.0;
    std::set<int> sources;
    for (int f : s.faces) sources.insert(mesh.faces[f].source);
    jfacades.push_back({{"input_faces", sources}, {"evidence", evidence}, {"max_move", deviation(mesh, s, mv.plane)},
                        {"mean_move", n > 0 ? mean / n : 0.0}});
  };
  auto describe = [&](const WallMove& mv, const char* evidence) { describe_on(current, surfaces, mv, evidence); };
  // Substitution on `mesh`, merged and validated; `js` says what happened.
  auto substitute_on = [&](const Mesh& mesh, const std::vector<ModelSurface>& ss, const std::vector<WallMove>& mv,
                           json& js) {
    SubstitutionResult sub = substitute_walls(mesh, ss, mv, prm.planarity_tolerance);
    js = {{"method", "substitution"}, {"walls", mv.size()}, {"ok", sub.ok}};
    if (!sub.ok) {
      js["reason"] = sub.reason;
      return std::optional<Mesh>();
    }
    Mesh m = merge_coplanar_faces(sub.mesh);
    const Validation vs = validate_mesh(m, prm.planarity_tolerance);
    if (!vs.valid()) {
      js["ok"] = false;
      js["reason"] = "substituted shell invalid: " + vs.problem;
      return std::optional<Mesh>();
    }
    js["moved_vertices"] = sub.moved_vertices;
    js["max_vertex_move"] = sub.max_vertex_move;
    js["split_faces"] = sub.split_faces;
    m.id = model.id;
    return std::optional<Mesh>(std::move(m));
  };
  auto substitute = [&](const std::vector<WallMove>& mv, json& js) { return substitute_on(current, surfaces, mv, js); };
  std::vector<WallMove> all = moves;
  for (const auto& c : corners) all.push_back(c.move);
  json jsub;
  std::optional<Mesh> refined;
  if (!prm.arrangement_only) refined = substitute(all, jsub);
  if (refined) {
    for (const auto& mv : moves) describe(mv, "scan");
    for (const auto& c : corners) describe(c.move, "corner");
  } else if (!corners.empty() && !moves.empty()) {
    json without;
    refined = substitute(moves, without);
    jsub["without_corners"] = without;
    if (refined)
      for (const auto& mv : moves) describe(mv, "scan");
  }
  if (!jsub.empty()) rep["substitution"] = jsub;
  timing["substitution"] = seconds_since(t);

  // Fallback: one wall at a time, each by substitution or by the local candidate arrangement and
  // GLPK, re-matching on the new model after each.
  t = Clock::now();
  json steps = json::array();
  if (!refined) {
    Mesh step_mesh = current;
    bool any = false;
    std::set<std::pair<int, long long>> tried;  // (scan plane, rounded wall position)
    double mip_seconds = 0.0;
    for (int iter = 0; iter < 4 * int(planes.size()) + 4; ++iter) {
      const auto ss = model_surfaces(step_mesh);
      const MatchResult mi = match_surfaces(step_mesh, ss, local, planes, prm);
      const Match* next = nullptr;
      for (const auto& m : mi.matches) {
        const auto key = std::make_pair(m.scan_plane, (long long)std::llround(ss[m.surface].centroid.squaredNorm() * 100));
        if (tried.count(key) || deviation(step_mesh, ss[m.surface], planes[m.scan_plane].plane) <= prm.change_tolerance)
          continue;
        if (next == nullptr || m.s_match > next->s_match) next = &m;
      }
      if (next == nullptr) break;
      const auto& surf = ss[next->surface];
      tried.insert({next->scan_plane, (long long)std::llround(surf.centroid.squaredNorm() * 100)});
      Replacement r;
      r.surfaces = {next->surface};
      r.plane = planes[next->scan_plane].plane;
      if (r.plane.n.dot(surf.plane.n) < 0) r.plane = r.plane.flipped();
      for (int i : planes[next->scan_plane].inliers) r.points.push_back(local.points[i]);
      json js;
      js["scan_plane"] = next->scan_plane;
      js["wall_faces"] = surf.faces;
      js["moved_by"] = deviation(step_mesh, surf, r.plane);
      std::optional<Mesh> m;
      if (!prm.arrangement_only) {
        json unused;
        m = substitute_on(step_mesh, ss, {{next->surface, r.plane}}, unused);
      }
      if (m) {
        js["method"] = "substitution";
      } else {
        // The arrangement needs the model to agree exactly with its planes.
        Params step_prm = prm;
        step_prm.mip_time_limit = prm.mip_time_limit - mip_seconds;
        if (step_prm.mip_time_limit <= 0.0) {
          js["ok"] = false;
          js["reason"] = "MIP time limit used up";
          steps.push_back(js);
          break;
        }
        Mesh snapped = step_mesh;
        snap_to_surfaces(snapped, ss, kSnapMove);
        StepResult sr = replace_walls(snapped, model_surfaces(snapped), r, step_prm);
        if (sr.info.contains("mip")) mip_seconds += sr.info["mip"].value("seconds", 0.0);
        js.update(sr.info);
        js["method"] = "arrangement";
        if (sr.ok && !roof_kept_away_from(step_mesh, sr.mesh, surf.plane, r.plane)) {
          sr.ok = false;
          sr.reason = "the arrangement changed the roof away from the moved wall";
        }
        if (sr.ok) m = std::move(sr.mesh);
        else js["reason"] = sr.reason;
      }
      js["ok"] = bool(m);
      steps.push_back(js);
      if (m) {
        describe_on(step_mesh, ss, {next->surface, r.plane}, "scan");
        step_mesh = std::move(*m);
        step_mesh.id = model.id;
        any = true;
      }
    }
    if (any) refined = step_mesh;
  }
  rep["replacements"] = steps;
  timing["replacement"] = seconds_since(t);
  rep["facades"] = jfacades;
  if (!refined) {
    std::string why = "no wall could be replaced";
    if (!steps.empty()) why = steps.back().value("reason", why);
    else if (jsub.contains("reason")) why = jsub.value("reason", why);
    return finish("kept", why, kept);
  }
  const Validation vf = validate_mesh(*refined, prm.planarity_tolerance);
  if (!vf.valid()) return finish("kept", "refined shell failed validation: " + vf.problem, kept);

  // Never worse: the refined model must fit the matched walls' points better than the input.
  const double fit_before = rms_distance(kept, facade_points), fit_after = rms_distance(*refined, facade_points);
  rep["facade_fit"] = {{"points", facade_points.size()}, {"rms_before", fit_before}, {"rms_after", fit_after}};
  if (!(fit_after < fit_before))
    return finish("kept", "the refinement does not fit the scan better (RMS " + std::to_string(fit_before) + " -> " +
                              std::to_string(fit_after) + " m)", kept);
  return finish("refined", std::to_string(jfacades.size()) + " wall(s) moved", *refined);
}

}  // namespace lodrefine



