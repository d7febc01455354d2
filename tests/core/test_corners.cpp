// Corners from the scan's extent: an unscanned side wall moves to where the scanned facade
// ends, but only where the scanner saw the building end there.
#include <gtest/gtest.h>

#include <random>

#include "lodrefine/core/corners.h"
#include "lodrefine/core/repair.h"

using namespace lodrefine;

namespace {

// A closed box [0,12] x [0,8] x [0,6] (front wall y = 0 faces -y); its right side wall runs from
// (12, 0) back to (back_right, 8) (skewed when not 12).
Mesh box(double back_right = 12.0) {
  Mesh soup;
  soup.id = "box";
  const double r = back_right;
  const Vec3 c[8] = {{0, 0, 0}, {12, 0, 0}, {r, 8, 0}, {0, 8, 0}, {0, 0, 6}, {12, 0, 6}, {r, 8, 6}, {0, 8, 6}};
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const Semantic sem[6] = {Semantic::Ground, Semantic::Roof, Semantic::Wall,
                           Semantic::Wall,   Semantic::Wall, Semantic::Wall};
  for (int f = 0; f < 6; ++f) {
    Face face;
    face.sem = sem[f];
    for (int k = 0; k < 4; ++k) {
      face.v.push_back(int(soup.vertices.size()));
      soup.vertices.push_back(c[quads[f][k]]);
    }
    soup.faces.push_back(face);
  }
  return repair_model(soup, 0.01);
}

struct Scene {
  Mesh mesh;
  std::vector<ModelSurface> surfaces;
  PointCloud cloud;
  std::vector<ScanPlane> planes;
  std::vector<ScannedWall> scanned;
};

// The front facade scanned from x = 0 to x = `end`, `offset` metres in front of the model's
// (a misplaced model facade when > 0); optionally the right side wall seen obliquely for `side`
// metres behind the facade at x = `end`. The box's right side wall runs back to `back_right`.
Scene scene(double end, double side, double offset = 0.0, double back_right = 12.0) {
  Scene s;
  s.mesh = box(back_right);
  s.surfaces = model_surfaces(s.mesh);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  ScanPlane sp;
  for (double x = 0.02; x < end; x += 0.05)
    for (double z = 0.1; z < 5.9; z += 0.05) {
      sp.inliers.push_back(int(s.cloud.points.size()));
      s.cloud.points.emplace_back(x, -offset + noise(rng), z);
    }
  for (double y = 0.05; y < side; y += 0.05)
    for (double z = 0.1; z < 5.9; z += 0.05) s.cloud.points.emplace_back(end + noise(rng), y, z);
  sp.plane = Plane(Vec3(0, -1, 0), -offset);
  sp.facade = true;
  s.planes.push_back(sp);
  for (int k = 0; k < int(s.surfaces.size()); ++k)
    if (s.surfaces[k].plane.n.y() < -0.99) s.scanned.push_back({k, 0, sp.plane});
  return s;
}

// The street in front of the facade, scanned from x = -3 to x = `to`.
void add_street(Scene& s, double to) {
  for (double x = -3.0; x < to; x += 0.1)
    for (double y = -1.0; y > -8.0; y -= 0.1) s.cloud.points.emplace_back(x, y, 0.02);
}

// Two storeys, front wall y = 0 facing -y: the lower one [0,12] x [0,8] x [0,3], the upper one
// set back at x = 9 ([0,9] x [0,8] x [3,6]). The front is one L-shaped wall; the upper storey's
// side wall x = 9 meets it only over z in [3, 6].
Mesh two_storeys() {
  const double profile[6][2] = {{0, 0}, {12, 0}, {12, 3}, {9, 3}, {9, 6}, {0, 6}};  // (x, z)
  Mesh soup;
  soup.id = "two storeys";
  auto add = [&](std::vector<Vec3> pts, Semantic sem) {
    Face face;
    face.sem = sem;
    for (const auto& p : pts) {
      face.v.push_back(int(soup.vertices.size()));
      soup.vertices.push_back(p);
    }
    soup.faces.push_back(face);
  };
  std::vector<Vec3> front, back;
  for (const auto& q : profile) {
    front.emplace_back(q[0], 0, q[1]);
    back.insert(back.begin(), Vec3(q[0], 8, q[1]));
  }
  add(front, Semantic::Wall);
  add(back, Semantic::Wall);
  for (int k = 0; k < 6; ++k) {
    const auto& a = profile[k];
    const auto& b = profile[(k + 1) % 6];
    const Semantic sem = a[1] == b[1] ? (a[1] == 0 ? Semantic::Ground : Semantic::Roof) : Semantic::Wall;
    add({{a[0], 0, a[1]}, {a[0], 8, a[1]}, {b[0], 8, b[1]}, {b[0], 0, b[1]}}, sem);
  }
  return repair_model(soup, 0.01);
}

// The two storeys' front scanned `offset` in front of the model's, the lower storey to x = 12
// (where the model has it), the upper one to x = 9.5 (0.5 m past the model's step); optionally
// the upper storey's side wall seen obliquely 1 m behind the facade; the street to x = 16.
Scene stepped_scene(double offset, bool side) {
  Scene s;
  s.mesh = two_storeys();
  s.surfaces = model_surfaces(s.mesh);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  ScanPlane sp;
  for (double z = 0.1; z < 5.9; z += 0.05)
    for (double x = 0.02; x < (z < 3.0 ? 11.98 : 9.5); x += 0.05) {
      sp.inliers.push_back(int(s.cloud.points.size()));
      s.cloud.points.emplace_back(x, -offset + noise(rng), z);
    }
  if (side)
    for (double y = 0.05 - offset; y < 1.0; y += 0.05)
      for (double z = 3.1; z < 5.9; z += 0.05) s.cloud.points.emplace_back(9.5 + noise(rng), y, z);
  sp.plane = Plane(Vec3(0, -1, 0), -offset);
  sp.facade = true;
  s.planes.push_back(sp);
  for (int k = 0; k < int(s.surfaces.size()); ++k)
    if (s.surfaces[k].plane.n.y() < -0.99) s.scanned.push_back({k, 0, sp.plane});
  for (double x = -3.0; x < 16.0; x += 0.1)
    for (double y = -1.0; y > -8.0; y -= 0.1) s.cloud.points.emplace_back(x, y, 0.02);
  return s;
}

// The box's front scanned `offset` in front of the model's to x = 11.3 (where the building
// really ends) and on, flush, over a terraced neighbour's facade from x = 11.3 to 20 up to
// `neighbour_top` (lower or taller than the box's 6 m); the street in front.
Scene terraced_scene(double offset, double neighbour_top) {
  Scene s = scene(11.3, 0.0, offset);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (double x = 11.32; x < 20.0; x += 0.05)
    for (double z = 0.1; z < neighbour_top; z += 0.05) {
      s.planes[0].inliers.push_back(int(s.cloud.points.size()));
      s.cloud.points.emplace_back(x, -offset + noise(rng), z);
    }
  add_street(s, 20.0);
  return s;
}

// The one move of a terraced scene: the right side wall (the party wall) to x = 11.3.
void expect_party_wall_moved(const Scene& s, const std::vector<CornerMove>& moves) {
  ASSERT_EQ(moves.size(), 1u);
  EXPECT_GT(s.surfaces[moves[0].move.surface].plane.n.x(), 0.99) << "the right side wall";
  EXPECT_NEAR(moves[0].move.plane.distance(Vec3(11.3, 0, 0)), 0.0, 0.06);
  ASSERT_TRUE(moves[0].flush_facade.has_value());
  EXPECT_NEAR(moves[0].flush_facade->distance(Vec3(15, -0.4, 2)), 0.0, 1e-9) << "the scanned facade's plane";
}

// The one move of a stepped scene: the upper storey's side wall (x = 9) to x = 9.5.
void expect_upper_side_wall_moved(const Scene& s, const std::vector<CornerMove>& moves) {
  ASSERT_EQ(moves.size(), 1u) << "the lower storey ends where the model has it";
  const ModelSurface& wall = s.surfaces[moves[0].move.surface];
  EXPECT_GT(wall.plane.n.x(), 0.99);
  EXPECT_NEAR(wall.plane.distance(Vec3(9, 0, 4)), 0.0, 1e-9) << "the step at x = 9, not the wing's end";
  EXPECT_NEAR(moves[0].move.plane.distance(Vec3(9.5, 0, 4)), 0.0, 0.06);
  EXPECT_NEAR(moves[0].shift, 0.5, 0.06);
}

}  // namespace

