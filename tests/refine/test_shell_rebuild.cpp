// Repair by reconstruction (rebuild_shell): the defect classes of municipal LoD2 exports.
#include <gtest/gtest.h>

#include <algorithm>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/shell_rebuild.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

// A 10 x 8 x 6 m box as an exported soup with only the faces listed (box(): 0 ground, 1 roof,
// walls 2 y = 0, 3 x = 10, 4 y = 8, 5 x = 0).
Mesh box_faces(std::initializer_list<int> keep) { return only_faces(box(Vec3(0, 0, 0), Vec3(10, 8, 6)), keep); }

// The whole box with one more wall face (source 6), `corners` in order: a fin above the roof.
Mesh box_with_fin(std::initializer_list<Vec3> corners) {
  Mesh soup = box_faces({0, 1, 2, 3, 4, 5});
  Face fin{{}, Semantic::Wall, 6};
  for (const Vec3& p : corners) {
    fin.v.push_back(int(soup.vertices.size()));
    soup.vertices.push_back(p);
  }
  soup.faces.push_back(fin);
  return soup;
}

// The soup rebuilt with the default configuration.
ShellRebuild rebuilt(const Mesh& soup) {
  const RefineConfig prm;
  return rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
}

}  // namespace

// A terraced house exported as roof, ground and one end wall (its facades and party wall
// missing, a hole no single face fills): closed along the footprint on the vertical planes
// through the hole's edges, the input's faces kept where they were.
TEST(RebuildShell, WallsMissingAlongTheFootprintAreAdded) {
  const Mesh soup = box_faces({0, 1, 3});
  const RefineConfig prm;
  const ShellRebuild rb = rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
  ASSERT_TRUE(rb.ok) << rb.reason;
  const Validation v = validate_mesh(rb.mesh, prm.repair.planarity_tolerance);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 480.0, 1e-6);
  EXPECT_EQ(rb.planes_added, 3);  // walls y = 0, y = 8, x = 0
  EXPECT_LE(rb.input_to_output, 1e-9);
  EXPECT_NEAR(rb.area_added, 2 * 60.0 + 48.0, 10.0);  // sampled every 0.25 m
  EXPECT_NEAR(rb.area_kept, 2 * 80.0 + 48.0, 10.0);
  EXPECT_LE(largest_vertex_move(rb.mesh, soup), 1e-9);
  int walls = 0;
  for (const Face& f : rb.mesh.faces) walls += f.sem == Semantic::Wall;
  EXPECT_EQ(walls, 4);
}

// A soup far larger than a building (2 km square, within size_problem's bounds: untrusted input)
// is measured on a sparser grid, so its rebuild's samples stay bounded.
TEST(RebuildShell, AHugeSoupIsSampledWithinBounds) {
  Mesh soup = box_faces({0, 1, 3});
  for (Vec3& p : soup.vertices) p = p.cwiseProduct(Vec3(200.0, 250.0, 1.0));
  const RefineConfig prm;
  const ShellRebuild rb = rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
  ASSERT_TRUE(rb.ok) << rb.reason;
  EXPECT_GT(rb.sampling, 5.0);
  const double kept = 2 * 2000.0 * 2000.0 + 2000.0 * 6.0;
  EXPECT_NEAR(rb.area_kept, kept, 0.02 * kept);
}

// A neighbour's wall standing 3 m above the roof (a fin: outside on both sides) is part of no
// solid: the rebuilt box holds the rest, and the fin goes beside it as read (its 24 m², on its
// plane, oriented like its face).
TEST(RebuildShell, AFinIsCarriedBesideTheShell) {
  const RefineConfig prm;
  const ShellRebuild rb = rebuilt(box_with_fin({Vec3(0, 0, 6), Vec3(0, 8, 6), Vec3(0, 8, 9), Vec3(0, 0, 9)}));
  ASSERT_TRUE(rb.ok) << rb.reason;
  const Validation v = validate_mesh(rb.mesh, prm.repair.planarity_tolerance);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 480.0, 1e-6);
  EXPECT_LE(rb.input_to_output, prm.repair.weld_tolerance);
  EXPECT_LE(rb.corner_to_input, prm.repair.weld_tolerance);
  EXPECT_EQ(rb.area_dropped, 0.0);
  EXPECT_NEAR(rb.area_carried, 24.0, 1.0);
  double area = 0.0;
  for (const Face& f : rb.fins.faces) {
    const Vec3 n = newell_normal(face_points(rb.fins, f));
    area += 0.5 * n.norm();
    EXPECT_GT(n.normalized().dot(Vec3(1, 0, 0)), 0.999);  // as read: facing +x
    EXPECT_EQ(f.source, 6);
    for (int i : f.v) {
      EXPECT_NEAR(rb.fins.vertices[std::size_t(i)].x(), 0.0, 1e-9);
      EXPECT_GE(rb.fins.vertices[std::size_t(i)].z(), 6.0 - 1e-9);
    }
  }
  EXPECT_NEAR(area, 24.0, 1e-6);
}

// The same holds for a fin that its plane's candidates do not fit (it ends mid-wall, where no
// other plane cuts): only the fin's own outline goes beside the shell.
TEST(RebuildShell, AFinEndingMidWallIsCarriedToItsOutline) {
  const RefineConfig prm;
  const ShellRebuild rb = rebuilt(box_with_fin({Vec3(0, 1, 6), Vec3(0, 5, 6), Vec3(0, 5, 8), Vec3(0, 1, 8)}));
  ASSERT_TRUE(rb.ok) << rb.reason;
  EXPECT_LE(rb.input_to_output, prm.repair.weld_tolerance);
  double area = 0.0;
  for (const Face& f : rb.fins.faces) area += 0.5 * newell_normal(face_points(rb.fins, f)).norm();
  EXPECT_NEAR(area, 8.0, 1e-6);
}

