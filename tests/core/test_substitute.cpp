// Wall substitution: moved walls take their new plane, every other vertex stays put, heights are
// kept unless the eave follows its roof, and a move that would turn a face inside out is refused.
#include <gtest/gtest.h>

#include "lodrefine/core/matching.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/substitute.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = Params{}.planarity_tolerance;

namespace {

// A closed gable house: x in [0,12], y in [0,8], eaves at 6 m, ridge at 9 m along y = 4.
Mesh gable_house() {
  Mesh soup;
  soup.id = "gable";
  auto quad = [&](std::vector<Vec3> pts, Semantic sem) {
    Face f;
    f.sem = sem;
    for (const auto& p : pts) {
      f.v.push_back(int(soup.vertices.size()));
      soup.vertices.push_back(p);
    }
    soup.faces.push_back(f);
  };
  const Vec3 a(0, 0, 0), b(12, 0, 0), c(12, 8, 0), d(0, 8, 0);
  const Vec3 ae(0, 0, 6), be(12, 0, 6), ce(12, 8, 6), de(0, 8, 6), r0(0, 4, 9), r1(12, 4, 9);
  quad({a, d, c, b}, Semantic::Ground);
  quad({a, b, be, ae}, Semantic::Wall);          // front, y = 0
  quad({b, c, ce, r1, be}, Semantic::Wall);      // gable end, x = 12
  quad({c, d, de, ce}, Semantic::Wall);          // back, y = 8
  quad({d, a, ae, r0, de}, Semantic::Wall);      // gable end, x = 0
  quad({ae, be, r1, r0}, Semantic::Roof);        // front slope
  quad({ce, de, r0, r1}, Semantic::Roof);        // back slope
  return repair_model(soup, 0.01);
}

int surface_with_normal(const std::vector<ModelSurface>& ss, const Vec3& n) {
  for (int s = 0; s < int(ss.size()); ++s)
    if (ss[s].plane.n.dot(n) > 0.99) return s;
  return -1;
}

}  // namespace

TEST(Substitute, MovedWallTakesItsPlaneAndNothingElseMoves) {
  const Mesh m = gable_house();
  const auto ss = model_surfaces(m);
  const int front = surface_with_normal(ss, Vec3(0, -1, 0));
  ASSERT_GE(front, 0);
  // 0.5 m out and turned 2 degrees about a vertical axis.
  const double a = 2.0 * M_PI / 180.0;
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
      // ...and still on its gable wall (x = 0 or 12): it slid along it.
      EXPECT_NEAR(std::min(std::abs(q.x()), std::abs(q.x() - 12)), 0.0, 1e-6);
    } else {
      EXPECT_EQ(p, q) << "vertex " << v << " is on no moved wall";
    }
  }
}

TEST(Substitute, EaveKeepsItsHeightOrFollowsTheRoofPlane) {
  const Mesh m = gable_house();
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
  const Mesh m = gable_house();
  const auto ss = model_surfaces(m);
  const int front = surface_with_normal(ss, Vec3(0, -1, 0));
  const auto r = substitute_walls(m, ss, {{front, Plane::through(Vec3(6, 9, 0), Vec3(0, -1, 0))}}, 0.01);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("inside out"), std::string::npos) << r.reason;
}
