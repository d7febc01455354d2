// Stage 2, planes: detect_planes, with both detectors (Efficient RANSAC, region growing): synthetic scans
// with 1 cm range noise give back their planes (normal,
// offset, inliers, RMS, hull area, facade flag, vertical snap), the same ones for a fixed seed,
// through the default voxel thinning and without it; too small or degenerate clouds give none,
// without hanging. Clouds are in a local frame, as the pipeline passes them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "lodrefine/core/planes.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

constexpr double kNoise = 0.01;  // range noise sigma (m)
constexpr double kStep = 0.1;    // grid spacing (m)

// A plane the scene was sampled on, and the indices of its points.
struct Truth {
  Plane plane;
  std::vector<int> points;
  double area;  // of the sampled rectangle (m^2)
};

Truth add_patch(PointCloud& cloud, const Patch& p, unsigned seed) {
  return {Plane::through(p.origin, p.normal()), add_grid(cloud, p, kStep, kNoise, seed), (p.s1 - p.s0) * (p.t1 - p.t0)};
}

// The corner of a building seen from the street: front wall y = 0 (x from 0 to 5.9), side wall
// x = 6 (y from 0.1 to 5), both from z = 0.1 to 4, and the street ground z = 0 in front (y from
// -3 to -0.1). No grid line lies on two planes.
struct Corner {
  PointCloud cloud;
  std::vector<Truth> truth;  // front, side, ground
};

Corner box_corner() {
  Corner c;
  c.truth.push_back(add_patch(c.cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 5.9, 0.1, 4.0), 1));
  c.truth.push_back(add_patch(c.cloud, {{6, 0, 0}, Vec3::UnitY(), Vec3::UnitZ(), 0.1, 5.0, 0.1, 4.0}, 2));
  c.truth.push_back(add_patch(c.cloud, {{0, 0, 0}, Vec3::UnitX(), Vec3::UnitY(), 0.0, 6.0, -3.0, -0.1}, 3));
  return c;
}

// The detected plane whose normal is within `deg` of the truth's (either sign), or null.
const ScanPlane* find_plane(const std::vector<ScanPlane>& planes, const Plane& truth, double deg = 1.0) {
  for (const auto& sp : planes)
    if (unoriented_angle_deg(sp.plane.n, truth.n) <= deg) return &sp;
  return nullptr;
}

// The detected plane `sp` is `truth`: normal within 1°, offset within 1 cm (orientation is free).
void expect_same_plane(const ScanPlane& sp, const Plane& truth) {
  EXPECT_LE(unoriented_angle_deg(sp.plane.n, truth.n), 1.0);
  const double sign = sp.plane.n.dot(truth.n) < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * sp.plane.d, truth.d, 0.01);
}

// The detected plane that is `truth` (see expect_same_plane), or null after a failure.
const ScanPlane* expect_found(const std::vector<ScanPlane>& planes, const Plane& truth) {
  const ScanPlane* sp = find_plane(planes, truth);
  if (!sp) {
    ADD_FAILURE() << "no plane with normal " << truth.n.transpose();
    return nullptr;
  }
  expect_same_plane(*sp, truth);
  return sp;
}

// How many of `inliers` are among `points`.
std::size_t count_of(const std::vector<int>& inliers, const std::vector<int>& points) {
  const std::set<int> in(points.begin(), points.end());
  return std::size_t(std::count_if(inliers.begin(), inliers.end(), [&](int i) { return in.count(i) > 0; }));
}