// A U-shaped fin (its arms 2 m wide, the gap between them 2 m deep) is carried in convex pieces:
// clipped whole, a non-convex face can come out touching itself. Its whole area is carried and
// no piece is a sliver narrower than the weld tolerance.
TEST(RebuildShell, ANonConvexFinIsCarriedInConvexPieces) {
  const RefineConfig prm;
  const ShellRebuild rb = rebuilt(box_with_fin({Vec3(0, 1, 6), Vec3(0, 7, 6), Vec3(0, 7, 10), Vec3(0, 5, 10),
                                                Vec3(0, 5, 8), Vec3(0, 3, 8), Vec3(0, 3, 10), Vec3(0, 1, 10)}));
  ASSERT_TRUE(rb.ok) << rb.reason;
  EXPECT_LE(rb.input_to_output, prm.repair.weld_tolerance);
  double area = 0.0;
  for (const Face& f : rb.fins.faces) {
    std::vector<Vec2> flat;
    for (int i : f.v) flat.emplace_back(rb.fins.vertices[std::size_t(i)].y(), rb.fins.vertices[std::size_t(i)].z());
    const double a = std::abs(signed_area_2d(flat));
    area += a;
    double perimeter = 0.0;
    for (std::size_t i = 0; i < flat.size(); ++i) perimeter += (flat[(i + 1) % flat.size()] - flat[i]).norm();
    EXPECT_GT(2.0 * a, prm.repair.weld_tolerance * perimeter);
    for (std::size_t i = 0; i < flat.size(); ++i) {  // convex: every turn the same way
      const Vec2 e = flat[(i + 1) % flat.size()] - flat[i],
                 g = flat[(i + 2) % flat.size()] - flat[(i + 1) % flat.size()];
      EXPECT_GE((e.x() * g.y() - e.y() * g.x()) * signed_area_2d(flat), -1e-9);
    }
  }
  EXPECT_NEAR(area, 6.0 * 4.0 - 2.0 * 2.0, 1e-6);
}

// Two overlapping boxes exported as one soup with their own walls inside each other: the walls
// inside the union (the other box's volume on both sides) are partitions, dropped; the union
// covers everything else.
TEST(RebuildShell, PartitionsBetweenOverlappingPartsAreJoined) {
  const Mesh soup = merged(box_faces({0, 1, 2, 3, 4, 5}), as_soup(box(Vec3(6, 4, 0), Vec3(14, 12, 6))));
  const RefineConfig prm;
  const ShellRebuild rb = rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
  ASSERT_TRUE(rb.ok) << rb.reason;
  const Validation v = validate_mesh(rb.mesh, prm.repair.planarity_tolerance);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 6.0 * (80.0 + 64.0 - 16.0), 1e-6);
  EXPECT_LE(rb.input_to_output, prm.repair.weld_tolerance);
  EXPECT_NEAR(rb.area_dropped, 2 * (4.0 + 4.0) * 6.0, 6.0);  // each box's two walls inside the other
}

// Two boxes that touch along one edge only: closing them as one shell would swallow their walls
// at the corner (no partition: outside on one side). Not rebuilt; the walls stay uncovered.
TEST(RebuildShell, PartsTouchingAlongAnEdgeAreNotSwallowed) {
  const Mesh soup = merged(box_faces({0, 1, 2, 3, 4, 5}), as_soup(box(Vec3(10, 8, 0), Vec3(16, 14, 5))));
  const RefineConfig prm;
  const ShellRebuild rb = rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
  EXPECT_TRUE(!rb.ok || rb.input_to_output > prm.repair.weld_tolerance) << rb.input_to_output;
}

// A roof alone (or with one wall) has no ground: closing it would invent the foot of every wall.
TEST(RebuildShell, ARoofWithoutAGroundIsNotClosed) {
  const RefineConfig prm;
  const ShellRebuild with_wall = rebuild_shell(welded_soup(box_faces({1, 3}), prm.repair.weld_tolerance), prm);
  EXPECT_FALSE(with_wall.ok);
  EXPECT_EQ(with_wall.reason, "it has no ground face: the foot of its walls would be invented");
  // A flat roof alone is its own lowest plane: nothing closes it.
  EXPECT_FALSE(rebuild_shell(welded_soup(box_faces({1}), prm.repair.weld_tolerance), prm).ok);
}

// Thirty rotated boxes overlapping one another (180 planes, an attacker's soup well within
// size_problem's bounds): the arrangement would pass 10,000 candidates, and GLPK's root LP on it
// took seconds its work budget does not count. Refused before any program is built.
TEST(RebuildShell, AnArrangementTooLargeForABuildingIsRefused) {
  Mesh soup;
  for (int k = 0; k < 30; ++k) {
    Mesh b = as_soup(box(Vec3(-4, -3, 0), Vec3(4, 3, 5 + 0.3 * k)));
    const Eigen::Matrix3d r = Eigen::AngleAxisd(radians(7.0 * k), Vec3::UnitZ()).toRotationMatrix();
    for (Vec3& p : b.vertices) p = r * p + Vec3(0.5 * k, 0.3 * k, 0);
    soup = merged(soup, b);
  }
  const RefineConfig prm;
  const ShellRebuild rb = rebuild_shell(welded_soup(soup, prm.repair.weld_tolerance), prm);
  EXPECT_FALSE(rb.ok);
  EXPECT_EQ(rb.reason.rfind("too many candidate faces (over 10000", 0), 0u) << rb.reason;
}
