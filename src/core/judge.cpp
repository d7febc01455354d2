// Stage 5: never worse, for the whole building (see judge.h).
#include "lodrefine/core/judge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

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

// The wall's region: the points whose nearest face is the wall's, before the move (a face on
// its old plane within its outline) or after it (a face on its new plane near that outline).
struct Region {
  std::vector<char> before, after;  // per face of each mesh: the wall's

  Region(const JudgedWall& w, const Mesh& mb, const Mesh& ma, double margin, double reach) {
    before = faces_on(w, w.from, mb, margin);
    after = faces_on(w, w.to, ma, reach);
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

// The points near either model with their capped distances.
std::vector<PointFit> judged_points(const Mesh& before, const Mesh& after, const std::vector<JudgedWall>& walls,
                                    const PointCloud& cloud, double cap, double on_plane) {
  Eigen::AlignedBox3d box = bounding_box(before.vertices);
  box.extend(bounding_box(after.vertices));
  const double ground = box.min().z() + kGroundBand;
  box.min() -= Vec3::Constant(cap);
  box.max() += Vec3::Constant(cap);
  const MeshDistance d0(before), d1(after);
  std::vector<PointFit> out;
  for (const auto& p : cloud.points) {
    if (!box.contains(p) || p.z() < ground || neighbours(p, walls, on_plane)) continue;
    const auto a = d0.nearest(p, false), b = d1.nearest(p, false);
    if (a.distance > cap && b.distance > cap) continue;
    out.push_back({std::min(a.distance, cap), std::min(b.distance, cap), a.face, b.face});
  }
  return out;
}

}  // namespace

Judgement judge_refinement(const Mesh& before, const Mesh& after, const std::vector<JudgedWall>& walls,
                           const PointCloud& cloud, const MatchConfig& prm, const PlaneConfig& detection) {
  Judgement j;
  const double cap = prm.match_distance, changed = detection.ransac_epsilon;
  std::vector<PointFit> points;
  try {
    points = judged_points(before, after, walls, cloud, cap, on_plane_band(detection));
  } catch (const InputError& e) {
    j.ok = false;
    j.check = "building";
    j.detail = e.what();
    return j;
  }
  j.building = fit_of(points, changed, [](const PointFit&) { return true; });
  for (const auto& w : walls) {
    const Region region(w, before, after, prm.match_margin, cap);
    j.walls.push_back(fit_of(points, changed, [&](const PointFit& q) {
      return region.before[std::size_t(q.face_before)] || region.after[std::size_t(q.face_after)];
    }));
  }
  if (const std::string why = worse_reason(j.building, kRmsSlack, true); !why.empty()) {
    j.ok = false;
    j.check = "building";
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
      j.check = "wall";
      j.detail = "moved wall " + std::to_string(k) + ": " + why;
      return j;
    }
  }
  const auto wall_gained = [](const Judgement::Fit& f) { return f.rms_before - f.rms_after >= kMinRmsGain; };
  if (j.building.better < std::size_t(kMinGain) && std::none_of(j.walls.begin(), j.walls.end(), wall_gained)) {
    j.ok = false;
    j.check = "gain";
    j.detail = std::to_string(j.building.better) + " scan points closer than before (" + std::to_string(kMinGain) +
               " needed) and no moved wall's RMS down by 1 mm: the scan shows no change";
  }
  return j;
}

}  // namespace lodrefine