// detect_planes finishes within `seconds` and finds no plane: run in a child process, so a hang
// fails the test instead of stalling the suite.
void expect_no_plane_and_no_hang(const PointCloud& cloud, const PlaneConfig& prm, unsigned seconds) {
  EXPECT_EXIT(
      {
        ::alarm(seconds);
        std::exit(detect_planes(cloud, prm).empty() ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

}  // namespace

// Every test runs with both detectors: Efficient RANSAC (the default, the paper's) and region
// growing (--ransac 0).
class Planes : public testing::TestWithParam<int> {
 protected:
  PlaneConfig params() const {
    PlaneConfig p;
    p.ransac = GetParam();
    return p;
  }
};
INSTANTIATE_TEST_SUITE_P(Detector, Planes, testing::Values(1, 0),
                         [](const testing::TestParamInfo<int>& info) { return info.param ? "Ransac" : "Growing"; });

TEST_P(Planes, BoxCornerGivesItsThreePlanes) {
  const Corner c = box_corner();
  const auto planes = detect_planes(c.cloud, params());
  ASSERT_EQ(planes.size(), 3u);
  std::set<int> seen;
  for (std::size_t k = 0; k < c.truth.size(); ++k) {
    SCOPED_TRACE("truth plane " + std::to_string(k));
    const Truth& t = c.truth[k];
    const ScanPlane* sp = expect_found(planes, t.plane);
    if (!sp) continue;
    // Nearly all its points (3-sigma noise, some border points with skewed normals and, with
    // the default thinning, those of a corner voxel whose point went to the other wall may go),
    // and hardly any from elsewhere.
    const std::size_t own = count_of(sp->inliers, t.points);
    EXPECT_GE(own, std::size_t(0.95 * double(t.points.size())));
    EXPECT_LE(sp->inliers.size() - own, t.points.size() / 100);
    for (int i : sp->inliers) {
      EXPECT_TRUE(seen.insert(i).second) << "point " << i << " in two planes";
      EXPECT_LE(std::abs(t.plane.distance(c.cloud.points[i])), 2 * params().ransac_epsilon);
    }
    EXPECT_NEAR(sp->rms, kNoise, 0.0015);
    EXPECT_NEAR(sp->hull_area, t.area, 0.03 * t.area);
    Vec3 mean = Vec3::Zero();
    for (int i : t.points) mean += c.cloud.points[i];
    mean /= double(t.points.size());
    EXPECT_LT((sp->centroid - mean).norm(), 0.1);
    EXPECT_EQ(sp->facade, std::abs(t.plane.n.z()) < 0.5);
  }
  // The walls are within vertical_snap_deg of vertical: refitted exactly vertical.
  for (int k : {0, 1}) {
    const ScanPlane* wall = find_plane(planes, c.truth[k].plane);
    ASSERT_NE(wall, nullptr);
    EXPECT_EQ(wall->plane.n.z(), 0.0);
  }
  for (std::size_t k = 1; k < planes.size(); ++k) EXPECT_GE(planes[k - 1].inliers.size(), planes[k].inliers.size());
}

TEST_P(Planes, SameSeedSameResult) {
  const Corner c = box_corner();
  PlaneConfig prm = params();
  prm.seed = 7;
  const auto a = detect_planes(c.cloud, prm);
  const auto b = detect_planes(c.cloud, prm);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].inliers, b[k].inliers);
    EXPECT_EQ(a[k].plane.n, b[k].plane.n);
    EXPECT_EQ(a[k].plane.d, b[k].plane.d);
    EXPECT_EQ(a[k].rms, b[k].rms);
    EXPECT_EQ(a[k].hull_area, b[k].hull_area);
  }
  // Another seed draws other samples but finds the same planes.
  prm.seed = 12345;
  const auto other = detect_planes(c.cloud, prm);
  ASSERT_EQ(other.size(), 3u);
  for (const auto& t : c.truth) expect_found(other, t.plane);
}

// Detection on one point per 0.2 m voxel (about a quarter of the points) still gives every
// point near its plane back as an inlier.
TEST_P(Planes, VoxelDetectionOfOneFacadeTakesBackItsPoints) {
  PointCloud cloud;
  const Truth wall = add_patch(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 6.0, 0.0, 4.0), 1);
  PlaneConfig prm = params();
  prm.detect_voxel = 0.2;
  const auto planes = detect_planes(cloud, prm);
  ASSERT_EQ(planes.size(), 1u);
  expect_same_plane(planes[0], wall.plane);
  EXPECT_GE(planes[0].inliers.size(), std::size_t(0.99 * double(wall.points.size())));
  EXPECT_NEAR(planes[0].hull_area, wall.area, 0.01 * wall.area);
  EXPECT_NEAR(planes[0].rms, kNoise, 0.0015);
}

