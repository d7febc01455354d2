#include <gtest/gtest.h>

#include "lodrefine/core/geometry.h"

using namespace lodrefine;

TEST(Geometry, TriangulatesAnLShapeWithoutOverlaps) {
  // The diagonal from (0,0) to (2,2) runs through the reflex vertex (1,1): not an ear.
  const std::vector<Vec3> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  const auto tris = triangulate_polygon(l);
  ASSERT_EQ(tris.size(), 4u);
  double area = 0.0;
  for (const auto& t : tris) {
    const Vec3 n = (l[t[1]] - l[t[0]]).cross(l[t[2]] - l[t[0]]);
    EXPECT_GT(n.z(), 0.0);  // same winding as the polygon
    area += 0.5 * n.norm();
  }
  EXPECT_NEAR(area, 3.0, 1e-12);
}

TEST(Geometry, MeetSolvesNearAxisAlignedPlanes) {
  // Refitted planes carry normal components like 1e-19: the meet must stay finite and exact.
  const Plane a(Vec3(1, 1e-19, -2e-19), -3), b(Vec3(3e-19, 1, 0), -4), c(Vec3(0, -1e-18, 1), -5);
  const auto x = meet(a, b, c);
  ASSERT_TRUE(x.has_value());
  EXPECT_NEAR((*x - Vec3(3, 4, 5)).norm(), 0.0, 1e-12);
  EXPECT_FALSE(meet(a, a, b).has_value());
}

TEST(Geometry, PolygonAreaAndCentroidAtGeoreferencedMagnitudes) {
  const Vec3 o(485123.25, 5801234.75, 40.0);
  const std::vector<Vec3> sq = {o, o + Vec3(4, 0, 0), o + Vec3(4, 0, 3), o + Vec3(0, 0, 3)};
  EXPECT_NEAR(polygon_area(sq), 12.0, 1e-9);
  EXPECT_NEAR((polygon_centroid(sq) - (o + Vec3(2, 0, 1.5))).norm(), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(polygon_plane(sq).n.y()), 1.0, 1e-12);
}

TEST(Geometry, ConvexClipAreas) {
  const std::vector<Vec2> a = {{0, 0}, {2, 0}, {2, 2}, {0, 2}}, b = {{1, 1}, {3, 1}, {3, 3}, {1, 3}};
  EXPECT_NEAR(convex_intersection_area(a, b), 1.0, 1e-12);
  const std::vector<Vec2> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};  // non-convex subject
  EXPECT_NEAR(polygon_convex_intersection_area(l, b), 0.0, 1e-12);
  EXPECT_NEAR(polygon_convex_intersection_area(l, a), 3.0, 1e-12);
  EXPECT_EQ(convex_hull_2d({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}}).size(), 4u);
}
