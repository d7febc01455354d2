// The supporting planes of a building's arrangement: see shell_supports.h.
#include "shell_supports.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <unordered_map>

#include "lodrefine/core/matching.h"
#include "occupancy.h"

namespace lodrefine::detail {
namespace {

// The region reaches this far (m) beyond the building and its scan evidence, so that no face of
// a building touches its boundary.
constexpr double kRegionMargin = 1.0;

// Where a scanned facade's points run along its horizontal direction `u` (positions along u;
// gaps shorter than kWindowGap are bridged: a window column still has wall above and below).
struct Interval {
  double a, b;
};
constexpr double kWindowGap = 2 * kOccupancyCell;  // m
std::vector<Interval> intervals_along(const std::vector<Vec3>& pts, const Vec3& u) {
  std::vector<double> t;
  for (const auto& p : pts) t.push_back(u.dot(p));
  std::sort(t.begin(), t.end());
  std::vector<Interval> out;
  for (double x : t) {
    if (out.empty() || x - out.back().b > kWindowGap) out.push_back({x, x});
    else out.back().b = x;
  }
  return out;
}

// Ends within kSideClear (m) of the footprint's ends are the building's own corners; other ends
// within kStepReach (m) belong to the same step; a plane within kSameStep (m) of the end is there
// already.
constexpr double kSideClear = 0.3, kStepReach = 1.0, kSameStep = 0.1;

// The start's span along the horizontal direction u.
Interval span_along(const Mesh& start, const Vec3& u) {
  Interval r{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& p : start.vertices) r.a = std::min(r.a, u.dot(p)), r.b = std::max(r.b, u.dot(p));
  return r;
}

// Whether a facade whose runs along their horizontal direction u are `a` continues the parallel
// facade `facade` across a step (`span`: the start's span along u): a run of each ends within
// kStepReach of the other's, inside the footprint, and their runs overlap along u by no more
// than that (a facade across the street runs alongside, not on from it).
bool continues_across_step(const std::vector<Interval>& a, const Interval& span, const std::vector<Vec3>& facade,
                           const Vec3& u) {
  const auto b = intervals_along(facade, u);
  double overlap = 0.0;
  for (const auto& ra : a)
    for (const auto& rb : b) overlap += std::max(0.0, std::min(ra.b, rb.b) - std::max(ra.a, rb.a));
  if (overlap > kStepReach) return false;
  for (const auto& ra : a)
    for (double e : {ra.a, ra.b}) {
      if (e < span.a + kSideClear || e > span.b - kSideClear) continue;
      for (const auto& rb : b)
        if (std::abs(rb.a - e) <= kStepReach || std::abs(rb.b - e) <= kStepReach) return true;
    }
  return false;
}

// Whether the points `pts` on a facade plane with normal `n` continue another parallel scanned
// facade of `s` (other than plane `self`) across a step. Their runs and the start's span are
// found once, not per facade tried.
bool continues_another_across_step(const Mesh& start, const Supports& s, const std::vector<Vec3>& pts, const Vec3& n,
                                   double angle_deg, int self = -1) {
  const Vec3 u = along_wall(n).normalized();
  const std::vector<Interval> runs = intervals_along(pts, u);
  const Interval span = span_along(start, u);
  for (int k = 0; k < int(s.planes.size()); ++k)
    if (k != self && !s.points[k].empty() && unoriented_angle_deg(s.planes[k].plane.n, n) <= angle_deg &&
        continues_across_step(runs, span, s.points[k], u))
      return true;
  return false;
}

// Where a scanned facade's points are the building's own along its horizontal direction: within
// the start's span, and past one of its ends only up to where a run crossing that end stops
// within `reach` (the facade's own corner, a wall the model has short). A run going on past the
// reach is the facade line running into a neighbour's: the party wall between them is not in the
// scan, so the model's end stands. A run from the end (within kWindowGap of it: a bay's return
// starts at the model's front) counts as crossing it; runs that begin farther past an end (across
// a gap) are another building's.
Interval own_extent(const std::vector<Interval>& runs, const Interval& span, double reach) {
  Interval own = span;
  for (const Interval& r : runs) {
    if (r.a <= span.b + kWindowGap && r.b > span.b && r.b <= span.b + reach) own.b = std::max(own.b, r.b);
    if (r.b >= span.a - kWindowGap && r.a < span.a && r.a >= span.a - reach) own.a = std::min(own.a, r.a);
  }
  return own;
}

}  // namespace

void add_start_planes(const Mesh& start, double planarity_tolerance, Supports& s) {
  const auto surfaces = model_surfaces(start);
  std::vector<int> order(surfaces.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return surfaces[a].area > surfaces[b].area; });
  s.face_plane.assign(start.faces.size(), -1);
  for (int si : order) {
    const ModelSurface& surf = surfaces[si];
    // The first (largest) plane the surface lies on within kSurfaceDistance and kSurfaceAngleDeg;
    // else the one nearest in angle of those its vertices lie within the planarity tolerance of,
    // whatever its own normal: a sliver's normal is noise (a hole filled between a roof's
    // jittered edge and its wall's top, 1 cm wide and 2° off the roof, was a plane of its own and
    // held the roof's edge where the model had it, so no wall under it could move).
    int k = -1, sliver_of = -1;
    double sliver_angle = 180.0;
    for (int j = 0; j < int(s.planes.size()) && k < 0; ++j) {
      double worst = 0.0;
      for (int f : surf.faces)
        for (int v : start.faces[f].v) worst = std::max(worst, std::abs(s.planes[j].plane.distance(start.vertices[v])));
      const double angle = unoriented_angle_deg(s.planes[j].plane.n, surf.plane.n);
      if (worst <= kSurfaceDistance && angle <= kSurfaceAngleDeg) k = j;
      else if (worst <= planarity_tolerance && angle < sliver_angle) sliver_of = j, sliver_angle = angle;
    }
    if (k < 0 && sliver_of >= 0) k = sliver_of;
    if (k < 0) {
      k = int(s.planes.size());
      s.planes.push_back({surf.plane, surf.sem, false, si});
    }
    for (int f : surf.faces) s.face_plane[f] = k;
  }
  s.start_planes = int(s.planes.size());
  // A plane a wall was moved onto is the scan's; one only added faces lie on is added; else the model's.
  std::vector<char> scan(s.planes.size(), 0), model(s.planes.size(), 0);
  for (std::size_t f = 0; f < start.faces.size(); ++f) {
    const int k = s.face_plane[f];
    if (k < 0) continue;
    const Provenance p = start.faces[f].provenance;
    if (p == Provenance::Scan) scan[std::size_t(k)] = 1;
    else if (p != Provenance::Added) model[std::size_t(k)] = 1;  // None: a model as read
  }
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    s.planes[k].provenance = scan[k] ? Provenance::Scan : model[k] ? Provenance::Model : Provenance::Added;
  s.points.assign(s.planes.size(), {});
}