// Voxel detection takes back every point of its planes on a three-plane corner. Efficient RANSAC
// reorders its input ("the data in the input is reordered by detect()"): a representative's shape
// was once recorded by its position in the reordered list and read by its position in the
// original one, and each plane got back about half of its points (front 1175 of 2400, side 657
// of 2000, ground 859 of 1830; the ground's hull 8.6 instead of 17.4 m²).
TEST_P(Planes, VoxelDetectionTakesBackEveryPointOfItsPlanes) {
  const Corner c = box_corner();
  PlaneConfig prm = params();
  prm.detect_voxel = 0.2;
  const auto planes = detect_planes(c.cloud, prm);
  ASSERT_EQ(planes.size(), 3u);
  for (const auto& t : c.truth) {
    const ScanPlane* sp = expect_found(planes, t.plane);
    if (!sp) continue;
    EXPECT_GE(count_of(sp->inliers, t.points), std::size_t(0.9 * double(t.points.size())));
    EXPECT_NEAR(sp->hull_area, t.area, 0.06 * t.area);
  }
}

// A plane the thinned detection finds with fewer than ransac_min_points points of the full cloud
// is dropped, as full detection would never have found it. Two walls, 10 000 and 120 points: the
// small one's representatives pass the scaled minimum, its points do not pass the real one.
TEST_P(Planes, VoxelDetectionKeepsTheMinimumOfPointsOfTheFullCloud) {
  PointCloud cloud;
  const Truth big = add_patch(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 9.9, 0.0, 9.9), 1);
  // 12 × 10 points, 0.25 m apart (within the 0.28 m a shape may span at 0.2 m voxels): 2.75 ×
  // 2.25 m, one point per voxel.
  PointCloud sparse;
  const auto small =
      add_grid(sparse, {{20, 0, 0}, Vec3::UnitY(), Vec3::UnitZ(), 0.0, 2.75, 0.0, 2.25}, 0.25, kNoise, 2);
  for (int i : small) cloud.points.push_back(sparse.points[i]);
  PlaneConfig prm = params();
  prm.detect_voxel = 0.2;
  const auto planes = detect_planes(cloud, prm);
  ASSERT_EQ(planes.size(), 1u);
  expect_same_plane(planes[0], big.plane);
  prm.ransac_min_points = 100;  // now the small wall has enough points of its own
  EXPECT_EQ(detect_planes(cloud, prm).size(), 2u);
}

