// The simulated MLS crop (src/synth/scan.cpp, internal to synth): which walls the van scans and
// the points it records on them, within the range noise of the wall and on its extent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lodrefine/base/geometry.h"
#include "support/synth_shape_fixtures.h"
#include "synth/scan.h"

using namespace lodrefine;
using namespace lodrefine::synth;
using synth_fixtures::box_mesh;

TEST(SynthScan, ScannedWallsAreARunOfAdjacentWalls) {
  const Mesh m = box_mesh();
  const std::vector<WallInfo> walls = wall_infos(m);
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Rng r(seed);
    const std::vector<int> chosen = choose_scanned(m, walls, 2, r);
    ASSERT_GE(chosen.size(), 1u);
    ASSERT_LE(chosen.size(), 2u);
    if (chosen.size() == 2) {  // adjacent lines of the rectangle
      const int a = walls[std::size_t(chosen[0])].line, b = walls[std::size_t(chosen[1])].line;
      EXPECT_TRUE((a - b + 4) % 4 == 1 || (b - a + 4) % 4 == 1) << a << " " << b;
    }
    const std::vector<int> faces = wall_faces(chosen, walls);
    ASSERT_EQ(faces.size(), chosen.size());
    for (std::size_t i = 0; i < faces.size(); ++i) EXPECT_EQ(faces[i], walls[std::size_t(chosen[i])].face);
  }
}

TEST(SynthScan, FacadePointsLieOnTheirWallWithinTheNoise) {
  const Mesh m = box_mesh();
  const std::vector<WallInfo> walls = wall_infos(m);
  const auto front = std::find_if(walls.begin(), walls.end(), [](const WallInfo& w) { return w.line == 0; });
  ASSERT_NE(front, walls.end());
  SynthOptions o;
  o.nuisances = false;
  o.noise = 0.01;
  o.target_points = 2000;
  Rng r(3);
  const ScanResult scan = simulate_scan(m, {front->face}, 0.0, Vec2::Zero(), o, r);
  ASSERT_EQ(scan.labels.size(), scan.pts.size());
  EXPECT_GT(scan.spacing, 0.0);
  EXPECT_GT(scan.pts.size(), 1000u);
  EXPECT_LT(scan.pts.size(), 4000u);
  for (std::size_t i = 0; i < scan.pts.size(); ++i) {
    ASSERT_EQ(scan.labels[i], front->face) << i;  // no nuisances: facade points only
    const Vec3& p = scan.pts[i];
    EXPECT_LE(std::abs(p.y()), 3.5 * o.noise + 1e-9) << i;  // the wall y = 0, noise cut at 3.5 sigma
    EXPECT_GE(p.x(), -0.05);
    EXPECT_LE(p.x(), 10.05);
    EXPECT_GE(p.z(), -0.05);
    EXPECT_LE(p.z(), 5.05);
  }
}