// The scan's facade planes near the footprint: each one's points within match_distance +
// bbox_margin of the start's box (in the plane's own horizontal frame) and along it within the
// building's own extent (own_extent), when at least ransac_min_points, go to the supporting plane
// of the start that they lie on, else to a new one.
// A facade farther before or behind the box (up to the building's depth) counts too where it
// continues a scanned facade of the building across a step (continues_across_step): a facade line stepping
// back or forward farther than the reach.
void add_scan_planes(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& scan,
                     const RefineConfig& prm, Supports& s) {
  const double reach = prm.scan_reach();  // a wall off by up to match_distance, plus a bay
  const double tilt = prm.plane.facade_max_tilt_deg;
  auto attach = [&](int i, const std::vector<Vec3>& pts) {
    auto mean_distance = [&](const Plane& pl) {
      double sum = 0.0;
      for (const auto& p : pts) sum += std::abs(pl.distance(p));
      return sum / double(pts.size());
    };
    int k = -1;
    double best = prm.selection.merge_distance;
    for (int j = 0; j < int(s.planes.size()); ++j) {
      if (!near_vertical(s.planes[j].plane, tilt) ||
          unoriented_angle_deg(s.planes[j].plane.n, scan[i].plane.n) > prm.selection.merge_angle_deg)
        continue;
      const double d = mean_distance(s.planes[j].plane);
      if (d <= best) best = d, k = j;
    }
    if (k < 0) {
      k = int(s.planes.size());
      s.planes.push_back({scan[i].plane, Semantic::Wall, true, i, Provenance::Scan});
      s.points.emplace_back();
      ++s.added;
    }
    s.points[k].insert(s.points[k].end(), pts.begin(), pts.end());
  };
  std::vector<std::pair<int, std::vector<Vec3>>> deep;  // facades beyond the reach in depth only
  for (int i = 0; i < int(scan.size()); ++i) {
    const ScanPlane& sp = scan[i];
    if (!sp.facade) continue;
    Vec3 n(sp.plane.n.x(), sp.plane.n.y(), 0.0);
    if (n.norm() < 1e-9) continue;
    n.normalize();
    const Vec3 u = along_wall(n);
    Eigen::AlignedBox3d box;  // the start in (u, n, z)
    for (const auto& p : start.vertices) box.extend(Vec3(u.dot(p), n.dot(p), p.z()));
    std::vector<Vec3> inliers;
    for (int idx : sp.inliers) inliers.push_back(cloud.points[idx]);
    const Interval own = own_extent(intervals_along(inliers, u), {box.min().x(), box.max().x()}, reach);
    std::vector<Vec3> near, beyond;
    for (const Vec3& p : inliers) {
      const Vec3 q(u.dot(p), n.dot(p), p.z());
      const Vec3 below = box.min() - q, above = q - box.max();
      if (q.x() < own.a || q.x() > own.b || std::max(below.z(), above.z()) > reach) continue;
      const double out = std::max(below.y(), above.y());  // before or behind the box
      if (out <= reach) near.push_back(p);
      else if (out <= box.sizes().y()) beyond.push_back(p);
    }
    if (int(near.size()) >= prm.plane.ransac_min_points) attach(i, near);
    else if (int(beyond.size()) >= prm.plane.ransac_min_points) deep.emplace_back(i, std::move(beyond));
  }
  for (const auto& [i, pts] : deep)
    if (continues_another_across_step(start, s, pts, scan[i].plane.n, prm.selection.merge_angle_deg)) attach(i, pts);
}