// By default detection is thinned to voxels of sqrt(min_plane_area / (normal_neighbors + 1)),
// and finds the planes that detection on every point finds: a corner scanned every 3 cm (61 000
// points) gives the same three planes, normals within 0.2°, offsets within 5 mm, inlier counts
// within 3 % (the ground lost 4 % before a corner voxel's points off its representative's wall
// went to the neighbouring wall's plane).
TEST_P(Planes, DefaultDetectionIsThinnedAndFindsThePlanesOfFullDetection) {
  PointCloud cloud;
  std::vector<Truth> truth;
  auto dense = [&](const Patch& p, unsigned seed) {
    truth.push_back({Plane::through(p.origin, p.normal()), add_grid(cloud, p, 0.03, kNoise, seed), 0.0});
  };
  dense(wall_patch({0, 0, 0}, Vec3::UnitX(), 5.9, 0.1, 4.0), 1);
  dense({{6, 0, 0}, Vec3::UnitY(), Vec3::UnitZ(), 0.1, 5.0, 0.1, 4.0}, 2);
  dense({{0, 0, 0}, Vec3::UnitX(), Vec3::UnitY(), 0.0, 6.0, -3.0, -0.1}, 3);
  PlaneConfig thin = params(), all = params();
  thin.detect_voxel = std::sqrt(thin.min_plane_area / double(thin.normal_neighbors + 1));
  all.detect_voxel = 0.0;
  const auto thinned = detect_planes(cloud, params());
  const auto full = detect_planes(cloud, all);
  ASSERT_EQ(full.size(), 3u);
  ASSERT_EQ(thinned.size(), 3u);
  const auto explicit_voxel = detect_planes(cloud, thin);
  ASSERT_EQ(explicit_voxel.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(thinned[k].inliers, explicit_voxel[k].inliers) << "the default voxel";
  for (std::size_t k = 0; k < truth.size(); ++k) {
    SCOPED_TRACE("truth plane " + std::to_string(k));
    const ScanPlane* a = find_plane(thinned, truth[k].plane);
    const ScanPlane* b = find_plane(full, truth[k].plane);
    ASSERT_TRUE(a && b);
    expect_same_plane(*a, truth[k].plane);
    EXPECT_LE(unoriented_angle_deg(a->plane.n, b->plane.n), 0.2);
    EXPECT_NEAR(std::abs(a->plane.d), std::abs(b->plane.d), 0.005);
    EXPECT_NEAR(double(a->inliers.size()), double(b->inliers.size()), 0.03 * double(b->inliers.size()));
    EXPECT_GE(count_of(a->inliers, truth[k].points), std::size_t(0.95 * double(truth[k].points.size())));
    EXPECT_NEAR(a->rms, kNoise, 0.0015);
  }
}

// The side wall of a 0.6 m jog in a dense facade (like a bay's side: 0.6 × 2.5 m, 1.5 m², about
// 20 voxels of the default 0.28 m) is not lost by the default thinning: found, with
// its points and extent.
TEST_P(Planes, DefaultDetectionKeepsASmallSideWall) {
  PointCloud cloud;
  const double step = 0.03;
  auto dense = [&](const Patch& p, unsigned seed) {
    return Truth{Plane::through(p.origin, p.normal()), add_grid(cloud, p, step, kNoise, seed),
                 (p.s1 - p.s0) * (p.t1 - p.t0)};
  };
  const Truth facade = dense(wall_patch({0, 0, 0}, Vec3::UnitX(), 8.0, 0.0, 4.0), 1);
  // The side x = 8.02, from the facade (y = 0) out to the front (y = -0.62).
  const Truth side = dense({{8.02, 0, 0}, -Vec3::UnitY(), Vec3::UnitZ(), 0.03, 0.6, 0.0, 2.5}, 2);
  const Truth front = dense(wall_patch({8.02, -0.62, 0}, Vec3::UnitX(), 3.0, 0.0, 2.5), 3);
  const auto planes = detect_planes(cloud, params());
  ASSERT_EQ(planes.size(), 3u);
  // The facade and the front are parallel: each is the plane holding most of its points.
  for (const Truth* t : {&facade, &front})
    EXPECT_TRUE(std::any_of(planes.begin(), planes.end(), [&](const ScanPlane& sp) {
      return count_of(sp.inliers, t->points) >= std::size_t(0.9 * double(t->points.size()));
    }));
  const ScanPlane* sp = find_plane(planes, side.plane);
  ASSERT_NE(sp, nullptr);
  expect_same_plane(*sp, side.plane);
  // A voxel at either end holds points of the neighbouring wall too: the take-back keeps those
  // near the side's plane (the facade's last columns, 2 cm off) and leaves the side's own points
  // of a voxel whose representative went to the other wall.
  EXPECT_GE(count_of(sp->inliers, side.points), std::size_t(0.75 * double(side.points.size())));
  EXPECT_LE(sp->inliers.size() - count_of(sp->inliers, side.points), side.points.size() / 10);
  EXPECT_GE(sp->hull_area, 0.8 * side.area);
}

// facade_max_tilt_deg (10°) decides the facade flag; vertical_snap_deg (1.5°) the refit.
TEST_P(Planes, FacadeFlagAndVerticalSnapFollowTheTilt) {
  PointCloud cloud;
  auto leaning = [&](double y, double tilt_deg, unsigned seed) {
    const double t = radians(tilt_deg);
    return add_patch(cloud, {{0, y, 0}, Vec3::UnitX(), Vec3(0, std::sin(t), std::cos(t)), 0.0, 6.0, 0.0, 4.0}, seed);
  };
  const Truth snapped = leaning(0.0, 1.0, 1), leaning5 = leaning(20.0, 5.0, 2), roof = leaning(40.0, 60.0, 3);
  const auto planes = detect_planes(cloud, params());
  ASSERT_EQ(planes.size(), 3u);

  const ScanPlane* a = find_plane(planes, snapped.plane, 1.5);
  ASSERT_NE(a, nullptr);
  EXPECT_TRUE(a->facade);
  EXPECT_EQ(a->plane.n.z(), 0.0);  // refitted exactly vertical
  EXPECT_NEAR(std::abs(a->plane.n.y()), 1.0, 1e-6);

  const ScanPlane* b = expect_found(planes, leaning5.plane);
  ASSERT_NE(b, nullptr);
  EXPECT_TRUE(b->facade);
  EXPECT_NEAR(std::asin(std::abs(b->plane.n.z())) * 180.0 / kPi, 5.0, 0.3);  // kept as fitted

  const ScanPlane* r = expect_found(planes, roof.plane);
  ASSERT_NE(r, nullptr);
  EXPECT_FALSE(r->facade);
}

// RANSAC's connectivity splits a facade at a gap wider than the cluster epsilon (a 1 m window
// column): the pieces are merged back into one plane.
TEST_P(Planes, PiecesOfOneFacadeAcrossAGapAreOnePlane) {
  PointCloud cloud;
  const Truth left = add_patch(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 3.0, 0.0, 4.0), 1);
  const Truth right = add_patch(cloud, wall_patch({4, 0, 0}, Vec3::UnitX(), 3.0, 0.0, 4.0), 2);
  const auto planes = detect_planes(cloud, params());
  ASSERT_EQ(planes.size(), 1u);
  expect_same_plane(planes[0], left.plane);
  EXPECT_GE(count_of(planes[0].inliers, left.points), std::size_t(0.97 * double(left.points.size())));
  EXPECT_GE(count_of(planes[0].inliers, right.points), std::size_t(0.97 * double(right.points.size())));
  EXPECT_NEAR(planes[0].hull_area, 7.0 * 4.0, 0.03 * 28.0);  // the hull spans the gap
}

