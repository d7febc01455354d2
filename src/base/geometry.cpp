#include "lodrefine/base/geometry.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace lodrefine {

Plane::Plane(const Vec3& normal, double offset) {
  const double len = normal.norm();
  n = len > 0 ? Vec3(normal / len) : Vec3(Vec3::UnitZ());
  d = len > 0 ? offset / len : 0.0;
}

Plane Plane::through(const Vec3& point, const Vec3& normal) {
  Plane p(normal, 0.0);
  p.d = -p.n.dot(point);
  return p;
}

std::pair<Vec3, Vec3> Plane::basis() const {
  // Horizontal u for non-horizontal planes keeps facade coordinates readable (u along the wall).
  Vec3 u = Vec3::UnitZ().cross(n);
  if (u.norm() < 1e-6) u = n.cross(Vec3::UnitX()).cross(n) * -1.0;
  if (u.norm() < 1e-6) u = Vec3::UnitX();
  u.normalize();
  Vec3 v = n.cross(u).normalized();
  return {u, v};
}

std::vector<Vec3> face_points(const Mesh& mesh, const Face& face) {
  std::vector<Vec3> pts;
  pts.reserve(face.v.size());
  for (int i : face.v) pts.push_back(mesh.vertices[i]);
  return pts;
}

Mesh translated(Mesh mesh, const Vec3& offset) {
  for (auto& v : mesh.vertices) v += offset;
  return mesh;
}

Plane fit_plane(const std::vector<Vec3>& pts) {
  Vec3 c = Vec3::Zero();
  for (const auto& p : pts) c += p;
  c /= std::max<std::size_t>(1, pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) {
    const Vec3 q = p - c;
    cov += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Vec3 n = es.eigenvectors().col(0);
  // Snap numerically-zero components: CGAL-style downstream code misbehaves on 1e-19 normals.
  for (int i = 0; i < 3; ++i)
    if (std::abs(n[i]) < 1e-12) n[i] = 0.0;
  return Plane::through(c, n);
}

Vec3 newell_normal(const std::vector<Vec3>& poly) {
  Vec3 n = Vec3::Zero();
  if (poly.empty()) return n;
  const Vec3 o = poly[0];  // relative coordinates keep precision at georeferenced magnitudes
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3 a = poly[i] - o, b = poly[(i + 1) % poly.size()] - o;
    n += a.cross(b);
  }
  return n;
}

double polygon_area(const std::vector<Vec3>& poly) { return 0.5 * newell_normal(poly).norm(); }

Eigen::AlignedBox3d bounding_box(const std::vector<Vec3>& pts) {
  Eigen::AlignedBox3d box;
  for (const Vec3& p : pts) box.extend(p);
  return box;
}

Eigen::AlignedBox3d bounding_box(const std::vector<Vec3>& pts, const std::vector<int>& subset) {
  Eigen::AlignedBox3d box;
  for (int i : subset) box.extend(pts[i]);
  return box;
}

Eigen::AlignedBox2d bounding_box(const std::vector<Vec2>& pts) {
  Eigen::AlignedBox2d box;
  for (const Vec2& p : pts) box.extend(p);
  return box;
}

Vec3 polygon_centroid(const std::vector<Vec3>& poly) {
  if (poly.empty()) return Vec3::Zero();
  const Vec3 o = poly[0];
  const Vec3 nn = newell_normal(poly);
  Vec3 acc = Vec3::Zero();
  double wsum = 0.0;
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
    const Vec3 a = poly[i] - o, b = poly[i + 1] - o;
    const double w = a.cross(b).dot(nn);  // signed, handles non-convex fans
    acc += w * (a + b) / 3.0;
    wsum += w;
  }
  if (std::abs(wsum) < 1e-18) {
    Vec3 m = Vec3::Zero();
    for (const auto& p : poly) m += p;
    return m / double(poly.size());
  }
  return o + acc / wsum;
}

Plane polygon_plane(const std::vector<Vec3>& poly) {
  Plane p = fit_plane(poly);
  if (p.n.dot(newell_normal(poly)) < 0) p = p.flipped();
  return p;
}

std::optional<Vec3> meet(const Plane& a, const Plane& b, const Plane& c, double min_det) {
  Eigen::Matrix3d m;
  m.row(0) = a.n.transpose();
  m.row(1) = b.n.transpose();
  m.row(2) = c.n.transpose();
  if (std::abs(m.determinant()) < min_det) return std::nullopt;
  const Vec3 rhs(-a.d, -b.d, -c.d);
  Vec3 x = m.fullPivLu().solve(rhs);
  if (!x.allFinite()) return std::nullopt;
  return x;
}

double unoriented_angle_deg(const Vec3& a, const Vec3& b) {
  const double c = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return std::acos(c) * 180.0 / kPi;
}

double signed_area_2d(const std::vector<Vec2>& poly) {
  double a = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

double segment_distance_2d(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

bool point_in_polygon_2d(const Vec2& p, const std::vector<Vec2>& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) in = !in;
    }
  }
  return in;
}

