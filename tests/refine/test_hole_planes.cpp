// The planes a soup's holes need (hole_planes.h): a box missing a face.
#include <gtest/gtest.h>

#include <cmath>

#include "refine/hole_planes.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::detail;
using namespace lodrefine::fixtures;

namespace {

Mesh without_face(Mesh m, std::size_t f) {
  m.faces.erase(m.faces.begin() + std::ptrdiff_t(f));
  return m;
}

}  // namespace

TEST(HolePlanes, AMissingWallGetsItsPlaneOnce) {
  // The front wall (y = 0) gone: the ground's and the roof's front edges ask for the plane y = 0,
  // the side walls' vertical edges for the same plane across their ends: one plane.
  const Mesh soup = without_face(box({0, 0, 0}, {10, 8, 6}), 2);
  Supports s;
  add_start_planes(soup, 0.01, s);
  ASSERT_EQ(s.planes.size(), 5u);
  add_hole_planes(soup, s);
  EXPECT_EQ(s.hole_planes, 1);
  ASSERT_EQ(s.planes.size(), 6u);
  ASSERT_EQ(s.points.size(), 6u);
  const SupportPlane& hole = s.planes.back();
  EXPECT_NEAR(std::abs(hole.plane.n.y()), 1.0, 1e-12);
  EXPECT_NEAR(hole.plane.distance({3, 0, 2}), 0.0, 1e-12);
  EXPECT_EQ(hole.sem, Semantic::Wall);
  EXPECT_EQ(hole.provenance, Provenance::Added);
  EXPECT_FALSE(hole.from_scan);
  EXPECT_TRUE(s.points.back().empty());
}

TEST(HolePlanes, AMissingRoofNeedsNoPlaneTheWallsLackAndAClosedBoxNone) {
  // The roof gone: its edges are the walls' tops, on planes the walls carry; no plane is added
  // (the roof's own plane is not a wall under an edge).
  const Mesh open = without_face(box({0, 0, 0}, {10, 8, 6}), 1);
  Supports s;
  add_start_planes(open, 0.01, s);
  add_hole_planes(open, s);
  EXPECT_EQ(s.hole_planes, 0);
  EXPECT_EQ(s.planes.size(), 5u);
  Supports closed;
  add_start_planes(box({0, 0, 0}, {10, 8, 6}), 0.01, closed);
  add_hole_planes(box({0, 0, 0}, {10, 8, 6}), closed);
  EXPECT_EQ(closed.hole_planes, 0);
}

TEST(HolePlanes, GroundIsCarriedOnlyWithAGroundFace) {
  const Mesh whole = box({0, 0, 0}, {10, 8, 6});
  Supports s;
  add_start_planes(whole, 0.01, s);
  EXPECT_TRUE(carries_ground(whole, s));
  const Mesh floorless = without_face(whole, 0);
  Supports t;
  add_start_planes(floorless, 0.01, t);
  EXPECT_FALSE(carries_ground(floorless, t));
  EXPECT_FALSE(carries_ground(Mesh{}, t));
}