TEST_P(Planes, FewerPointsThanRansacMinPointsGiveNoPlane) {
  PointCloud cloud;
  add_grid(cloud, {{0, 0, 0}, Vec3::UnitX(), Vec3::UnitZ(), 0.0, 1.4, 0.0, 0.9}, kStep);  // 15 × 10
  cloud.points.pop_back();
  ASSERT_EQ(cloud.points.size(), 149u);
  PlaneConfig prm = params();
  EXPECT_TRUE(detect_planes(cloud, prm).empty());  // ransac_min_points = 150
  // Copies of points do not count: 149 distinct points stay too few.
  PointCloud doubled = cloud;
  doubled.points.insert(doubled.points.end(), cloud.points.begin(), cloud.points.end());
  EXPECT_TRUE(detect_planes(doubled, prm).empty());
  // The same points with a lower minimum: the plane is there.
  prm.ransac_min_points = 100;
  const auto planes = detect_planes(cloud, prm);
  ASSERT_EQ(planes.size(), 1u);
  EXPECT_EQ(planes[0].inliers.size(), 149u);
  EXPECT_NEAR(std::abs(planes[0].plane.n.y()), 1.0, 1e-9);
}

// Fuzz regressions (tests/fuzz/README.md): repeated points and a subset smaller than the
// cluster epsilon sent CGAL's octree into an endless loop.
TEST_P(Planes, RepeatedIdenticalPointsGiveNoPlaneAndDoNotHang) {
  PointCloud copies;
  copies.points.assign(300, Vec3(1.5, -2.25, 3.0));
  expect_no_plane_and_no_hang(copies, params(), 20);
  PointCloud tiny;  // 300 distinct points within a millimetre
  for (int i = 0; i < 300; ++i) tiny.points.emplace_back(1e-5 * (i % 7), 1e-5 * (i % 11), 1e-5 * (i % 13));
  expect_no_plane_and_no_hang(tiny, params(), 20);
}

TEST_P(Planes, RepeatedPointsBesideAFacadeLeaveItsPlane) {
  PointCloud cloud;
  const Truth wall = add_patch(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 6.0, 0.0, 4.0), 1);
  cloud.points.insert(cloud.points.end(), 300, Vec3(20.0, -5.0, 1.0));
  const auto planes = detect_planes(cloud, params());
  ASSERT_EQ(planes.size(), 1u);
  expect_same_plane(planes[0], wall.plane);
  EXPECT_EQ(count_of(planes[0].inliers, wall.points), planes[0].inliers.size());
}

