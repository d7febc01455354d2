// Stage 6, judge: never worse, for the whole building (see judge.h).
#include "lodrefine/core/judge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <set>

#include "lodrefine/core/corners.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"

namespace lodrefine {
namespace {

// A face lies on a wall's plane when it faces the same way (cos 1 deg) and its vertices are
// within the surface grouping's distance of it (matching.h).
const double kSameFacing = std::cos(radians(kSurfaceAngleDeg));
constexpr double kOnPlane = kSurfaceDistance;

// A point's capped distance to each model.
struct PointFit {
  double before, after;
  int face_before, face_after;  // the nearest face of each mesh
  Vec3 p;
};

// The fit over `points` (those `take` accepts).
template <class Take>
Judgement::Fit fit_of(const std::vector<PointFit>& points, double changed, Take take) {
  Judgement::Fit f;
  double s0 = 0.0, s1 = 0.0;
  for (const auto& q : points) {
    if (!take(q)) continue;
    ++f.points;
    s0 += q.before * q.before;
    s1 += q.after * q.after;
    f.better += q.after < q.before - changed;
    f.worse += q.after > q.before + changed;
  }
  if (f.points > 0) {
    f.rms_before = std::sqrt(s0 / double(f.points));
    f.rms_after = std::sqrt(s1 / double(f.points));
  }
  return f;
}

// Why a fit is worse (empty when it is not): its RMS grew by more than `slack`, or (when
// `count` is set) more than kWorseShare of the points it changed got farther.
std::string worse_reason(const Judgement::Fit& f, double slack, bool count) {
  char buf[200];
  if (f.rms_after > f.rms_before + slack) {
    std::snprintf(buf, sizeof buf, "RMS of %zu scan points %.3f -> %.3f m", f.points, f.rms_before, f.rms_after);
    return buf;
  }
  if (count && double(f.worse) > kWorseShare * double(f.better + f.worse)) {
    std::snprintf(buf, sizeof buf, "%zu of %zu scan points farther, %zu closer", f.worse, f.points, f.better);
    return buf;
  }
  return {};
}

// The wall's points (WallPoints): the points whose nearest face is the wall's, before the move (a face on
// its old plane within its outline) or after it (a face on its new plane near that outline),
// and which lie on its old or its new plane (within `on_plane`). The points farther from both
// stand on other surfaces near the wall (a return, a neighbour, clutter): the building check
// judges them, and they must not decide whether the wall itself is scanned.
struct WallPoints {
  std::vector<char> before, after;  // per face of each mesh: the wall's
  const JudgedWall& wall;
  double on_plane;

