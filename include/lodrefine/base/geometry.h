// Small geometric helpers shared by the stages: planes, polygons, frames.
#pragma once
#include <array>
#include <optional>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

constexpr double kPi = 3.14159265358979323846;  // M_PI is POSIX, not C++17
constexpr double radians(double degrees) { return degrees * kPi / 180.0; }

// Oriented plane n·x + d = 0 with unit normal n.
struct Plane {
  Vec3 n = Vec3::UnitZ();
  double d = 0.0;
  Plane() = default;
  Plane(const Vec3& normal, double offset);
  static Plane through(const Vec3& point, const Vec3& normal);
  double distance(const Vec3& p) const { return n.dot(p) + d; }  // signed
  Vec3 project(const Vec3& p) const { return p - distance(p) * n; }
  Plane flipped() const { return Plane(-n, -d); }
  // Orthonormal in-plane basis (u, v) with u × v = n; u is horizontal unless the plane is.
  std::pair<Vec3, Vec3> basis() const;
};

// The horizontal direction along a wall whose outward normal is `n`: n's horizontal part turned
// +90 degrees about z, so that, seen from outside, it runs from left to right. Not normalized: its
// length is that of n's horizontal part (1 for a vertical unit normal, less for a tilted one, 0 for
// a horizontal plane); callers that need a unit vector normalize it.
inline Vec3 along_wall(const Vec3& n) { return Vec3(-n.y(), n.x(), 0.0); }

// The positions of a face's vertices, in order.
std::vector<Vec3> face_points(const Mesh& mesh, const Face& face);
// The mesh moved by `offset` (e.g. into or out of a local frame).
Mesh translated(Mesh mesh, const Vec3& offset);

// Axis-aligned bounding box of the points (of those listed in `subset`); an empty box (min
// above max) for none.
Eigen::AlignedBox3d bounding_box(const std::vector<Vec3>& pts);
Eigen::AlignedBox3d bounding_box(const std::vector<Vec3>& pts, const std::vector<int>& subset);
Eigen::AlignedBox2d bounding_box(const std::vector<Vec2>& pts);

// Least-squares (PCA) plane; the normal's sign is arbitrary. Needs >= 3 non-collinear points.
Plane fit_plane(const std::vector<Vec3>& pts);
// PCA plane oriented along the polygon's Newell normal (i.e. the face's outward side).
Plane polygon_plane(const std::vector<Vec3>& polygon);

// Newell normal (not normalised; its length is twice the area).
Vec3 newell_normal(const std::vector<Vec3>& polygon);
double polygon_area(const std::vector<Vec3>& polygon);
Vec3 polygon_centroid(const std::vector<Vec3>& polygon);  // area-weighted

// The point on three planes, solved with full pivoting; nullopt when they are (near) dependent.
std::optional<Vec3> meet(const Plane& a, const Plane& b, const Plane& c, double min_det = 1e-9);

// Angle between two normals in degrees, ignoring orientation (0..90).
double unoriented_angle_deg(const Vec3& a, const Vec3& b);

// 2D polygon helpers (coordinates in a plane's (u, v) basis).
double signed_area_2d(const std::vector<Vec2>& poly);
bool point_in_polygon_2d(const Vec2& p, const std::vector<Vec2>& poly);
// Distance from p to the segment ab.
double segment_distance_2d(const Vec2& p, const Vec2& a, const Vec2& b);
std::vector<Vec2> convex_hull_2d(std::vector<Vec2> pts);
// Area of the intersection of two convex CCW polygons.
double convex_intersection_area(const std::vector<Vec2>& a, const std::vector<Vec2>& b);
// The part of a simple polygon inside a convex one (Sutherland–Hodgman), in the simple one's
// orientation; empty when none. A non-convex `simple` may come out with bridging edges that
// enclose no area.
std::vector<Vec2> polygon_clipped_to_convex(const std::vector<Vec2>& simple, const std::vector<Vec2>& convex);
// Intersection area of a simple (possibly non-convex) polygon with a convex one.
double polygon_convex_intersection_area(const std::vector<Vec2>& simple, const std::vector<Vec2>& convex);

// Triangulates a planar simple polygon (ear clipping in its own plane); indices into polygon.
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vec3>& polygon);

// Calls fn(a, b, c, face) for every triangle of every face (ear clipping, face orientation kept).
template <class Fn>
void for_each_triangle(const Mesh& mesh, Fn&& fn) {
  std::vector<Vec3> poly;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    poly.clear();
    for (int v : mesh.faces[f].v) poly.push_back(mesh.vertices.at(v));
    for (const auto& t : triangulate_polygon(poly)) fn(poly[t[0]], poly[t[1]], poly[t[2]], int(f));
  }
}

}  // namespace lodrefine
