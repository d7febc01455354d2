// Stage 3 (fallback, paper Sec. 3.2-3.4): one wall replaced through a local candidate
// arrangement, confidence, coverage cost and GLPK face selection.
#include "lodrefine/core/arrangement.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/confidence.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"

namespace lodrefine {
namespace {

namespace bg = boost::geometry;
using BPoint = bg::model::d2::point_xy<double>;
using BPolygon = bg::model::polygon<BPoint, false, false>;  // CCW, open
using BMulti = bg::model::multi_polygon<BPolygon>;

// Vertices moved by the repair's weld may snap onto their surfaces' plane meet by at most this
// (m), so that the arrangement's planes and the kept model agree; warped input faces keep theirs.
constexpr double kSnapMove = 0.05;
// Weight of "stay where you are" in the snap's least squares: picks the nearest point where
// fewer than three independent planes meet, too small to pull a vertex off a true meet.
constexpr double kSnapRegulariser = 1e-9;
// m²: clipping leaves slivers of ~1e-12 m² of faces that only touch the region; no overlap.
constexpr double kMinOverlapArea = 1e-8;
// The region's bounds keep this far (m) from model vertices and from where model edges cross its
// faces, moving out by kClearStep (m) at a time (at most kMaxClearRounds): a model feature
// running along the boundary makes slivers and an ambiguous outside surface.
constexpr double kClear = 0.02, kClearStep = 0.05;
constexpr int kMaxClearRounds = 60;
// Coplanar walls swept into the replacement, region regrown, at most this often (a facade of
// several coplanar walls needs two rounds; a third finds nothing new in every case seen).
constexpr int kGrowRounds = 3;
// Surfaces on the very same plane (the model was snapped to its planes: agreement up to
// rounding): 1 - cos of their normals' angle, and offset (m).
constexpr double kSameNormal = 1e-9, kSameOffset = 1e-6;
// A boundary edge's probe into the kept surface beyond the region: this far (m) from the edge;
// edges whose direction is within kAcrossCos of parallel to the box face are not probed, and
// edges shorter than kDegenerateLength (m) have no direction.
constexpr double kProbe = 0.01, kAcrossCos = 1e-3, kDegenerateLength = 1e-12;
// Outside the slab between the old and new wall (kSlabTolerance, m, either side of each plane)
// a candidate covered by a kept face at least kSureIn and coplanar with it within kCoplanar (m)
// is fixed in; one at most kSureOut covered is fixed out.
constexpr double kSlabTolerance = 0.05, kSureIn = 0.99, kSureOut = 0.01, kCoplanar = 0.01;
// The assembled pieces were cut exactly; welding at 1 mm joins their rounding only.
constexpr double kAssemblyWeld = 1e-3;


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
    Eigen::Matrix3d a = kSnapRegulariser * Eigen::Matrix3d::Identity();
    Vec3 b = kSnapRegulariser * mesh.vertices[v];
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

Region replacement_region(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const WallReplacement& rep,
                          const Params& prm) {
  const auto [u, v] = rep.plane.basis();
  Eigen::Matrix3d axes;
  axes.col(0) = u;
  axes.col(1) = v;
  axes.col(2) = rep.plane.n;
  std::vector<Vec3> pts;  // the old wall and its projection onto the new plane, in the region's axes
  for (int s : rep.surfaces)
    for (int f : surfaces[s].faces)
      for (int vi : mesh.faces[f].v) {
        pts.push_back(axes.transpose() * mesh.vertices[vi]);
        pts.push_back(axes.transpose() * rep.plane.project(mesh.vertices[vi]));
      }
  const Eigen::AlignedBox3d box = bounding_box(pts);
  const Vec3 lo = box.min(), hi = box.max();
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
  auto near_bound = [&](const Vec3& q, int k) {  // pushes the bound of axis k that q is close to
    if (std::abs(q[k] - qlo[k]) < kClear) { qlo[k] -= kClearStep; return true; }
    if (std::abs(q[k] - qhi[k]) < kClear) { qhi[k] += kClearStep; return true; }
    return false;
  };
  for (int round = 0; round < kMaxClearRounds; ++round) {
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
    if (piece.size() >= 3 && polygon_area(piece) > kMinOverlapArea) pieces.push_back(std::move(piece));
  }
  return true;
}

ArrangementResult replace_walls(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, WallReplacement rep,
                                const Params& prm) {
  ArrangementResult res;
  const auto t0 = Clock::now();

  // Model walls that the scan plane makes coplanar with it are replaced together.
  Region region = replacement_region(mesh, surfaces, rep, prm);
  for (int round = 0; round < kGrowRounds; ++round) {
    bool grew = false;
    for (int s = 0; s < int(surfaces.size()); ++s) {
      if (surfaces[s].sem != Semantic::Wall ||
          std::find(rep.surfaces.begin(), rep.surfaces.end(), s) != rep.surfaces.end())
        continue;
      if (unoriented_angle_deg(surfaces[s].plane.n, rep.plane.n) > prm.merge_angle_deg) continue;
      bool near = true, inside = false;
      for (int f : surfaces[s].faces) {
        for (int vi : mesh.faces[f].v) near = near && std::abs(rep.plane.distance(mesh.vertices[vi])) <= prm.merge_distance;
        inside = inside || area_inside(face_points(mesh, mesh.faces[f]), region) > kMinOverlapArea;
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
    face_in_region[f] = !replaced_faces.count(f) && area_inside(face_points(mesh, mesh.faces[f]), region) > kMinOverlapArea;
  for (int s = 0; s < int(surfaces.size()); ++s) {
    if (replaced.count(s)) continue;
    bool in = false;
    for (int f : surfaces[s].faces) in = in || face_in_region[f];
    if (!in) continue;
    // Surfaces on the very same plane (split by other faces, or a repaired hole labelled
    // otherwise) share one supporting plane, named after the larger surface.
    int idx = -1;
    for (int k = 1; k < int(planes.size()) && idx < 0; ++k)
      if (planes[k].plane.n.dot(surfaces[s].plane.n) > 1.0 - kSameNormal &&
          std::abs(planes[k].plane.d - surfaces[s].plane.d) < kSameOffset)
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
  res.stats.supporting_planes = int(planes.size());
  res.stats.candidates = int(cs.faces.size());
  res.stats.edges = int(cs.edges.size());

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
      if (t.norm() < kDegenerateLength) continue;
      t.normalize();
      const double along = t.dot(box[edge.box_plane].n);
      if (std::abs(along) < kAcrossCos) continue;
      if (along < 0) t = -t;
      const Vec3 q = 0.5 * (a + b) + kProbe * t;
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
    if (!replaced_faces.count(f) && area_inside(face_points(mesh, mesh.faces[f]), near_region) > kMinOverlapArea)
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
    if (conf[f].value >= kSureIn && conf[f].model_ref >= 0) {
      // Covered by a kept face on this very plane (confidence also accepts nearby parallels).
      const Plane ref = polygon_plane(model_refs[conf[f].model_ref].polygon);
      bool coplanar = true;
      for (int vi : cs.faces[f].v) coplanar = coplanar && std::abs(ref.distance(cs.vertices[vi])) < kCoplanar;
      if (coplanar) fixed[f] = 1;
    } else if (conf[f].value <= kSureOut) {
      fixed[f] = 0;
    }
  }
  SelectionResult sel = select_faces(cs, cost, outside, prm, &fixed);
  if (sel.status == SolveStatus::Infeasible && sel.fixed > 0 && prm.mip_time_limit > sel.seconds) {
    // A model only approximately consistent with its planes (warped faces, snapped vertices)
    // can make the fixed cells contradict each other: then the whole region is free.
    SelectionProgram free_region;
    free_region.cost = cost;
    free_region.outside = outside;
    const double first = sel.seconds;
    sel = select_faces(cs, free_region, prm, prm.mip_time_limit - first);
    sel.seconds += first;
    res.stats.fixing_dropped = true;
  }
  res.stats.selection = sel;
  res.stats.selection->selected.clear();
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
  res.stats.selected = selected;

  RepairReport rr;
  Mesh closed;
  try {
    closed = repair_model(soup, kAssemblyWeld, &rr);
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
  res.stats.seconds = seconds_since(t0);
  return res;
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

}  // namespace

ArrangementResult arrange_wall(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                               const WallReplacement& rep, const Params& prm) {
  Mesh snapped = mesh;
  snap_to_surfaces(snapped, surfaces, kSnapMove);
  ArrangementResult r = replace_walls(snapped, model_surfaces(snapped), rep, prm);
  if (r.ok && !roof_kept_away_from(mesh, r.mesh, surfaces[rep.surfaces.front()].plane, rep.plane)) {
    r.ok = false;
    r.reason = "the arrangement changed the roof away from the moved wall";
  }
  return r;
}

}  // namespace lodrefine