  WallPoints(const JudgedWall& w, const Mesh& mb, const Mesh& ma, double margin, double reach, double band)
      : wall(w), on_plane(band) {
    before = faces_on(w, w.from, mb, margin);
    after = faces_on(w, w.to, ma, reach);
  }
  bool holds(const PointFit& q) const {
    return (before[std::size_t(q.face_before)] || after[std::size_t(q.face_after)]) &&
           (std::abs(wall.from.distance(q.p)) <= on_plane || std::abs(wall.to.distance(q.p)) <= on_plane);
  }
  // Faces of `m` on `plane` whose centroid projects into the wall's outline grown by `grow`.
  static std::vector<char> faces_on(const JudgedWall& w, const Plane& plane, const Mesh& m, double grow) {
    const auto [u, v] = w.from.basis();
    const Vec3 o = w.polygons.empty() || w.polygons.front().empty() ? Vec3::Zero() : w.polygons.front().front();
    std::vector<std::vector<Vec2>> outline;
    for (const auto& poly : w.polygons) {
      std::vector<Vec2> q;
      for (const auto& p : poly) q.emplace_back((p - o).dot(u), (p - o).dot(v));
      outline.push_back(std::move(q));
    }
    std::vector<char> on(m.faces.size(), 0);
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      const auto poly = face_points(m, m.faces[f]);
      bool flat = newell_normal(poly).normalized().dot(plane.n) > kSameFacing;
      for (const auto& p : poly) flat = flat && std::abs(plane.distance(p)) <= kOnPlane;
      if (!flat) continue;
      const Vec3 c = polygon_centroid(poly) - o;
      const Vec2 q(c.dot(u), c.dot(v));
      for (const auto& ring : outline) {
        bool in = point_in_polygon_2d(q, ring);
        for (std::size_t k = 0; k < ring.size() && !in; ++k)
          in = segment_distance_2d(q, ring[k], ring[(k + 1) % ring.size()]) <= grow;
        if (in) on[f] = 1;
      }
    }
    return on;
  }
};

// Whether p is a flush neighbour's: past a wall moved to the party wall, on or behind the
// facade's plane (its facade, window recesses and all).
bool neighbours(const Vec3& p, const std::vector<JudgedWall>& walls, double on_plane) {
  for (const auto& w : walls)
    if (w.flush_facade && w.flush_facade->distance(p) <= on_plane && w.to.distance(p) > 0) return true;
  return false;
}

// The scan plane each point of the cloud is an inlier of (-1: none).
std::vector<int> plane_of(const std::vector<ScanPlane>& planes, std::size_t points) {
  std::vector<int> of(points, -1);
  for (std::size_t k = 0; k < planes.size(); ++k)
    for (int i : planes[k].inliers)
      if (i >= 0 && std::size_t(i) < points) of[std::size_t(i)] = int(k);
  return of;
}

std::vector<Plane> face_planes(const Mesh& m) {
  std::vector<Plane> out;
  for (const auto& f : m.faces) out.push_back(polygon_plane(face_points(m, f)));
  return out;
}

// Where along each face of a mesh its own points stand: the columns (kColumn wide, along the
// face's horizontal direction) holding a point within the cap whose nearest face it is. A
// facade line beyond the cap that stands before a column of the face's own points is another
// object before the wall (a neighbour across an alley, seen past or over); where the face has
// no points of its own, it is the building's facade stepping forward (a setback's front line).
constexpr double kColumn = 0.5;  // m; a column's neighbours count too (window gaps up to ~1 m)
long long column_of(const Vec3& p, const Plane& f) { return (long long)std::floor(along_wall(f.n).dot(p) / kColumn); }

// One model as the judge sees it: distances to it, its faces' planes and, when facade lines
// beyond the cap are judged, the columns of each face's own points.
struct Side {
  MeshDistance distance;
  std::vector<Plane> faces;              // per face, its plane
  std::vector<std::set<long long>> own;  // per face, the columns holding its own points (facade lines only)

  bool facade_lines;

  Side(const Mesh& m, bool lines) : distance(m), faces(face_planes(m)), own(faces.size()), facade_lines(lines) {}

  // Records `p` (nearest face `near`) as a point of that face's own when within `cap` of it.
  void note(const Vec3& p, const MeshDistance::Nearest& near, double cap) {
    if (facade_lines && near.distance <= cap)
      own[std::size_t(near.face)].insert(column_of(p, faces[std::size_t(near.face)]));
  }

  // Whether the scan plane `scan`'s inlier `p` faces its nearest face `near`: turned from it by at
  // most `max_angle_deg`, its foot on the face's plane inside the face (its distance is the plane
  // distance, not beside the model).
  bool faces_face(const Vec3& p, const Plane& scan, const MeshDistance::Nearest& near, double max_angle_deg,
                  double tolerance) const {
    const Plane& f = faces[std::size_t(near.face)];
    return unoriented_angle_deg(scan.n, f.n) <= max_angle_deg && std::abs(f.distance(p)) >= near.distance - tolerance;
  }