namespace {
// Points below this many go straight to the monotone chain.
constexpr std::size_t kHullFilterMin = 64;

// Akl–Toussaint: the points extreme in eight directions span a convex polygon inside the hull;
// a point inside it by a margin can be no hull vertex, so dropping it leaves the hull (and the
// chain's output, vertex for vertex) as it was, and the sort runs on the few points left.
std::vector<Vec2> outside_extremes(std::vector<Vec2> pts) {
  static const Vec2 kDirections[8] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
  std::size_t extreme[8] = {};  // per direction, the first point farthest along it
  for (std::size_t i = 1; i < pts.size(); ++i)
    for (int k = 0; k < 8; ++k)
      if (kDirections[k].dot(pts[i]) > kDirections[k].dot(pts[extreme[k]])) extreme[k] = i;
  std::vector<Vec2> poly;
  for (std::size_t i : extreme)
    if (poly.empty() || (pts[i] != poly.back() && pts[i] != poly.front())) poly.push_back(pts[i]);
  Eigen::AlignedBox2d box;
  for (const Vec2& v : poly) box.extend(v);
  if (poly.size() < 3 || !box.diagonal().allFinite()) return pts;
  // Far above the cross products' rounding (~1e-16 of the box's squared size): a point this close
  // to the polygon's boundary stays.
  const double margin = 1e-9 * box.diagonal().squaredNorm();
  auto inside = [&](const Vec2& p) {
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2 &a = poly[i], &b = poly[(i + 1) % poly.size()];
      if ((b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) <= margin) return false;
    }
    return true;
  };
  pts.erase(std::remove_if(pts.begin(), pts.end(), inside), pts.end());
  return pts;
}
}  // namespace

std::vector<Vec2> convex_hull_2d(std::vector<Vec2> pts) {
  if (pts.size() >= kHullFilterMin) pts = outside_extremes(std::move(pts));
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Vec2> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  return h;
}

namespace {
// Sutherland–Hodgman: clips any polygon by one half-plane (left of a->b). Degenerate bridging
// edges may appear for non-convex subjects, but they enclose no area, so areas stay exact.
std::vector<Vec2> clip_half_plane(const std::vector<Vec2>& poly, const Vec2& a, const Vec2& b) {
  std::vector<Vec2> out;
  const Vec2 e = b - a;
  auto side = [&](const Vec2& p) { return e.x() * (p.y() - a.y()) - e.y() * (p.x() - a.x()); };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    const double sp = side(p), sq = side(q);
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
  }
  return out;
}
}  // namespace

std::vector<Vec2> polygon_clipped_to_convex(const std::vector<Vec2>& simple, const std::vector<Vec2>& convex) {
  if (simple.size() < 3 || convex.size() < 3) return {};
  std::vector<Vec2> clip = convex;
  if (signed_area_2d(clip) < 0) std::reverse(clip.begin(), clip.end());
  std::vector<Vec2> poly = simple;
  for (std::size_t i = 0; i < clip.size() && poly.size() >= 3; ++i)
    poly = clip_half_plane(poly, clip[i], clip[(i + 1) % clip.size()]);
  if (poly.size() < 3) poly.clear();
  return poly;
}

double polygon_convex_intersection_area(const std::vector<Vec2>& simple, const std::vector<Vec2>& convex) {
  return std::abs(signed_area_2d(polygon_clipped_to_convex(simple, convex)));
}

double convex_intersection_area(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  return polygon_convex_intersection_area(a, b);
}

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vec3>& polygon) {
  std::vector<std::array<int, 3>> tris;
  const int n = int(polygon.size());
  if (n < 3) return tris;
  const Plane pl = polygon_plane(polygon);
  const auto [u, v] = pl.basis();
  std::vector<Vec2> p(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 q = polygon[i] - polygon[0];
    p[i] = Vec2(q.dot(u), q.dot(v));
  }
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  if (signed_area_2d(p) < 0) std::reverse(idx.begin(), idx.end());
  auto cross = [&](int a, int b, int c) {
    return (p[b].x() - p[a].x()) * (p[c].y() - p[a].y()) - (p[b].y() - p[a].y()) * (p[c].x() - p[a].x());
  };
  // Closed triangle: a diagonal running through a reflex vertex is no ear. Vertices at the
  // ear's own corners (repeated positions) do not block it.
  auto inside = [&](int a, int b, int c, int q) {
    if (p[q] == p[a] || p[q] == p[b] || p[q] == p[c]) return false;
    return cross(a, b, q) >= 0 && cross(b, c, q) >= 0 && cross(c, a, q) >= 0;
  };
  int guard = 0;
  while (idx.size() > 3 && guard++ < 10 * n * n) {
    bool clipped = false;
    const int m = int(idx.size());
    for (int i = 0; i < m; ++i) {
      const int a = idx[(i + m - 1) % m], b = idx[i], c = idx[(i + 1) % m];
      if (cross(a, b, c) <= 1e-14) continue;
      bool ear = true;
      for (int q : idx)
        if (q != a && q != b && q != c && inside(a, b, c, q)) {
          ear = false;
          break;
        }
      if (!ear) continue;
      tris.push_back({a, b, c});
      idx.erase(idx.begin() + i);
      clipped = true;
      break;
    }
    if (!clipped) {  // degenerate (collinear) remainder: fan it so no area is lost
      for (std::size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
      idx.clear();
    }
  }
  if (idx.size() == 3) tris.push_back({idx[0], idx[1], idx[2]});
  // Restore the polygon's own orientation.
  if (signed_area_2d(p) < 0)
    for (auto& t : tris) std::swap(t[1], t[2]);
  return tris;
}

}  // namespace lodrefine
