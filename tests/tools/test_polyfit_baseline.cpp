// CGAL's PolyFit as a baseline: on a box building with a clean scan of every face it closes a mesh
// within centimetres of the truth (in the input's georeferenced frame), in this process and in
// the bounded child; its failures are statuses, never exceptions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/tools/polyfit_baseline.h"
#include "support/mesh_fixtures.h"
#include "support/polyfit_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

// RMS distance of points sampled on every truth face to `m` (m).
double truth_rms(const Mesh& m, const Mesh& truth) {
  return rms_distance(m, sample_faces(truth, {0, 1, 2, 3, 4, 5}, 0.25));
}

void expect_box(const PolyfitResult& r, const Mesh& truth) {
  ASSERT_EQ(r.status, PolyfitStatus::Closed) << r.reason;
  EXPECT_TRUE(r.reason.empty());
  EXPECT_TRUE(is_watertight(r.mesh));
  EXPECT_EQ(r.mesh.faces.size(), 6u);  // the box's six planes, one face each
  EXPECT_LT(truth_rms(r.mesh, truth), 0.02);
  EXPECT_LT(rms_distance(truth, r.mesh.vertices), 0.02);  // corners on the truth's, in its frame
  EXPECT_GE(r.planes, 6);
  EXPECT_GT(r.candidates, 6);
}

}  // namespace

TEST(PolyfitBaseline, ScanPlanesCloseTheBoxOnTheTruth) {
  const Mesh truth = truth_box();
  const PolyfitResult r = polyfit_baseline(coarse_box(), full_scan(truth), RefineConfig{}, {PolyfitPlanes::Scan});
  expect_box(r, truth);
  EXPECT_EQ(r.model_planes, 0);
  EXPECT_GT(r.points, 20000u);
}

// The moved model wall is a plane too, but the scan's points outweigh its samples.
TEST(PolyfitBaseline, ModelAndScanPlanesFollowTheScan) {
  const Mesh truth = truth_box();
  const PolyfitResult r = polyfit_baseline(coarse_box(), full_scan(truth), RefineConfig{}, {});
  expect_box(r, truth);
  EXPECT_EQ(r.model_planes, 6);
  EXPECT_GT(truth_rms(coarse_box(), truth), 0.1);  // the coarse model is off
}

TEST(PolyfitBaseline, IsolatedChildGivesTheSameMesh) {
  const Mesh truth = truth_box();
  const PointCloud cloud = full_scan(truth);
  const PolyfitResult in_process = polyfit_baseline(coarse_box(), cloud, RefineConfig{}, {});
  const PolyfitResult isolated = polyfit_baseline_isolated(coarse_box(), cloud, RefineConfig{}, {});
  expect_box(isolated, truth);
  // CGAL orders planes by address (std::set of pointers), so a corner may come from another
  // plane triple in another process: equal to rounding.
  ASSERT_EQ(isolated.mesh.vertices.size(), in_process.mesh.vertices.size());
  for (std::size_t i = 0; i < isolated.mesh.vertices.size(); ++i)
    EXPECT_LT((isolated.mesh.vertices[i] - in_process.mesh.vertices[i]).norm(), 1e-6);
  EXPECT_EQ(isolated.candidates, in_process.candidates);
  EXPECT_GT(isolated.cpu_seconds, 0.0);
  EXPECT_GE(isolated.seconds, isolated.polyfit_seconds);
}

// Failures are statuses with a reason: nothing thrown, no mesh claimed closed.
TEST(PolyfitBaseline, TooFewPlanesIsAStatus) {
  const Mesh truth = truth_box();
  const PolyfitResult r = polyfit_baseline(truth, scan_of(truth, {2, 3}), RefineConfig{}, {PolyfitPlanes::Scan});
  EXPECT_EQ(r.status, PolyfitStatus::TooFewPlanes);
  EXPECT_NE(r.reason.find("at least 4"), std::string::npos) << r.reason;
  EXPECT_EQ(r.planes, 2);
  EXPECT_TRUE(r.mesh.faces.empty());
}

TEST(PolyfitBaseline, UnusableModelIsAnError) {
  const PolyfitResult r = polyfit_baseline(Mesh{}, full_scan(truth_box()), RefineConfig{}, {});
  EXPECT_EQ(r.status, PolyfitStatus::Error);
  EXPECT_FALSE(r.reason.empty());
  RefineConfig bad;
  bad.plane.ransac_epsilon = -1;  // out of the parameter table's range
  EXPECT_EQ(polyfit_baseline(truth_box(), PointCloud{}, bad, {}).status, PolyfitStatus::Error);
}

// A scan of 30 planes crossing each other in a 20 m cube: an arrangement of thousands of
// candidates, far more than one CPU second of work. The child is stopped at its limit.
TEST(PolyfitBaseline, IsolatedChildStopsAtItsCpuLimit) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> at(0.0, 20.0), angle(0.0, 2 * kPi);
  PointCloud cloud;
  for (int k = 0; k < 30; ++k) {
    const Vec3 n(std::cos(angle(rng)), std::sin(angle(rng)), 0.3 * std::cos(angle(rng)));
    const auto [u, v] = Plane::through(Vec3::Zero(), n.normalized()).basis();
    add_grid(cloud, {kTileOrigin + Vec3(at(rng), at(rng), at(rng)), u, v, -4, 4, -4, 4}, 0.1, 0.005, unsigned(k));
  }
  PolyfitOptions options{PolyfitPlanes::Scan};
  options.cpu_limit = 1.0;
  const Mesh model = translated(box(Vec3::Zero(), Vec3(20, 20, 20)), kTileOrigin);
  const PolyfitResult r = polyfit_baseline_isolated(model, cloud, RefineConfig{}, options);
  EXPECT_EQ(r.status, PolyfitStatus::TimeLimit) << polyfit_status_name(r.status) << ": " << r.reason;
  EXPECT_NE(r.reason.find("1 s CPU"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.mesh.faces.empty());
  // The kernel checks RLIMIT_CPU against its tick-based accounting, which may run ahead of the
  // parent's clock: a fresh checkout's run read 0.99995 s of wall clock.
  EXPECT_GE(r.seconds, 0.95);
  EXPECT_DOUBLE_EQ(r.cpu_seconds, 1.0);
}
