// The supporting planes of a building's arrangement and its region (shell_supports.h), on a box
// 10 x 8 x 6 and facades scanned before it: numbers worked by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "refine/shell_supports.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::detail;
using namespace lodrefine::fixtures;

namespace {

const Mesh kBox = box({0, 0, 0}, {10, 8, 6});

// The supporting plane the start face with centroid `at` lies on.
int plane_of_face_at(const Mesh& start, const Supports& s, const Vec3& at) {
  for (std::size_t f = 0; f < start.faces.size(); ++f)
    if ((polygon_centroid(face_points(start, start.faces[f])) - at).norm() < 1e-9) return s.face_plane[f];
  return -1;
}

// A recessed front: the facade y = 0 scanned over x in [0, 4] (it carries the start's front
// wall), the recess's back y = 1 over x in [4, 9.9], z in [0.05, 5.95] (a plane the start lacks;
// its points inside the front wall's outline, none on its edges).
struct Recess {
  Supports s;
  int front = -1, back = -1;
};
Recess recess() {
  Recess r;
  add_start_planes(kBox, 0.01, r.s);
  PointCloud cloud;
  std::vector<ScanPlane> scan{grid_scan_plane(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 4.0, 0.0, 6.0), 0.1),
                              grid_scan_plane(cloud, wall_patch({4, 1, 0}, Vec3::UnitX(), 5.9, 0.05, 5.95), 0.1)};
  add_scan_planes(kBox, cloud, scan, RefineConfig{}, r.s);
  r.front = plane_of_face_at(kBox, r.s, {5, 0, 3});
  r.back = int(r.s.planes.size()) - 1;
  return r;
}

}  // namespace

TEST(ShellSupports, StartPlanesOnePerSurfaceLargestFirst) {
  Mesh start = kBox;
  start.faces[2].provenance = Provenance::Scan;  // the front wall, moved onto its scan plane
  Supports s;
  add_start_planes(start, 0.01, s);
  ASSERT_EQ(s.planes.size(), 6u);
  EXPECT_EQ(s.start_planes, 6);
  EXPECT_EQ(s.points.size(), 6u);
  std::vector<int> seen = s.face_plane;
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(s.planes[0].sem == Semantic::Ground || s.planes[0].sem == Semantic::Roof);  // 80 m² first
  EXPECT_EQ(s.planes[std::size_t(s.face_plane[2])].provenance, Provenance::Scan);
  EXPECT_EQ(s.planes[std::size_t(s.face_plane[3])].provenance, Provenance::Model);
  for (const auto& sp : s.planes) EXPECT_FALSE(sp.from_scan);
}

// A 1 cm strip closing the roof 5 mm above it at the right wall's top (a hole filled between a
// jittered eave and its wall): its normal is 27° off the roof's, noise at that width, so it lies
// on the roof's plane when its vertices are within the planarity tolerance of it, else on its own.
TEST(ShellSupports, ASliverWithinThePlanarityToleranceLiesOnTheNearestPlaneInAngle) {
  Mesh start;
  start.vertices = {{0, 0, 0},    {10, 0, 0},     {10, 8, 0},     {0, 8, 0},    {0, 0, 6},
                    {9.99, 0, 6}, {10, 0, 6.005}, {10, 8, 6.005}, {9.99, 8, 6}, {0, 8, 6}};
  start.faces = {{{0, 3, 2, 1}, Semantic::Ground},  {{4, 5, 8, 9}, Semantic::Roof}, {{5, 6, 7, 8}, Semantic::Roof},
                 {{0, 1, 6, 5, 4}, Semantic::Wall}, {{1, 2, 7, 6}, Semantic::Wall}, {{2, 3, 9, 8, 7}, Semantic::Wall},
                 {{3, 0, 4, 9}, Semantic::Wall}};
  Supports within;
  add_start_planes(start, 0.01, within);
  EXPECT_EQ(within.planes.size(), 6u);
  EXPECT_EQ(within.face_plane[2], within.face_plane[1]);  // the strip on the roof's plane
  Supports beyond;
  add_start_planes(start, 0.001, beyond);
  EXPECT_EQ(beyond.planes.size(), 7u);
  EXPECT_NE(beyond.face_plane[2], beyond.face_plane[1]);
  EXPECT_NE(beyond.face_plane[2], beyond.face_plane[4]);  // nor the right wall's
}