// A facade line that steps, a recess or a bay needs the wall across the step, which the scan
// often misses (seen edge-on, or in the shadow of the feature). Where the points of a facade
// plane the start does not carry end inside the footprint, a vertical plane across that end is
// a hypothesis, and one at each nearby end of a parallel scanned facade's points (the other side
// of the step, where the points usually end more sharply). The selection takes such a wall only
// where it closes what the scan shows.
void add_step_walls(const Mesh& start, const RefineConfig& prm, Supports& s) {
  const double tilt = prm.plane.facade_max_tilt_deg;
  const int existing = int(s.planes.size());
  for (int j = s.start_planes; j < existing; ++j) {
    const Plane& pj = s.planes[j].plane;
    if (!s.planes[j].from_scan || s.points[j].empty() || !near_vertical(pj, tilt)) continue;
    const Vec3 u = along_wall(pj.n).normalized();
    const auto [lo, hi] = span_along(start, u);
    std::vector<double> ends;
    for (const auto& r : intervals_along(s.points[j], u)) ends.insert(ends.end(), {r.a, r.b});
    std::vector<double> positions;
    for (double e : ends) {
      if (e < lo + kSideClear || e > hi - kSideClear) continue;
      positions.push_back(e);
      for (int k = 0; k < existing; ++k) {
        if (k == j || s.points[k].empty() ||
            unoriented_angle_deg(s.planes[k].plane.n, pj.n) > prm.selection.merge_angle_deg)
          continue;
        for (const auto& r : intervals_along(s.points[k], u))
          for (double f : {r.a, r.b})
            if (std::abs(f - e) <= kStepReach && f > lo + kSideClear && f < hi - kSideClear) positions.push_back(f);
      }
    }
    Vec3 c = Vec3::Zero();
    for (const auto& p : s.points[j]) c += p;
    c /= double(s.points[j].size());
    for (double t : positions) {
      const Vec3 x = c + (t - u.dot(c)) * u;
      bool there = false;
      for (const auto& sp : s.planes)
        there = there || (near_vertical(sp.plane, tilt) &&
                          unoriented_angle_deg(sp.plane.n, u) <= prm.selection.merge_angle_deg &&
                          std::abs(sp.plane.distance(x)) <= kSameStep);
      if (there) continue;
      s.planes.push_back({Plane::through(x, u), Semantic::Wall, true, -1, Provenance::Added});
      s.points.emplace_back();
    }
  }
}

