// The planes a soup's holes need to close (hole_planes.h).
#include "hole_planes.h"

#include <algorithm>
#include <cmath>

#include "lodrefine/base/topology.h"
#include "lodrefine/core/matching.h"

namespace lodrefine::detail {

// A boundary edge shorter than this in plan (m) is vertical: the edges beside it give the wall.
constexpr double kPlanEdge = 0.05;

namespace {
// Whether a supporting plane already carries the plane `pl` through `a` and `b`.
bool carried(const Supports& s, const Plane& pl, const Vec3& a, const Vec3& b) {
  return std::any_of(s.planes.begin(), s.planes.end(), [&](const SupportPlane& sp) {
    return unoriented_angle_deg(sp.plane.n, pl.n) <= kSurfaceAngleDeg &&
           std::abs(sp.plane.distance(a)) <= kSurfaceDistance && std::abs(sp.plane.distance(b)) <= kSurfaceDistance;
  });
}

}  // namespace

void add_hole_planes(const Mesh& soup, Supports& s) {
  for (const auto& [key, uses] : edge_uses(soup.faces)) {
    if (uses.size() != 1) continue;
    const Vec3 &a = soup.vertices[key.first], &b = soup.vertices[key.second];
    const Vec3 d(b.x() - a.x(), b.y() - a.y(), 0.0);
    Vec3 n(-d.y(), d.x(), 0.0);  // the wall under a roof's or beside a wall's horizontal edge
    if (d.norm() < kPlanEdge) {  // a wall's vertical edge: the wall across its end
      const std::vector<Vec3> pts = face_points(soup, soup.faces[std::size_t(uses.front().face)]);
      n = (b - a).cross(polygon_plane(pts).n);
      n.z() = 0.0;
      if (n.norm() < 1e-6) continue;
    }
    const Plane wall = Plane::through(a, n.normalized());
    if (carried(s, wall, a, b)) continue;
    s.planes.push_back({wall, Semantic::Wall, false, -1, Provenance::Added});
    s.points.emplace_back();
    ++s.hole_planes;
  }
}

bool carries_ground(const Mesh& soup, const Supports& s) {
  if (soup.vertices.empty()) return false;
  const Eigen::AlignedBox3d box = bounding_box(soup.vertices);
  const Vec3 far_corner(box.max().x(), box.max().y(), box.min().z());
  return carried(s, Plane::through(box.min(), -Vec3::UnitZ()), box.min(), far_corner);
}

}  // namespace lodrefine::detail
