// The plane fitted to a point set, a wall seen twice by two drives joined midway, and relief
// (wall_layers.h, planes.h), on noise-free grids: numbers worked by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <tuple>

#include "core/wall_layers.h"
#include "lodrefine/core/planes.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

// The points of a wall along x (y = y0 + z * lean), x in [0, 4], z in [0, 3], 10 cm apart.
std::vector<Vec3> leaning_wall(double lean, double y0 = 0.0) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 30; ++j) pts.emplace_back(0.1 * i, y0 + 0.1 * j * lean, 0.1 * j);
  return pts;
}

std::vector<int> all_of(const std::vector<Vec3>& pts) {
  std::vector<int> idx(pts.size());
  std::iota(idx.begin(), idx.end(), 0);
  return idx;
}

}  // namespace

TEST(WallLayers, DescribePlaneFitsCentroidRmsHullAndFacade) {
  const PlaneConfig prm;  // facade within 10 deg of vertical, snapped within 1.5 deg
  const auto upright = leaning_wall(0.0);
  const ScanPlane a = detail::describe_plane(upright, all_of(upright), prm);
  EXPECT_TRUE(a.facade);
  EXPECT_NEAR(std::abs(a.plane.n.y()), 1.0, 1e-12);
  EXPECT_NEAR((a.centroid - Vec3(2.0, 0.0, 1.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.rms, 0.0, 1e-12);
  EXPECT_NEAR(a.hull_area, 12.0, 1e-9);
  EXPECT_EQ(a.inliers.size(), 41u * 31u);
  // Leaning 1 deg: snapped vertical (n.z = 0), its rms the lean's spread, tan(1 deg) x the
  // standard deviation of z (0.1 x sqrt((31^2 - 1) / 12) = 0.8944 m).
  const auto lean = leaning_wall(std::tan(1.0 * kPi / 180.0));
  const ScanPlane b = detail::describe_plane(lean, all_of(lean), prm);
  EXPECT_TRUE(b.facade);
  EXPECT_EQ(b.plane.n.z(), 0.0);
  EXPECT_NEAR(b.rms, std::tan(1.0 * kPi / 180.0) * 0.894427, 1e-6);
  // Leaning 20 deg: no facade, fitted as it lies (rms 0).
  const auto roofish = leaning_wall(std::tan(20.0 * kPi / 180.0));
  const ScanPlane c = detail::describe_plane(roofish, all_of(roofish), prm);
  EXPECT_FALSE(c.facade);
  EXPECT_NEAR(std::abs(c.plane.n.z()), std::sin(20.0 * kPi / 180.0), 1e-9);
  EXPECT_NEAR(c.rms, 0.0, 1e-9);
  EXPECT_NEAR(c.hull_area, 4.0 * 3.0 / std::cos(20.0 * kPi / 180.0), 1e-6);
}

TEST(WallLayers, TwoCopiesSevenCentimetresApartAreOnePlaneMidway) {
  const PlaneConfig prm;
  PointCloud cloud;
  ScanPlane near = grid_scan_plane(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.05);
  ScanPlane far = grid_scan_plane(cloud, wall_patch({0.02, -0.07, 0}, Vec3::UnitX(), 9.9, 0.0, 6.0), 0.07);
  const std::size_t total = cloud.points.size();
  const auto joined = detail::join_doubled_walls({far, near}, cloud.points, prm);
  ASSERT_EQ(joined.size(), 1u);  // the second copy's plane lost every point: dropped
  EXPECT_NEAR(joined[0].doubled, 0.07, 1e-9);
  // Midway, not at the denser copy (the fit leans ~1e-4 rad: the copies' extents differ along x).
  EXPECT_NEAR(joined[0].plane.distance(Vec3(5, -0.035, 3)), 0.0, 1e-5);
  EXPECT_EQ(joined[0].inliers.size(), total);
  EXPECT_NEAR(joined[0].rms, 0.0, 1e-9);  // each copy at its layer's centre
  // Laid onto the joined plane, the copies are one layer, within the lean over 10 m (0.4 mm).
  collapse_doubled_walls(cloud, joined);
  double worst = 0.0;
  for (int i : joined[0].inliers) worst = std::max(worst, std::abs(joined[0].plane.distance(cloud.points[i])));
  EXPECT_LT(worst, 0.001);
}

TEST(WallLayers, CopiesNearerThanRansacEpsilonStayAsTheyAre) {
  const PlaneConfig prm;  // ransac_epsilon 3 cm: 2 cm apart is one thick plane to the detection
  PointCloud cloud;
  ScanPlane near = grid_scan_plane(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.05);
  ScanPlane far = grid_scan_plane(cloud, wall_patch({0.02, -0.02, 0}, Vec3::UnitX(), 9.9, 0.0, 6.0), 0.07);
  const auto out = detail::join_doubled_walls({near, far}, cloud.points, prm);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].doubled, 0.0);
  EXPECT_EQ(out[1].doubled, 0.0);
  EXPECT_EQ(out[0].inliers.size(), near.inliers.size());  // the larger first, as it was
}

TEST(WallLayers, AFacadeOverPartOfAWallsHeightIsRelief) {
  const Mesh model = box({0, 0, 0}, {12, 8, 9});
  const PlaneConfig prm;
  // 0.5 m before the front wall (9 m high): over 0 - 3 m (a third of the height) relief, over
  // 0 - 8.5 m a wall; 20 m away from every wall, kept (nothing to be relief of).
  for (const auto& [y, z1, kept] :
       {std::tuple{-0.5, 3.0, false}, std::tuple{-0.5, 8.5, true}, std::tuple{-20.0, 3.0, true}}) {
    PointCloud cloud;
    std::vector<ScanPlane> relief;
    const auto out = without_relief({grid_scan_plane(cloud, wall_patch({2, y, 0}, Vec3::UnitX(), 6.0, 0.0, z1), 0.1)},
                                    model, cloud, prm, &relief);
    EXPECT_EQ(out.size(), kept ? 1u : 0u) << y << " " << z1;
    EXPECT_EQ(relief.size(), kept ? 0u : 1u) << y << " " << z1;
  }
}