TEST(Corners, SideWallMovesToWhereTheFacadeEnds) {
  Scene s = scene(11.3, 1.0);  // the building really ends at x = 11.3
  const auto moves = corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{});
  ASSERT_EQ(moves.size(), 1u);
  const Plane& p = moves[0].move.plane;
  EXPECT_GT(s.surfaces[moves[0].move.surface].plane.n.x(), 0.99) << "the right side wall";
  EXPECT_NEAR(p.distance(Vec3(11.3, 0, 0)), 0.0, 0.06);
  EXPECT_NEAR(moves[0].shift, -0.7, 0.06);
}

TEST(Corners, AScanThatJustStopsIsNoEvidence) {
  Scene s = scene(11.3, 0.0);  // nothing seen where the facade's points end
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

TEST(Corners, AFacadeRunningPastTheCornerIntoAReturnMovesItOut) {
  Scene s = scene(12.5, 1.0);  // the building really ends at x = 12.5, its side wall seen
  const auto moves = corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{});
  ASSERT_EQ(moves.size(), 1u);
  EXPECT_NEAR(moves[0].shift, 0.5, 0.06);
  EXPECT_NEAR(moves[0].move.plane.distance(Vec3(12.5, 0, 0)), 0.0, 0.06);
}

// The tile's edge cuts a facade that runs on (a flush neighbour) 0.5 m past the corner: the
// scan ends there, the building does not.
TEST(Corners, AFacadeCutAtTheTileEdgePastTheCornerIsNoEvidence) {
  Scene s = scene(12.5, 0.0);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A van parked across the corner hides the last 0.7 m of the facade over its whole height;
// the scanner sees the van's side, 1 m in front of the facade, where the facade's points end.
TEST(Corners, AnOccluderAtTheCornerIsNoEvidence) {
  Scene s = scene(11.3, 0.0);
  for (double x = 11.3; x < 13.5; x += 0.05)
    for (double z = 0.1; z < 5.9; z += 0.05) s.cloud.points.emplace_back(x, -1.0, z);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// Terraced houses: the neighbour's facade starts at the true corner x = 12, 0.4 m behind this
// one's (the party wall's exposed end is the return there); a lamp post's shadow ends this
// facade's points at x = 11.3. The neighbour's facade beyond is no return at 11.3.
TEST(Corners, ASetBackNeighbourBeyondAShadowIsNoEvidence) {
  Scene s = scene(11.3, 0.0);
  for (double z = 0.1; z < 5.9; z += 0.05) {
    for (double x = 12.0; x < 20.0; x += 0.05) s.cloud.points.emplace_back(x, 0.4, z);
    for (double y = 0.05; y < 0.4; y += 0.05) s.cloud.points.emplace_back(12.0, y, z);
  }
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

TEST(Corners, AFacadeRunningOnIntoANeighbourIsNoEvidence) {
  Scene s = scene(20.0, 0.0);  // a flush neighbour: the plane runs far past the corner
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// See-through is no corner evidence: on the city dev tile, scans of correct buildings' facades
// often end 0.1-0.2 m short of (or past) the true corner with a set-back neighbour or a yard
// seen 1-5 m behind the facade line right past the end. Here the facade's points end at
// x = 11.8 (the last 0.2 m unfitted) and a yard wall is seen 2 m behind it from x = 11.8 on: the
// building still ends at x = 12, and no side wall moves.
TEST(Corners, PointsSeenBehindTheFacadePastItsEndAreNoEvidence) {
  Scene s = scene(11.8, 0.0);
  for (double x = 11.8; x < 16.0; x += 0.05)
    for (double z = 0.1; z < 5.9; z += 0.05) s.cloud.points.emplace_back(x, 2.0, z);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A facade the scan moves 0.4 m, whose points end 0.7 m short of the model's corner with the
// street scanned on past the end and nothing in front or beyond: the building ends there (the
// side wall itself was not scanned), and the model is already known to be misplaced.
TEST(Corners, AMisplacedFacadeEndingInTheOpenMovesTheSideWall) {
  Scene s = scene(11.3, 0.0, 0.4);
  add_street(s, 16.0);
  const auto moves = corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{});
  ASSERT_EQ(moves.size(), 1u);
  EXPECT_NEAR(moves[0].move.plane.distance(Vec3(11.3, 0, 0)), 0.0, 0.06);
  EXPECT_NEAR(moves[0].shift, -0.7, 0.06);
}

// The same end in the open on a facade the scan confirms: a correct building whose facade scan
// was cut off (a neighbour's facade scanned in part, on the city tile) keeps its side wall.
TEST(Corners, ACorrectFacadeEndingInTheOpenMovesNothing) {
  Scene s = scene(11.3, 0.0);
  add_street(s, 16.0);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A misplaced facade cut at the tile's edge: the street ends where the facade's points do.
TEST(Corners, AMisplacedFacadeCutAtTheTileEdgeMovesNothing) {
  Scene s = scene(11.3, 0.0, 0.4);
  add_street(s, 11.3);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A misplaced facade whose last metre is hidden by a van parked in front of it.
TEST(Corners, AMisplacedFacadeShadowedByAVanMovesNothing) {
  Scene s = scene(11.3, 0.0, 0.4);
  add_street(s, 16.0);
  for (double x = 11.3; x < 13.5; x += 0.05)
    for (double z = 0.1; z < 2.5; z += 0.05) s.cloud.points.emplace_back(x, -2.0, z);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A facade that steps: the upper storey's end shows only in the points at its own heights (the
// lower storey runs on to x = 12 below it). Its side wall, seen where the upper facade ends,
// moves there.
TEST(Corners, AnUpperStoreysSideWallMovesToWhereItsFacadeEnds) {
  const Scene s = stepped_scene(0.0, true);
  expect_upper_side_wall_moved(
      s, corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}));
}

// The same on a facade the scan moves 0.4 m, the upper storey's side wall not scanned: the
// upper facade ends in the open at its own heights.
TEST(Corners, AMisplacedUpperStoreyEndingInTheOpenMovesItsSideWall) {
  const Scene s = stepped_scene(0.4, false);
  expect_upper_side_wall_moved(
      s, corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}));
}

// Terraced houses, the facade misplaced 0.4 m and flush with a lower neighbour's: below 3 m the
// scan runs on, above it the facade's own points end at the party wall.
TEST(Corners, AMisplacedFacadeAboveALowerFlushNeighbourMovesThePartyWall) {
  const Scene s = terraced_scene(0.4, 3.0);
  expect_party_wall_moved(s,
                          corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}));
}

// The same beside a taller neighbour (9 m): its facade's points above this roof start at the
// party wall.
TEST(Corners, AMisplacedFacadeBelowATallerFlushNeighbourMovesThePartyWall) {
  const Scene s = terraced_scene(0.4, 9.0);
  expect_party_wall_moved(s,
                          corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}));
}