// Two drives registered 7 cm apart see one wall twice: one plane midway, holding both copies,
// with their distance; laid onto it, the copies are one layer of the scan's noise.
TEST_P(Planes, AWallSeenTwiceByMisregisteredDrivesIsOnePlaneMidway) {
  PointCloud cloud;
  add_grid(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.05, 0.008, 1);
  add_grid(cloud, wall_patch({0.02, -0.07, 0}, Vec3::UnitX(), 10.0, 0.0, 6.0), 0.07, 0.008, 2);
  auto planes = detect_planes(cloud, params());
  ASSERT_EQ(planes.size(), 1u);
  EXPECT_NEAR(planes[0].doubled, 0.07, 0.01);
  EXPECT_NEAR(std::abs(planes[0].plane.distance(Vec3(5, -0.035, 3))), 0.0, 0.005);  // midway, not at the denser copy
  EXPECT_GE(planes[0].inliers.size(), std::size_t(0.97 * double(cloud.points.size())));
  collapse_doubled_walls(cloud, planes);
  double worst = 0.0;
  for (int i : planes[0].inliers) worst = std::max(worst, std::abs(planes[0].plane.distance(cloud.points[i])));
  EXPECT_LT(worst, 0.04);
}

// A wall and a plinth 7 cm proud along its foot, a facade stepping 7 cm half-way along: two
// surfaces each, not one wall seen twice.
TEST_P(Planes, AWallWithAPlinthIsNotAWallSeenTwice) {
  PointCloud cloud;
  add_grid(cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 10.0, 1.0, 6.0), 0.05, 0.005, 1);
  add_grid(cloud, wall_patch({0, -0.07, 0}, Vec3::UnitX(), 10.0, 0.0, 1.0), 0.05, 0.005, 2);
  for (const auto& p : detect_planes(cloud, params())) EXPECT_EQ(p.doubled, 0.0);
  PointCloud step;
  add_grid(step, wall_patch({0, 0, 0}, Vec3::UnitX(), 5.0, 0.0, 6.0), 0.05, 0.005, 1);
  add_grid(step, wall_patch({5, -0.07, 0}, Vec3::UnitX(), 5.0, 0.0, 6.0), 0.05, 0.005, 2);
  for (const auto& p : detect_planes(step, params())) EXPECT_EQ(p.doubled, 0.0);
  // Windows 1.2 m wide, their panes 10 cm back in every other 1.2 m of the wall.
  PointCloud windows;
  for (int k = 0; k < 8; ++k)
    add_grid(windows, wall_patch({1.2 * k, k % 2 ? -0.1 : 0.0, 0}, Vec3::UnitX(), 1.15, 0.0, 6.0), 0.05, 0.005, k);
  for (const auto& p : detect_planes(windows, params())) EXPECT_EQ(p.doubled, 0.0);
}

namespace {

// The front wall (y = 0, 12 m long, 9 m high) of a box model, scanned, and a patch before it.
struct FrontAndPatch {
  PointCloud cloud;
  std::vector<ScanPlane> planes;
};
FrontAndPatch front_and(const Patch& patch, double step) {
  FrontAndPatch f;
  f.planes.push_back(grid_scan_plane(f.cloud, wall_patch({0, 0, 0}, Vec3::UnitX(), 12.0, 0.0, 9.0), 0.1));
  f.planes.push_back(grid_scan_plane(f.cloud, patch, step));
  return f;
}

}  // namespace

// A balcony's front 1.2 m before the wall, 1.1 m high, and a cornice: relief, not walls. A bay's
// front standing the wall's height, however sparse, is a wall.
TEST_P(Planes, BalconiesAndCornicesAreReliefABayIsAWall) {
  const Mesh model = fixtures::box({0, 0, 0}, {12, 8, 9});
  for (const auto& [patch, step, wall] :
       {std::tuple{wall_patch({3, -1.2, 0}, Vec3::UnitX(), 3.0, 3.0, 4.1), 0.05, false},
        std::tuple{wall_patch({0, -0.25, 0}, Vec3::UnitX(), 12.0, 8.4, 8.8), 0.05, false},
        std::tuple{wall_patch({4, -1.0, 0}, Vec3::UnitX(), 3.0, 0.0, 9.0), 0.3, true}}) {
    FrontAndPatch f = front_and(patch, step);
    std::vector<ScanPlane> relief;
    const auto walls = without_relief(f.planes, model, f.cloud, params(), &relief);
    EXPECT_EQ(walls.size(), wall ? 2u : 1u) << patch.origin.transpose() << " z " << patch.t0 << "-" << patch.t1;
    EXPECT_EQ(relief.size(), wall ? 0u : 1u);
  }
}