TEST(ShellSupports, ScanFacadesJoinThePlaneTheyLieOnOrAddOne) {
  Supports s;
  add_start_planes(kBox, 0.01, s);
  PointCloud cloud;
  const std::vector<ScanPlane> scan{
      grid_scan_plane(cloud, wall_patch({0, -0.03, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.1),  // on the front
      grid_scan_plane(cloud, wall_patch({0, -0.6, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.1),   // 0.6 m before
      grid_scan_plane(cloud, wall_patch({0, -30, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.1)};   // across the street
  add_scan_planes(kBox, cloud, scan, RefineConfig{}, s);
  const int front = plane_of_face_at(kBox, s, {5, 0, 3});
  EXPECT_EQ(s.added, 1);
  ASSERT_EQ(s.planes.size(), 7u);
  EXPECT_EQ(s.points[std::size_t(front)].size(), 101u * 61u);
  EXPECT_EQ(s.points[6].size(), 101u * 61u);
  EXPECT_TRUE(s.planes[6].from_scan);
  EXPECT_EQ(s.planes[6].source, 1);
  EXPECT_EQ(s.planes[6].provenance, Provenance::Scan);
  EXPECT_NEAR(std::abs(s.planes[6].plane.distance({5, -0.6, 3})), 0.0, 1e-12);
}

TEST(ShellSupports, AStepWallStandsWhereARecessedFacadeEnds) {
  Recess r = recess();
  const std::size_t before = r.s.planes.size();
  ASSERT_EQ(before, 7u);  // the box's six and the recess's back
  add_step_walls(kBox, RefineConfig{}, r.s);
  ASSERT_EQ(r.s.planes.size(), 8u);  // one wall at x = 4 (both facades end there)
  const SupportPlane& step = r.s.planes.back();
  EXPECT_NEAR(std::abs(step.plane.n.x()), 1.0, 1e-12);
  EXPECT_NEAR(step.plane.distance({4, 0.5, 3}), 0.0, 1e-9);
  EXPECT_EQ(step.provenance, Provenance::Added);
  EXPECT_TRUE(r.s.points.back().empty());
}

TEST(ShellSupports, StepVolumeSweepsTheRecessOntoTheWallItReplaces) {
  Recess r = recess();
  const std::size_t points = r.s.points[std::size_t(r.back)].size();
  ASSERT_EQ(points, 60u * 60u);
  // 1 m deep, sampled every 2 m: each point once, on the front wall.
  const auto once = step_volume_samples(kBox, r.s, RefineConfig{}, 2.0);
  ASSERT_EQ(once.size(), points);
  for (const Vec3& p : once) EXPECT_NEAR(p.y(), 0.0, 1e-9);
  // Every 0.4 m: 0.4, 0.8 and the wall at 1.0 behind each point.
  const auto thrice = step_volume_samples(kBox, r.s, RefineConfig{}, 0.4);
  ASSERT_EQ(thrice.size(), 3 * points);
  EXPECT_NEAR(thrice[0].y(), 0.6, 1e-9);
  EXPECT_NEAR(thrice[1].y(), 0.2, 1e-9);
  EXPECT_NEAR(thrice[2].y(), 0.0, 1e-9);
}

TEST(ShellSupports, RegionAndPlaneReach) {
  Supports s;
  add_start_planes(kBox, 0.01, s);
  const Region region = building_region(kBox, s, 10.0);
  EXPECT_NEAR((region.center - Vec3(5, 4, 3)).norm(), 0.0, 1e-9);
  // In the axes of the largest wall (along x, its normal, up), 1 m beyond the box.
  EXPECT_NEAR(std::abs(region.axes.col(0).x()), 1.0, 1e-12);
  EXPECT_NEAR((region.half - Vec3(6, 5, 4)).norm(), 0.0, 1e-9);
  const auto reach = plane_reach(kBox, s, region, 0.5);
  ASSERT_EQ(reach.size(), 6u);
  const int front = plane_of_face_at(kBox, s, {5, 0, 3});
  // Its face grown by 0.5 m: 11 m along, 1 m across, 7 m up.
  EXPECT_NEAR((reach[std::size_t(front)].half - Vec3(5.5, 0.5, 3.5)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((reach[std::size_t(front)].center - Vec3(5, 0, 3)).norm(), 0.0, 1e-9);
}
