// Metrics of the paper's evaluation: statistics, ΔD, watertightness, scanned walls, pooling
// (the C2M distances themselves: tests/core/test_distance.cpp; plots: test_plots.cpp).
#include <gtest/gtest.h>

#include <cmath>

#include "lodrefine/eval/eval.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

Mesh unit_cube() { return box(Vec3::Zero(), Vec3::Ones()); }

BuildingEval fake_building(std::vector<double> before, std::vector<double> after, bool wt_after) {
  BuildingEval b;
  b.c2m_before = std::move(before), b.c2m_after = std::move(after);
  b.facade_points = b.c2m_before.size();
  b.before = summarize_distances(b.c2m_before), b.after = summarize_distances(b.c2m_after);
  b.watertight_after = wt_after;
  b.delta_d = 0.1;
  return b;
}

}  // namespace

TEST(EvalStats, KnownVectors) {
  const DistanceStats a = summarize_distances({1, -1, 2, -2, 0});
  EXPECT_EQ(a.count, 5u);
  EXPECT_NEAR(a.mean, 0.0, 1e-12);
  EXPECT_NEAR(a.rmse, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(a.mae, 1.2, 1e-12);
  EXPECT_NEAR(a.std, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(a.median, 0.0, 1e-12);
  EXPECT_NEAR(a.p95, 2.0, 1e-12);
  EXPECT_NEAR(a.max_abs, 2.0, 1e-12);

  const DistanceStats b = summarize_distances({0.4, 0.1, -0.3, 0.2});
  EXPECT_NEAR(b.mean, 0.1, 1e-12);
  EXPECT_NEAR(b.rmse, std::sqrt(0.075), 1e-12);
  EXPECT_NEAR(b.mae, 0.25, 1e-12);
  EXPECT_NEAR(b.std, std::sqrt(0.065), 1e-12);  // population std: rmse² = mean² + std²
  EXPECT_NEAR(b.median, 0.15, 1e-12);
  EXPECT_NEAR(b.p95, 0.3 + 0.85 * 0.1, 1e-12);  // of |d| = {0.1, 0.2, 0.3, 0.4}

  EXPECT_EQ(summarize_distances({}).count, 0u);
  EXPECT_EQ(summarize_distances({}).rmse, 0.0);
}

TEST(EvalCentroid, VolumeCentroidOfTranslatedBoxAndAreaFallback) {
  const Vec3 c = mesh_centroid(box({2, 3, 4}, {4, 7, 5}));
  EXPECT_NEAR((c - Vec3(3, 5, 4.5)).norm(), 0.0, 1e-12);
  // A box without its ground is open: area centroid, pulled up by the roof.
  Mesh open = box({0, 0, 0}, {2, 2, 2});
  open.faces.erase(open.faces.begin());
  const Vec3 a = mesh_centroid(open);
  EXPECT_NEAR(a.z(), (4 * 4 * 1.0 + 4 * 2.0) / 20.0, 1e-12);
}

TEST(EvalWatertight, ClosedSoupOpenFlippedAndGapped) {
  EXPECT_TRUE(is_watertight(unit_cube()));
  EXPECT_TRUE(is_watertight(as_soup(unit_cube())));  // identical coordinates are welded

  Mesh open = unit_cube();
  open.faces.pop_back();
  EXPECT_FALSE(is_watertight(open));

  Mesh flipped = unit_cube();
  std::reverse(flipped.faces[2].v.begin(), flipped.faces[2].v.end());
  EXPECT_FALSE(is_watertight(flipped));

  Mesh gapped = as_soup(unit_cube());
  gapped.vertices[0].x() += 0.002;  // a 2 mm gap is not welded away
  EXPECT_FALSE(is_watertight(gapped));
}

// Points on two walls (and a stray one) mark exactly those walls as scanned.
TEST(EvalScannedWalls, PointsOnTwoWallsMarkThoseWalls) {
  const Mesh cube = unit_cube();
  std::vector<Vec3> pts;
  for (int i = 1; i < 10; ++i)
    for (int j = 1; j < 10; ++j) pts.push_back({0.1 * i, 0.01, 0.1 * j}), pts.push_back({-0.02, 0.1 * i, 0.1 * j});
  pts.push_back({1.01, 0.5, 0.5});
  EXPECT_EQ(scanned_walls(cube, pts), (std::vector<int>{2, 5}));
}

TEST(EvalPool, PooledOverPointsVersusMeanOfBuildings) {
  std::vector<BuildingEval> run = {fake_building({0.1, 0.1, 0.1, 0.1}, {0, 0, 0, 0}, true),
                                   fake_building({1.0}, {0.5}, true)};
  BuildingEval failed;
  failed.error = "refined.obj missing";
  failed.watertight_before = true;
  run.push_back(failed);
  const PooledEval p = pool_evaluations(run);
  EXPECT_EQ(p.buildings, 3u);
  EXPECT_EQ(p.failed, 1u);
  EXPECT_EQ(p.evaluated, 2u);
  EXPECT_EQ(p.before.count, 5u);
  EXPECT_NEAR(p.before.rmse, std::sqrt((4 * 0.01 + 1.0) / 5), 1e-12);
  EXPECT_NEAR(p.mean_before.rmse, (0.1 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(p.after.rmse, std::sqrt(0.25 / 5), 1e-12);
  EXPECT_NEAR(p.mean_after.mae, 0.25, 1e-12);
  EXPECT_NEAR(p.delta_d_mean, 0.1, 1e-12);
  EXPECT_NEAR(p.watertight_rate_before, 1.0 / 3, 1e-12);
  EXPECT_NEAR(p.watertight_rate_after, 2.0 / 3, 1e-12);  // the failure counts as not watertight
}

// End to end on a building-sized box: the coarse model is shifted 30 cm in x and 20 cm in y,
// away from the two densely scanned walls; the refined one is the truth.
TEST(EvalBuilding, ShiftedBoxBeforeAndAfter) {
  const Mesh truth = box({0, 0, 0}, {10, 8, 6});
  Mesh original = as_soup(box({0.3, 0.2, 0}, {10.3, 8.2, 6}));
  original.id = "b1";
  PointCloud cloud;
  for (double u = 0.025; u < 10; u += 0.05)
    for (double z = 0.025; z < 6; z += 0.05) cloud.points.push_back({u, 0.0, z});
  for (double u = 0.025; u < 8; u += 0.05)
    for (double z = 0.025; z < 6; z += 0.05) cloud.points.push_back({0.0, u, z});
  const BuildingEval e = evaluate_building(original, truth, cloud, &truth, RefineConfig{});
  ASSERT_TRUE(e.ok()) << e.error;
  ASSERT_GT(e.facade_points, cloud.points.size() * 9 / 10);
  EXPECT_EQ(e.id, "b1");
  EXPECT_NEAR(e.after.rmse, 0.0, 1e-9);
  EXPECT_GT(e.before.mean, 0.15);  // the facade points lie outside the shifted model
  EXPECT_GT(e.before.rmse, 0.15);
  EXPECT_TRUE(e.watertight_before);
  EXPECT_TRUE(e.watertight_after);
  Vec3 c_mls = Vec3::Zero();
  for (int i : e.facade_index) c_mls += cloud.points[std::size_t(i)];
  c_mls /= double(e.facade_index.size());
  const double want = (c_mls - Vec3(5.3, 4.2, 3)).norm() - (c_mls - Vec3(5, 4, 3)).norm();
  EXPECT_NEAR(e.delta_d, want, 1e-9);
  EXPECT_GT(e.delta_d, 0.0);
  ASSERT_TRUE(e.truth_facade_after && e.truth_roof_after);
  EXPECT_EQ(e.scanned_truth_faces, (std::vector<int>{2, 5}));
  EXPECT_NEAR(e.truth_facade_after->max_abs, 0.0, 1e-9);
  EXPECT_GT(e.truth_facade_before->rmse, 0.15);
  EXPECT_NEAR(e.truth_roof_before->median, 0.0, 1e-9);  // same roof plane, shifted outline
}

TEST(EvalBuilding, EmptyRefinedModelIsAFailureRow) {
  const Mesh truth = box({0, 0, 0}, {10, 8, 6});
  const BuildingEval e = evaluate_building(truth, Mesh{}, PointCloud{}, nullptr, RefineConfig{});
  EXPECT_FALSE(e.ok());
  EXPECT_FALSE(e.watertight_after);
  EXPECT_TRUE(e.watertight_before);
}
