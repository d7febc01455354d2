// The fallback stage: one wall replaced through the local candidate arrangement and GLPK. The
// new wall lies on the scan plane, the shell closes, the rest of the building stays, and the
// report figures (candidates, program, selection) are filled in.
#include <gtest/gtest.h>

#include "lodrefine/core/arrangement.h"
#include "lodrefine/core/validate.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

int surface_facing(const std::vector<ModelSurface>& ss, const Vec3& n) {
  for (int s = 0; s < int(ss.size()); ++s)
    if (ss[s].plane.n.dot(n) > 0.99) return s;
  return -1;
}

// The front wall (y = 0, facing -y) of `m` to move onto y = -offset, with a scan of it.
WallReplacement front_onto(const std::vector<ModelSurface>& ss, double offset, double length, double height) {
  WallReplacement rep;
  rep.surfaces = {surface_facing(ss, Vec3(0, -1, 0))};
  rep.plane = Plane::through(Vec3(0, -offset, 0), Vec3(0, -1, 0));
  PointCloud scan;
  add_grid(scan, wall_patch(Vec3(0, -offset, 0), Vec3::UnitX(), length, 0.0, height), 0.25);
  rep.points = scan.points;
  return rep;
}

// The largest distance of a vertex of `after` with y >= min_y from every vertex of `before`.
double farthest_new_vertex(const Mesh& before, const Mesh& after, double min_y) {
  double worst = 0.0;
  for (const auto& p : after.vertices) {
    if (p.y() < min_y) continue;
    double best = 1e300;
    for (const auto& q : before.vertices) best = std::min(best, (p - q).norm());
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace

TEST(Arrangement, BoxFrontWallMovesOntoItsScanPlane) {
  const Mesh m = box(Vec3(0, 0, 0), Vec3(12, 8, 6));
  const auto ss = model_surfaces(m);
  const WallReplacement rep = front_onto(ss, 0.4, 12.0, 6.0);
  ASSERT_GE(rep.surfaces[0], 0);
  const ArrangementResult r = arrange_wall(m, ss, rep, Params{});
  ASSERT_TRUE(r.ok) << r.reason;
  const Validation v = validate_mesh(r.mesh, 0.01);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 12.0 * 8.4 * 6.0, 1e-6);
  // Every vertex in front of the old wall is on the new plane.
  int on_new = 0;
  for (const auto& p : r.mesh.vertices)
    if (p.y() < -0.01) {
      EXPECT_NEAR(p.y(), -0.4, 1e-9);
      ++on_new;
    }
  EXPECT_EQ(on_new, 4);
  // The figures of what was built and solved.
  ASSERT_TRUE(r.stats.candidates && r.stats.selection && r.stats.selected && r.stats.seconds);
  EXPECT_GE(*r.stats.supporting_planes, 5);  // the scan plane, the two side walls, roof, ground
  EXPECT_GT(*r.stats.candidates, *r.stats.selected);
  EXPECT_EQ(r.stats.selection->status, SolveStatus::Optimal);
  EXPECT_TRUE(r.stats.selection->selected.empty());  // figures only
  EXPECT_GT(r.stats.selection->variables, 0);
}

TEST(Arrangement, GableFrontWallMovesAndTheRoofAwayFromItStays) {
  const Mesh m = gable_house();  // front wall y = 0 under the eave at 6 m, ridge at 9 m along x
  const auto ss = model_surfaces(m);
  const WallReplacement rep = front_onto(ss, 0.3, 10.0, 6.0);
  const ArrangementResult r = arrange_wall(m, ss, rep, Params{});
  ASSERT_TRUE(r.ok) << r.reason;
  const Validation v = validate_mesh(r.mesh, 0.01);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_GT(v.volume, validate_mesh(m, 0.01).volume);
  // Beyond the region (the back half of the house) every vertex is one of the input's.
  EXPECT_LT(farthest_new_vertex(m, r.mesh, 4.5), 1e-9);
  double min_y = 1e300;
  for (const auto& p : r.mesh.vertices) min_y = std::min(min_y, p.y());
  EXPECT_NEAR(min_y, -0.3, 1e-9);
}
