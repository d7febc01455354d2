#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "lodrefine/base/geometry.h"

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

// Many points take a filtered path (the points inside the eight extremes' polygon are dropped
// before the sort): its hull must be the few points' hull vertex for vertex, bit for bit.
TEST(Geometry, ConvexHullOfManyPointsIsTheHullOfItsCorners) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec2 o(485123.25, 5801234.75);  // georeferenced magnitudes
  for (int shape = 0; shape < 50; ++shape) {
    // A random convex polygon's corners.
    std::vector<Vec2> few;
    for (int i = 0; i < 3 + shape % 9; ++i) {
      const double a = 2 * kPi * u(rng);
      few.push_back(o + Vec2(std::cos(a) * (5 + 3 * u(rng)), std::sin(a) * (2 + u(rng))));
    }
    const std::vector<Vec2> corners = convex_hull_2d(few);
    ASSERT_GE(corners.size(), 3u);
    std::vector<Vec2> boundary = corners;  // and the edges' midpoints: (nearly) collinear
    for (std::size_t i = 0; i < corners.size(); ++i)
      boundary.push_back(0.5 * (corners[i] + corners[(i + 1) % corners.size()]));
    const std::vector<Vec2> expected = convex_hull_2d(boundary);  // under 64 points: the plain path
    Vec2 centre = Vec2::Zero();
    for (const auto& c : corners) centre += c - o;
    centre = o + centre / double(corners.size());
    std::vector<Vec2> many = boundary;
    while (many.size() < 2000) {  // convex combinations of three corners, pulled in: inside
      const Vec2 &a = corners[rng() % corners.size()], &b = corners[rng() % corners.size()],
                 &c = corners[rng() % corners.size()];
      const double s = u(rng), t = u(rng) * (1 - s);
      many.push_back(centre + 0.99 * (a + s * (b - a) + t * (c - a) - centre));
    }
    std::shuffle(many.begin(), many.end(), rng);
    const std::vector<Vec2> hull = convex_hull_2d(many);
    ASSERT_EQ(hull.size(), expected.size()) << shape;
    for (std::size_t i = 0; i < hull.size(); ++i) EXPECT_EQ(hull[i], expected[i]) << shape;
  }
  // A grid (many collinear points, ties in every direction) keeps its four corners.
  std::vector<Vec2> grid;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 20; ++j) grid.push_back(Vec2(0.1 * i, 0.1 * j));
  EXPECT_EQ(convex_hull_2d(grid).size(), 4u);
  EXPECT_NEAR(std::abs(signed_area_2d(convex_hull_2d(grid))), 2.9 * 1.9, 1e-12);
}

TEST(Geometry, AlongWallRunsLeftToRightSeenFromOutside) {
  // A south wall, counter-clockwise seen from outside (from the south): its bottom edge runs
  // from the left (x = 0) to the right (x = 4), along +x.
  const std::vector<Vec3> wall = {{0, 0, 0}, {4, 0, 0}, {4, 0, 3}, {0, 0, 3}};
  const Vec3 n = newell_normal(wall).normalized();
  ASSERT_NEAR((n - Vec3(0, -1, 0)).norm(), 0.0, 1e-15);
  EXPECT_EQ(along_wall(n), Vec3(1, 0, 0));
  EXPECT_EQ(along_wall(n).dot(wall[1] - wall[0]), 4.0);
  EXPECT_EQ(along_wall(Vec3(1, 0, 0)), Vec3(0, 1, 0));  // an east wall: along +y
  // Not normalized: a tilted normal gives its horizontal part's length, a roof's none.
  EXPECT_EQ(along_wall(Vec3(0.6, 0, 0.8)), Vec3(0, 0.6, 0));
  EXPECT_EQ(along_wall(Vec3(0, 0, 1)).norm(), 0.0);
  // Horizontal and perpendicular to the normal.
  const Vec3 t = Vec3(0.3, -0.5, 0.2).normalized();
  EXPECT_EQ(along_wall(t).z(), 0.0);
  EXPECT_NEAR(along_wall(t).dot(t), 0.0, 1e-15);
}
