// An assembled shell checked before it is written (shell_checks.h): validity, vertices snapped
// back onto the start, and changes that put solid where the scan saw through.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "refine/shell_checks.h"
#include "support/candidate_fixtures.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::detail;
using namespace lodrefine::fixtures;

TEST(ShellChecks, ShellProblemNamesWhyAShellCannotBeWritten) {
  const Mesh whole = box({0, 0, 0}, {10, 8, 6});
  EXPECT_EQ(shell_problem(whole, RepairConfig{}), "");
  Mesh open = whole;
  open.faces.pop_back();
  EXPECT_NE(shell_problem(open, RepairConfig{}), "");
}

TEST(ShellChecks, VerticesWithin3cmOfTheStartsGoBackOntoThem) {
  const Mesh start = box({0, 0, 0}, {10, 8, 6});
  Mesh m = start;
  m.vertices[6] += Vec3(0.02, -0.01, 0.01);  // 2.4 cm off: back on the start's vertex
  m.vertices[7] += Vec3(0.0, 0.0, 0.05);     // 5 cm off: stays
  const Mesh snapped = snapped_to_start(m, start);
  ASSERT_EQ(snapped.vertices.size(), 8u);
  ASSERT_EQ(snapped.faces.size(), 6u);
  EXPECT_EQ(snapped.vertices[6], start.vertices[6]);
  EXPECT_EQ(snapped.vertices[7], m.vertices[7]);
  // Two vertices snapped to one start vertex become one; a face left with two corners goes.
  Mesh pinched;
  pinched.vertices = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {5, 0, 0}};
  pinched.faces = {{{0, 1, 2}}, {{0, 1, 3}}};
  Mesh one;
  one.vertices = {{0, 0, 0}};
  const Mesh merged = snapped_to_start(pinched, one);
  EXPECT_EQ(merged.vertices.size(), 2u);  // (0, 0, 0) and (5, 0, 0)
  EXPECT_EQ(merged.faces.size(), 0u);
}

namespace {

// The box 10 x 8 x 6's arrangement cut at z = 3 too; `start` its lower half, the shell the whole
// box: the changes are the upper walls, the roof and the floor at z = 3, one connected piece.
struct Grown {
  CandidateSet cs;
  std::vector<char> changed;
  Mesh start = box({0, 0, 0}, {10, 8, 3});
  Mesh shell = box({0, 0, 0}, {10, 8, 6});
};
Grown grown() {
  auto planes = box_planes(10, 8, 6);
  planes.push_back({Plane(Vec3(0, 0, 1), -3), Semantic::Other, false, 6});
  Grown g{build_candidates(planes, box_region(10, 8, 6)), {}};
  for (int f = 0; f < g.cs.size(); ++f) {
    const Vec3 c = centroid_of(g.cs, f);
    const bool in_shell = inside_box(c, 10, 8, 6) && std::abs(c.z() - 3) > 1e-9;
    const bool in_start = inside_box(c, 10, 8, 3);
    g.changed.push_back(char(in_shell != in_start));
  }
  return g;
}

}  // namespace

TEST(ShellChecks, AChangeEnclosingScanPointsIsRefusedWhole) {
  Grown g = grown();
  ASSERT_EQ(std::count(g.changed.begin(), g.changed.end(), 1), 6);
  const PlaneEvidence prm{PlaneConfig{}};  // ransac_min_points 150
  // 150 points 1.5 m under the new roof: inside the shell, outside the start.
  std::vector<Vec3> seen;
  for (int i = 0; i < 150; ++i) seen.emplace_back(2.0 + 0.04 * i, 4.0, 4.5);
  const auto refused = enclosing_changes(g.cs, g.changed, g.start, g.shell, seen, prm);
  EXPECT_EQ(refused.size(), 6u);
  // 149 are too few for a surface; points inside the start were hidden already.
  seen.pop_back();
  EXPECT_TRUE(enclosing_changes(g.cs, g.changed, g.start, g.shell, seen, prm).empty());
  std::vector<Vec3> below(150, Vec3(5, 4, 1.5));
  EXPECT_TRUE(enclosing_changes(g.cs, g.changed, g.start, g.shell, below, prm).empty());
  EXPECT_TRUE(enclosing_changes(g.cs, std::vector<char>(g.changed.size(), 0), g.start, g.shell, seen, prm).empty());
}
