// Wall substitution: moved walls take their new plane, every other vertex stays put, heights are
// kept unless the eave follows its roof, and a move that would turn a face inside out is refused.
#include <gtest/gtest.h>

#include "lodrefine/core/matching.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/substitute.h"
#include "lodrefine/core/validate.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace {

// The shared 10 x 8 m gable house (eaves 6 m, ridge 9 m along y = 4) as an exported soup, repaired.
Mesh repaired_gable_house() { return repair_model(as_soup(gable_house()), 0.01); }

int surface_with_normal(const std::vector<ModelSurface>& ss, const Vec3& n) {
  for (int s = 0; s < int(ss.size()); ++s)
    if (ss[s].plane.n.dot(n) > 0.99) return s;
  return -1;
}

}  // namespace

TEST(Substitute, MovedWallTakesItsPlaneAndNothingElseMoves) {
  const Mesh m = repaired_gable_house();
  const auto ss = model_surfaces(m);
  const int front = surface_with_normal(ss, Vec3(0, -1, 0));
  ASSERT_GE(front, 0);
  // 0.5 m out and turned 2 degrees about a vertical axis.
  const double a = radians(2.0);
  const Plane moved = Plane::through(Vec3(6, -0.5, 0), Vec3(std::sin(a), -std::cos(a), 0));
  const auto r = substitute_walls(m, ss, {{front, moved}}, 0.01);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.moved_vertices, 4);
  EXPECT_TRUE(validate_mesh(r.mesh, kPlanarity).valid()) << validate_mesh(r.mesh, kPlanarity).problem;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    const Vec3 &p = m.vertices[v], &q = r.mesh.vertices[v];
    EXPECT_EQ(p.z(), q.z()) << "heights are kept";
    if (std::abs(p.y()) < 1e-9) {
      EXPECT_NEAR(moved.distance(q), 0.0, 1e-6) << "front vertex on the new plane";
      // ...and still on its gable wall (x = 0 or 10): it slid along it.
      EXPECT_NEAR(std::min(std::abs(q.x()), std::abs(q.x() - 10)), 0.0, 1e-6);
    } else {
      EXPECT_EQ(p, q) << "vertex " << v << " is on no moved wall";
    }
  }
}

TEST(Substitute, EaveKeepsItsHeightOrFollowsTheRoofPlane) {
  const Mesh m = repaired_gable_house();
  const auto ss = model_surfaces(m);
  const int front = surface_with_normal(ss, Vec3(0, -1, 0));
  const int roof = surface_with_normal(ss, Vec3(0, -3, 4).normalized());
  ASSERT_GE(front, 0);
  ASSERT_GE(roof, 0);
  const Plane moved = Plane::through(Vec3(6, 1.0, 0), Vec3(0, -1, 0));  // 1 m in
  const auto keep = substitute_walls(m, ss, {{front, moved, false}}, 0.01);
  const auto follow = substitute_walls(m, ss, {{front, moved, true}}, 0.01);
  ASSERT_TRUE(keep.ok) << keep.reason;
  ASSERT_TRUE(follow.ok) << follow.reason;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    if (std::abs(m.vertices[v].y()) > 1e-9 || m.vertices[v].z() < 1) continue;  // the front eave
    EXPECT_NEAR(keep.mesh.vertices[v].z(), 6.0, 1e-9);
    EXPECT_NEAR(ss[roof].plane.distance(follow.mesh.vertices[v]), 0.0, 1e-6) << "on the old roof plane";
    EXPECT_NEAR(follow.mesh.vertices[v].z(), 6.75, 1e-6);  // slope 3/4 over 1 m
    EXPECT_NEAR(follow.mesh.vertices[v].y(), 1.0, 1e-6);
  }
  EXPECT_TRUE(validate_mesh(keep.mesh, kPlanarity).valid());
  EXPECT_TRUE(validate_mesh(follow.mesh, kPlanarity).valid());
}

TEST(Substitute, RefusesAMoveThatTurnsAFaceInsideOut) {
  const Mesh m = repaired_gable_house();
  const auto ss = model_surfaces(m);
  const int front = surface_with_normal(ss, Vec3(0, -1, 0));
  const auto r = substitute_walls(m, ss, {{front, Plane::through(Vec3(6, 9, 0), Vec3(0, -1, 0))}}, 0.01);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("inside out"), std::string::npos) << r.reason;
}