// The evidence a scan-only facade gives for the volume between it and the start's parallel wall
// it stands before or behind (a step of the facade line, a bay, a recess): the change that
// replaces that wall's part by the facade is asked for by the scan however deep the step is.
// Each point of such a facade, swept along the wall's normal onto the nearest parallel start
// face it stands before, sampled every `step` m (its endpoint included). Only a facade that
// continues another scanned facade across a step (continues_across_step): a lone parallel facade before a
// wall may be a neighbour's across an alley.
std::vector<Vec3> step_volume_samples(const Mesh& start, const Supports& s, const RefineConfig& prm, double step) {
  const double tilt = prm.plane.facade_max_tilt_deg;
  struct Wall {
    Plane plane;
    Vec3 u, v;
    std::vector<Vec2> poly;  // in (u, v)
  };
  std::vector<Wall> walls;
  for (std::size_t f = 0; f < start.faces.size(); ++f) {
    const int k = s.face_plane[f];
    if (k < 0 || !near_vertical(s.planes[k].plane, tilt)) continue;
    Wall w{s.planes[k].plane, {}, {}, {}};
    std::tie(w.u, w.v) = w.plane.basis();
    for (int i : start.faces[f].v) w.poly.emplace_back(w.u.dot(start.vertices[i]), w.v.dot(start.vertices[i]));
    walls.push_back(std::move(w));
  }
  std::vector<Vec3> out;
  for (int k = s.start_planes; k < int(s.planes.size()); ++k) {
    if (s.points[k].empty() || !near_vertical(s.planes[k].plane, tilt) ||
        !continues_another_across_step(start, s, s.points[k], s.planes[k].plane.n, prm.selection.merge_angle_deg, k))
      continue;
    std::vector<const Wall*> parallel;
    for (const auto& w : walls)
      if (unoriented_angle_deg(w.plane.n, s.planes[k].plane.n) <= prm.selection.merge_angle_deg) parallel.push_back(&w);
    for (const auto& p : s.points[k]) {
      const Wall* near = nullptr;
      double best = std::numeric_limits<double>::infinity();
      for (const Wall* w : parallel) {
        const double d = w->plane.distance(p);
        if (std::abs(d) < std::abs(best) && point_in_polygon_2d(Vec2(w->u.dot(p), w->v.dot(p)), w->poly))
          best = d, near = w;
      }
      if (!near) continue;
      const double depth = std::abs(best);
      for (double t = std::min(step, depth);; t = std::min(t + step, depth)) {
        out.push_back(p - std::copysign(t, best) * near->plane.n);
        if (t >= depth) break;
      }
    }
  }
  return out;
}

// The region: the start and the scan evidence, in the axes of the start's largest wall.
Region building_region(const Mesh& start, const Supports& s, double max_tilt_deg) {
  Vec3 n = Vec3::UnitY();
  for (const auto& sp : s.planes)  // the start's planes come in decreasing area: the first wall
    if (!sp.from_scan && near_vertical(sp.plane, max_tilt_deg)) {
      n = Vec3(sp.plane.n.x(), sp.plane.n.y(), 0.0).normalized();
      break;
    }
  Region r;
  r.axes.col(0) = along_wall(n);
  r.axes.col(1) = n;
  r.axes.col(2) = Vec3::UnitZ();
  Eigen::AlignedBox3d box;
  for (const auto& p : start.vertices) box.extend(r.axes.transpose() * p);
  for (const auto& pts : s.points)
    for (const auto& p : pts) box.extend(r.axes.transpose() * p);
  r.center = r.axes * box.center();
  r.half = 0.5 * box.sizes() + Vec3::Constant(kRegionMargin);
  return r;
}

std::vector<Region> plane_reach(const Mesh& start, const Supports& s, const Region& region, double margin) {
  std::vector<Eigen::AlignedBox3d> box(s.planes.size());  // in the region's axes
  for (std::size_t f = 0; f < start.faces.size(); ++f)
    if (s.face_plane[f] >= 0)
      for (int v : start.faces[f].v) box[s.face_plane[f]].extend(region.axes.transpose() * start.vertices[v]);
  for (std::size_t k = 0; k < s.points.size(); ++k)
    for (const auto& p : s.points[k]) box[k].extend(region.axes.transpose() * p);
  for (std::size_t k = 0; k < box.size(); ++k) {
    if (!box[k].isEmpty()) continue;
    // A hypothesised wall: the slab of the start and the evidence it can reach.
    const Plane& pl = s.planes[k].plane;
    for (const auto& p : start.vertices)
      if (std::abs(pl.distance(p)) <= margin) box[k].extend(region.axes.transpose() * p);
    for (const auto& pts : s.points)
      for (const auto& p : pts)
        if (std::abs(pl.distance(p)) <= margin) box[k].extend(region.axes.transpose() * p);
  }
  std::vector<Region> out(s.planes.size(), region);
  for (std::size_t k = 0; k < box.size(); ++k) {
    if (box[k].isEmpty()) continue;  // nothing near: the whole region
    out[k].center = region.axes * box[k].center();
    out[k].half = 0.5 * box[k].sizes() + Vec3::Constant(margin);
    if (s.planes[k].from_scan) {  // a street scan sees a wall's lower storeys: it runs ground to roof
      out[k].center.z() = region.center.z();
      out[k].half.z() = region.half.z();
    }
  }
  return out;
}

}  // namespace lodrefine::detail