// A correct facade with the same neighbours: the scan shows no misplaced wall, and a flush
// neighbour's outline alone moves nothing.
TEST(Corners, ACorrectFacadeBesideAFlushNeighbourMovesNothing) {
  for (double top : {3.0, 9.0}) {
    const Scene s = terraced_scene(0.0, top);
    EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty())
        << "neighbour " << top << " m high";
  }
}

// A flush neighbour of one height with this facade: no outline step, no party wall, no move.
TEST(Corners, AMisplacedFacadeFlushWithAnEqualNeighbourMovesNothing) {
  const Scene s = terraced_scene(0.4, 5.9);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}

// A facade the scan moves 0.4 m out whose points end where the model's facade ends (x = 12, the
// corner's edge), the street scanned on past it: the scan agrees with the model's extent. The
// side wall, skewed 22 deg from perpendicular (to x = 15.2 at the back), meets the moved
// facade's plane at x = 11.84: the end 0.16 m past that is the corner sliding along the moved
// facade, no evidence the side wall is off (City3D AHN3 building 00005).
TEST(Corners, AMisplacedFacadeEndingAtTheModelsCornerMovesNoSkewedSideWall) {
  Scene s = scene(12.0, 0.0, 0.4, 15.2);
  add_street(s, 16.0);
  EXPECT_TRUE(corner_moves(s.mesh, s.surfaces, s.scanned, s.cloud, s.planes, MatchConfig{}, PlaneConfig{}).empty());
}