  // Whether the facade plane `scan`'s inlier `p` (nearest face `near`) is judged up to `reach`
  // here: within it, facing its face, and standing before no column of that face's own points.
  bool reaches(const Vec3& p, const Plane& scan, const MeshDistance::Nearest& near, double reach, double max_angle_deg,
               double tolerance) const {
    if (near.distance > reach || !faces_face(p, scan, near, max_angle_deg, tolerance)) return false;
    const Plane& f = faces[std::size_t(near.face)];
    const long long c = column_of(p, f);
    const auto& columns = own[std::size_t(near.face)];
    return !(columns.count(c - 1) || columns.count(c) || columns.count(c + 1));
  }
};

// Returns from behind a scanned wall's openings (a room seen through glass, a pane in its
// reveal): between kBehindWall and kRoomDepth behind a facade plane, in a column (kColumn wide)
// where the wall's own points stand above and below them, and inside both models by kBehindWall
// (not a wall of either: the building's own wall behind a neighbour's standing before it). They show what is behind the
// facade, not where it is: the judge leaves them out, whichever way a wall moved.
constexpr double kBehindWall = 0.1, kRoomDepth = 6.0;  // m
class Openings {
 public:
  // `model` with its distances, and the other model's distances (the judge's own, not built again).
  Openings(const std::vector<ScanPlane>& planes, const PointCloud& cloud, const Mesh& model,
           const MeshDistance& distance, const MeshDistance& other)
      : distance_(distance), other_(other) {
    const auto normals = face_planes(model);
    for (const auto& sp : planes) {
      if (!sp.facade || sp.inliers.empty() || normals.empty()) continue;
      Wall w{sp.plane, {}};
      const int f = distance_.nearest(sp.centroid, false).face;
      if (f >= 0 && w.plane.n.dot(normals[std::size_t(f)].n) < 0) w.plane = w.plane.flipped();
      for (int i : sp.inliers) {
        const Vec3& q = cloud.points[std::size_t(i)];
        auto [it, fresh] = w.columns.try_emplace(column_of(q, w.plane), q.z(), q.z());
        if (!fresh)
          it->second.first = std::min(it->second.first, q.z()), it->second.second = std::max(it->second.second, q.z());
      }
      walls_.push_back(std::move(w));
    }
  }
  bool behind(const Vec3& p) const {
    for (const auto& w : walls_) {
      const double d = w.plane.distance(p);
      if (d > -kBehindWall || d < -kRoomDepth) continue;
      const auto it = w.columns.find(column_of(p, w.plane));
      if (it != w.columns.end() && it->second.first < p.z() && p.z() < it->second.second)
        return distance_.distance(p, true) < -kBehindWall && other_.distance(p, true) < -kBehindWall;
    }
    return false;
  }

 private:
  struct Wall {
    Plane plane;                                             // outwards
    std::map<long long, std::pair<double, double>> columns;  // the lowest and highest inlier per column
  };
  const MeshDistance &distance_, &other_;
  std::vector<Wall> walls_;
};

// Whether `p` (off both models' surfaces, nearest faces `a` and `b`, inlier of scan plane `plane`
// or -1) is consistent with both models: outside both, and on no scan plane that faces its
// nearest face in either. Such a return (a car, a tree, a neighbour's wall past the corner) says
// only that the space it stands in is empty, which both models agree on: it is no evidence of
// where the building's surface lies, and would count against any wall that moves away from it.
bool in_free_space(const Vec3& p, int plane, const std::vector<ScanPlane>& planes, const Side& s0, const Side& s1,
                   const MeshDistance::Nearest& a, const MeshDistance::Nearest& b, double on_plane,
                   double max_angle_deg, double tolerance) {
  if (plane >= 0) {
    const Plane& scan = planes[std::size_t(plane)].plane;
    if (s0.faces_face(p, scan, a, max_angle_deg, tolerance) || s1.faces_face(p, scan, b, max_angle_deg, tolerance))
      return false;
  }
  return s0.distance.distance(p, true) > on_plane && s1.distance.distance(p, true) > on_plane;
}

// The points near either model with their capped distances: within `cap` of one, or a facade
// line's within `reach` where it stands before no points of the face it faces (judge.h).
std::vector<PointFit> judged_points(const Mesh& before, const Mesh& after, const std::vector<JudgedWall>& walls,
                                    const PointCloud& cloud, const std::vector<ScanPlane>& planes, double cap,
                                    double reach, double max_angle_deg, const PlaneEvidence& detection) {
  const double on_plane = on_plane_band(detection);
  reach = std::max(reach, cap);
  const bool facade_lines = reach > cap;
  Eigen::AlignedBox3d box = bounding_box(before.vertices);
  box.extend(bounding_box(after.vertices));
  const double ground = box.min().z() + kStreetGroundBand;
  Eigen::AlignedBox3d within_cap = box;  // beyond it only a facade line's points are judged
  within_cap.min() -= Vec3::Constant(cap);
  within_cap.max() += Vec3::Constant(cap);
  box.min() -= Vec3::Constant(reach);
  box.max() += Vec3::Constant(reach);
  Side s0(before, facade_lines), s1(after, facade_lines);
  const std::vector<int> on = plane_of(planes, cloud.points.size());
  const auto facade_of = [&](std::size_t i) { return on[i] >= 0 && planes[std::size_t(on[i])].facade ? on[i] : -1; };
  const Openings openings(planes, cloud, before, s0.distance, s1.distance);
  std::vector<std::size_t> judged;  // the cloud's points near enough to be judged
  std::vector<Vec3> at;
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const Vec3& p = cloud.points[i];
    if (!box.contains(p) || (facade_of(i) < 0 && !within_cap.contains(p)) || p.z() < ground ||
        neighbours(p, walls, on_plane) || openings.behind(p))
      continue;
    judged.push_back(i);
    at.push_back(p);
  }
  const auto near0 = s0.distance.nearest_all(at), near1 = s1.distance.nearest_all(at);
  for (std::size_t k = 0; k < at.size(); ++k) {
    s0.note(at[k], near0[k], cap);
    s1.note(at[k], near1[k], cap);
  }
  const double tol = detection.ransac_epsilon;
  std::vector<PointFit> out;
  for (std::size_t k = 0; k < at.size(); ++k) {
    const std::size_t i = judged[k];
    const Vec3& p = at[k];
    const MeshDistance::Nearest &a = near0[k], &b = near1[k];
    double c = cap;
    if (facade_lines && facade_of(i) >= 0 && std::min(a.distance, b.distance) > cap) {
      const Plane& scan = planes[std::size_t(on[i])].plane;
      if (s0.reaches(p, scan, a, reach, max_angle_deg, tol) || s1.reaches(p, scan, b, reach, max_angle_deg, tol))
        c = reach;
    }
    if (a.distance > c && b.distance > c) continue;
    if (std::min(a.distance, b.distance) > on_plane &&
        in_free_space(p, on[i], planes, s0, s1, a, b, on_plane, max_angle_deg, tol))
      continue;
    out.push_back({std::min(a.distance, c), std::min(b.distance, c), a.face, b.face, p});
  }
  return out;
}

}  // namespace

Judgement judge_refinement(const Mesh& before, const Mesh& after, const std::vector<JudgedWall>& walls,
                           const PointCloud& cloud, const MatchConfig& prm, const PlaneEvidence& detection,
                           const std::vector<ScanPlane>& planes, double facade_reach) {
  Judgement j;
  const double cap = prm.match_distance, changed = detection.ransac_epsilon;
  std::vector<PointFit> points;
  try {
    points = judged_points(before, after, walls, cloud, planes, cap, facade_reach, prm.match_angle_deg, detection);
  } catch (const InputError& e) {
    j.ok = false;
    j.check = JudgeCheck::Building;
    j.detail = e.what();
    return j;
  }
  j.building = fit_of(points, changed, [](const PointFit&) { return true; });
  for (const auto& w : walls) {
    const WallPoints own(w, before, after, prm.match_margin, cap, on_plane_band(detection));
    j.walls.push_back(fit_of(points, changed, [&](const PointFit& q) { return own.holds(q); }));
  }
  if (const std::string why = worse_reason(j.building, kRmsSlack, true); !why.empty()) {
    j.ok = false;
    j.check = JudgeCheck::Building;
    j.detail = why;
    return j;
  }
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const Judgement::Fit& f = j.walls[k];
    std::string why;
    if (f.points < std::size_t(detection.ransac_min_points)) {
      if (!walls[k].corner)
        why = "moved with " + std::to_string(f.points) + " scan points in front of it and no corner evidence";
    } else {
      why = worse_reason(f, kWallRmsSlack, false);
    }
    if (!why.empty()) {
      j.ok = false;
      j.check = JudgeCheck::Wall;
      j.wall = int(k);
      j.detail = "moved wall " + std::to_string(k) + ": " + why;
      return j;
    }
  }
  const auto wall_gained = [](const Judgement::Fit& f) { return f.rms_before - f.rms_after >= kMinRmsGain; };
  if (j.building.better < std::size_t(kMinGain) && std::none_of(j.walls.begin(), j.walls.end(), wall_gained)) {
    j.ok = false;
    j.check = JudgeCheck::Gain;
    j.detail = std::to_string(j.building.better) + " scan points closer than before (" + std::to_string(kMinGain) +
               " needed) and no moved wall's RMS down by 1 mm: the scan shows no change";
  }
  return j;
}

}  // namespace lodrefine
