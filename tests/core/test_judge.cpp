// Never worse, for the whole building: the judge compares the input and the refined model on
// every scan point near the building and on each moved wall's region.
#include <gtest/gtest.h>

#include <utility>

#include "lodrefine/core/judge.h"
#include "lodrefine/core/matching.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using fixtures::add_grid;
using fixtures::box;
using fixtures::wall_patch;

namespace {

const Vec3 kX = Vec3::UnitX(), kY = Vec3::UnitY();

// The front wall (y = y0, facing -y) of the box [0,12] x [y0,8] x [0,6] as a moved wall.
JudgedWall front_wall(double from_y, double to_y, bool corner = false) {
  JudgedWall w;
  w.polygons = {{{0, from_y, 0}, {12, from_y, 0}, {12, from_y, 6}, {0, from_y, 6}}};
  w.from = Plane(-kY, from_y);
  w.to = Plane(-kY, to_y);
  w.corner = corner;
  return w;
}

// A facade scan of the front wall at y = `y` over x in [x0, x1], z in [0.5, 5.5].
void scan_front(PointCloud& cloud, double y, double x0, double x1, unsigned seed = 1) {
  add_grid(cloud, wall_patch({x0, y, 0}, kX, x1 - x0, 0.5, 5.5), 0.05, 0.005, seed);
}

// Street ground in front of the front wall, 3 m deep.
void scan_ground(PointCloud& cloud, double y) {
  add_grid(cloud, {{0, y - 3.0, 0.02}, kX, kY, 0.0, 12.0, 0.0, 2.9}, 0.05);
}

}  // namespace

TEST(Judge, AWallMovedOntoItsScanIsBetter) {
  const Mesh coarse = box({0, -0.5, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.5, 11.5);
  const Judgement j = judge_refinement(coarse, refined, {front_wall(-0.5, 0.0)}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.wall, -1);
  EXPECT_EQ(j.building.points, cloud.points.size());
  EXPECT_NEAR(j.building.rms_before, 0.5, 0.01);
  EXPECT_LT(j.building.rms_after, 0.01);
  EXPECT_EQ(j.building.worse, 0u);
  ASSERT_EQ(j.walls.size(), 1u);
  EXPECT_EQ(j.walls[0].points, cloud.points.size());
}

// A wall moved inwards onto its scan brings it farther from the street's ground in front: the
// ground does not count against the move.
TEST(Judge, StreetGroundDoesNotCountAgainstAWallMovedInwards) {
  const Mesh coarse = box({0, -0.6, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.5, 11.5);
  const std::size_t facade = cloud.points.size();
  scan_ground(cloud, -0.6);
  const Judgement j = judge_refinement(coarse, refined, {front_wall(-0.6, 0.0)}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.points, facade);
}

// The scan shows a bay 2 m wide, 0.5 m out, in a facade the model has plain (0.2 m out): moving
// the wall onto the bay's plane takes it away from the 10 m of facade either side.
TEST(Judge, AWallMovedOntoABaysPlaneIsRefused) {
  const Mesh coarse = box({0, -0.2, 0}, {12, 8, 6}), refined = box({0, -0.5, 0}, {12, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.0, 5.0, 1);
  scan_front(cloud, -0.5, 5.0, 7.0, 2);
  scan_front(cloud, 0.0, 7.0, 12.0, 3);
  const Judgement j = judge_refinement(coarse, refined, {front_wall(-0.2, -0.5)}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Building);
  EXPECT_NE(j.detail.find("RMS"), std::string::npos) << j.detail;
  EXPECT_GT(j.building.rms_after, j.building.rms_before);
  // Onto the facade's own plane it is better.
  const Judgement k = judge_refinement(coarse, box({0, 0, 0}, {12, 8, 6}), {front_wall(-0.2, 0.0)}, cloud,
                                       MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(k.ok) << k.refusal();
  // A bay twice as wide: no plane of the model's wall fits better than where it is. The bay's
  // points lie outside both models: as a scan plane facing the wall, they are its evidence.
  PointCloud wide;
  const ScanPlane left = fixtures::grid_scan_plane(wide, wall_patch({0, 0, 0}, kX, 4.0, 0.5, 5.5), 0.05);
  const ScanPlane bay = fixtures::grid_scan_plane(wide, wall_patch({4, -0.5, 0}, kX, 4.0, 0.5, 5.5), 0.05);
  const ScanPlane right = fixtures::grid_scan_plane(wide, wall_patch({8, 0, 0}, kX, 4.0, 0.5, 5.5), 0.05);
  const Judgement w = judge_refinement(coarse, box({0, 0, 0}, {12, 8, 6}), {front_wall(-0.2, 0.0)}, wide, MatchConfig{},
                                       PlaneConfig{}, {left, bay, right});
  EXPECT_FALSE(w.ok);
  EXPECT_EQ(w.building.points, wide.points.size());
}

// The right side wall (x = 12) moves in by 0.7 m while only the front is scanned: the points do
// not see it (the building fit is unchanged), so only corner evidence may move it.
TEST(Judge, AnUnscannedWallMovesOnlyOnCornerEvidence) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {11.3, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.5, 11.0);
  JudgedWall side;
  side.polygons = {{{12, 0, 0}, {12, 8, 0}, {12, 8, 6}, {12, 0, 6}}};
  side.from = Plane(kX, -12.0);
  side.to = Plane(kX, -11.3);
  const Judgement j = judge_refinement(coarse, refined, {side}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Wall);
  EXPECT_EQ(j.wall, 0);
  EXPECT_NE(j.detail.find("no corner evidence"), std::string::npos) << j.detail;
  side.corner = true;
  EXPECT_EQ(judge_refinement(coarse, refined, {side}, cloud, MatchConfig{}, PlaneConfig{}).check,
            JudgeCheck::Gain);  // nothing shows it
  // The return onto the side wall where the facade ends (corners.h): now the scan shows it.
  add_grid(cloud, wall_patch({11.3, 0.05, 0}, kY, 0.6, 1.0, 5.5), 0.05);
  const Judgement k = judge_refinement(coarse, refined, {side}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(k.ok) << k.refusal();
}

// The front moves onto its scan and the side wall (x = 12) 0.7 m in on corner evidence, while a
// neighbour's wall stands 0.2-1.2 m off the side wall, square to it: its 500 points are nearest
// the side wall and get farther, but they lie on neither of its planes, so the side wall is still
// unscanned (the building check judges them). Scanned where it was, it may not move off its points.
TEST(Judge, OnlyPointsOnAWallsOldOrNewPlaneJudgeTheWall) {
  const Mesh coarse = box({0, -0.5, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {11.3, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.5, 11.0);
  add_grid(cloud, wall_patch({12.2, 4, 0}, kX, 1.0, 0.5, 5.5), 0.1);
  JudgedWall side;
  side.polygons = {{{12, -0.5, 0}, {12, 8, 0}, {12, 8, 6}, {12, -0.5, 6}}};
  side.from = Plane(kX, -12.0);
  side.to = Plane(kX, -11.3);
  side.corner = true;
  const std::vector<JudgedWall> walls = {front_wall(-0.5, 0.0), side};
  const Judgement j = judge_refinement(coarse, refined, walls, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(j.ok) << j.refusal();
  ASSERT_EQ(j.walls.size(), 2u);
  EXPECT_EQ(j.walls[1].points, 0u);
  EXPECT_EQ(j.building.worse, 0u);  // the neighbour's points stand in space both models leave empty
  // The side wall's own points, where it was: moving it off them is refused.
  add_grid(cloud, wall_patch({12, 1, 0}, kY, 6.0, 0.5, 5.5), 0.1);
  const Judgement k = judge_refinement(coarse, refined, walls, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(k.ok);
  EXPECT_EQ(k.check, JudgeCheck::Wall);
  EXPECT_NE(k.detail.find("moved wall 1: RMS"), std::string::npos) << k.detail;
  EXPECT_EQ(k.wall, 1);  // which one, for refine to drop its move
  EXPECT_NEAR(k.walls[1].rms_after, 0.7, 0.01);
}

// A van's view of a model whose front stands 0.7 m out: the wall scanned where it is, a parked
// car 1.2-2.8 m before it, and the neighbour's facade running on past the corner. Moving the
// wall back onto its scan takes it away from the car and the neighbour's wall; both stand in
// space either model leaves empty, and they are no evidence of where the wall is. Left in, the
// car's 6,000 points outnumbered the quarter of changed points the building check allows.
TEST(Judge, ReturnsInSpaceBothModelsLeaveEmptyAreNotJudged) {
  const Mesh coarse = box({0, -0.7, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  const ScanPlane own = fixtures::grid_scan_plane(cloud, wall_patch({0.5, 0, 0}, kX, 11.0, 0.5, 5.5), 0.1);
  const std::size_t wall = cloud.points.size();
  add_grid(cloud, {{2, -1.2, 0.3}, kX, Vec3(0, -0.8, 0.6).normalized(), 0.0, 4.0, 0.0, 1.2}, 0.02, 0.01);  // a car
  const ScanPlane next = fixtures::grid_scan_plane(cloud, wall_patch({12.3, 0, 0}, kX, 5.0, 0.5, 5.5), 0.1);
  ASSERT_GT(cloud.points.size() - wall, 2 * wall);
  const Judgement j = judge_refinement(coarse, refined, {front_wall(-0.7, 0.0)}, cloud, MatchConfig{}, PlaneConfig{},
                                       {own, next}, MatchConfig{}.match_distance + 1.0);
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.points, wall);
  EXPECT_EQ(j.building.worse, 0u);
  EXPECT_LT(j.building.rms_after, 0.01);
}

// The left wall, scanned where it is, moved 1 m inwards (onto nothing): refused.
TEST(Judge, AWallMovedAwayFromItsPointsIsRefused) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({1.0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  add_grid(cloud, wall_patch({0, 7.5, 0}, -kY, 7.0, 0.5, 5.5), 0.05);
  JudgedWall left;
  left.polygons = {{{0, 8, 0}, {0, 0, 0}, {0, 0, 6}, {0, 8, 6}}};
  left.from = Plane(-kX, 0.0);
  left.to = Plane(-kX, 1.0);
  const Judgement j = judge_refinement(coarse, refined, {left}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Building);
  EXPECT_EQ(j.building.worse, cloud.points.size());
  EXPECT_NEAR(j.building.rms_after, 1.0, 0.01);
}

TEST(Judge, NoPointsNearTheBuildingChangesNothingButAMovedWallNeedsEvidence) {
  const Mesh coarse = box({0, -0.5, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  cloud.points.push_back({100, 100, 3});
  const Judgement j = judge_refinement(coarse, refined, {front_wall(-0.5, 0.0)}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_EQ(j.building.points, 0u);
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Wall);
}

// A correct wall refitted 2.5 cm off (its windows pull the plane): no point is clearly closer.
TEST(Judge, AMoveWithinTheScansNoiseIsNoGain) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({0, -0.025, 0}, {12, 8, 6});
  PointCloud cloud;
  scan_front(cloud, -0.0125, 0.5, 11.5);  // halfway: as far from either
  const Judgement j = judge_refinement(coarse, refined, {front_wall(0.0, -0.025)}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Gain);
  EXPECT_EQ(j.building.better, 0u);
}

// Terraced houses: the front runs on, flush, into the neighbour's facade past x = 12, and the
// party wall moved from x = 12 to 11.3 (corners.h). The neighbour's facade points and window
// recesses past it got farther from this building; on the party wall's evidence they are the
// neighbour's and are not judged.
TEST(Judge, AFlushNeighboursPointsPastThePartyWallAreNotJudged) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {11.3, 8, 6});
  PointCloud cloud;
  scan_front(cloud, 0.0, 0.5, 11.3);
  scan_front(cloud, 0.0, 11.3, 14.0, 2);  // the neighbour's facade
  scan_front(cloud, 0.2, 12.5, 13.5, 3);  // a window recess of the neighbour
  JudgedWall party;
  party.polygons = {{{12, 0, 0}, {12, 8, 0}, {12, 8, 6}, {12, 0, 6}}};
  party.from = Plane(kX, -12.0);
  party.to = Plane(kX, -11.3);
  party.corner = true;
  const Judgement refused = judge_refinement(coarse, refined, {party}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_FALSE(refused.ok) << "without the party wall's evidence the neighbour's points count";
  party.flush_facade = Plane(-kY, 0.0);
  const Judgement j = judge_refinement(coarse, refined, {party}, cloud, MatchConfig{}, PlaneConfig{});
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.worse, 0u);
  EXPECT_LT(j.building.points, refused.building.points);
}

// A facade line that steps back part-way (the truth of a generated setback): its left half runs
// 2 m before the model's wall (beyond match_distance), its right half 0.3 m behind it. Moving the
// whole wall back onto the right half takes it farther from the left half's dense line: the
// facade lines beyond match_distance are judged too (up to the supports' reach), so the move is
// refused.
TEST(Judge, AMoveAwayFromAFacadeLineBeyondMatchDistanceIsRefused) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({0, 0.3, 0}, {12, 8, 6});
  PointCloud cloud;
  const ScanPlane front = fixtures::grid_scan_plane(cloud, wall_patch({0.5, -2.0, 0}, kX, 5.0, 0.5, 5.5), 0.05);
  const ScanPlane rear = fixtures::grid_scan_plane(cloud, wall_patch({6.5, 0.3, 0}, kX, 5.0, 0.5, 5.5), 0.05);
  const MatchConfig match;
  const double reach = match.match_distance + 1.0;
  const Judgement j =
      judge_refinement(coarse, refined, {front_wall(0.0, 0.3)}, cloud, match, PlaneConfig{}, {front, rear}, reach);
  EXPECT_FALSE(j.ok);
  EXPECT_EQ(j.check, JudgeCheck::Building);
  EXPECT_EQ(j.building.points, cloud.points.size());
  EXPECT_GT(j.building.rms_after, j.building.rms_before + 0.1);
  EXPECT_GE(j.building.worse, front.inliers.size());
}

// The same move onto the wall's own scan along its whole length, with a parallel facade line 2 m
// out from x = `line_x` for `line_length` m, and a tree 2 m before the wall when `tree`: the
// judgement, and how many of the cloud's points are the wall's own (those first).
namespace {
std::pair<Judgement, std::size_t> judge_move_past_a_line(double line_x, double line_length, bool tree) {
  const Mesh coarse = box({0, 0, 0}, {12, 8, 6}), refined = box({0, 0.3, 0}, {12, 8, 6});
  PointCloud cloud;
  const ScanPlane own = fixtures::grid_scan_plane(cloud, wall_patch({0.5, 0.3, 0}, kX, 11.0, 0.5, 5.5), 0.05);
  const std::size_t facade = cloud.points.size();
  const ScanPlane line =
      fixtures::grid_scan_plane(cloud, wall_patch({line_x, -2.0, 0}, kX, line_length, 0.5, 5.5), 0.05);
  if (tree) add_grid(cloud, {{4, -2.2, 1.0}, kX, Vec3(0, -0.6, 0.8).normalized(), 0.0, 2.0, 0.0, 2.0}, 0.1, 0.15);
  const MatchConfig match;
  return {judge_refinement(coarse, refined, {front_wall(0.0, 0.3)}, cloud, match, PlaneConfig{}, {own, line},
                           match.match_distance + 1.0),
          facade};
}
}  // namespace

// The line 2 m out beside the building (a neighbour's facade standing forward past the corner),
// and a tree 2 m before the wall: neither is the building's facade line, neither is judged, and
// the move onto the wall's own scan is written.
TEST(Judge, AParallelLineBesideTheBuildingAndATreeBeyondMatchDistanceAreNotJudged) {
  const auto [j, facade] = judge_move_past_a_line(12.5, 6.0, true);
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.points, facade);
}

// The line 2 m out standing before the wall's own points (a neighbour's side wall across an
// alley, before a gable end the scan sees whole): another object, not the building's facade
// stepping forward. Its points are not judged, and the move onto the wall's own scan is written
// (a setback's front line stands where the rear line has no points).
TEST(Judge, AFacadeLineBeforeTheWallsOwnPointsIsNotJudged) {
  const auto [j, facade] = judge_move_past_a_line(3.0, 5.0, false);
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.points, facade);
}

// The model's front stands 0.5 m behind the scanned wall, which has a shop window 8 m wide: the
// van sees the shop 1 m behind the glass. Those returns show what is behind the facade, not where
// it is: moving the wall out onto its scan takes it away from them, and that does not count.
TEST(Judge, ReturnsFromARoomSeenThroughGlassAreNotJudged) {
  const Mesh coarse = box({0, 0.5, 0}, {12, 8, 6}), refined = box({0, 0, 0}, {12, 8, 6});
  PointCloud cloud;
  ScanPlane front;
  front.plane = Plane(-kY, 0.0);
  front.facade = true;
  for (const auto& part : {wall_patch({0, 0, 0}, kX, 2.0, 0.3, 5.5), wall_patch({10, 0, 0}, kX, 2.0, 0.3, 5.5),
                           wall_patch({2, 0, 0}, kX, 8.0, 3.1, 5.5), wall_patch({2, 0, 0}, kX, 8.0, 0.3, 0.6)})
    for (int i : add_grid(cloud, part, 0.1, 0.005)) front.inliers.push_back(i);
  for (int i : front.inliers) front.centroid += cloud.points[i];
  front.centroid /= double(front.inliers.size());
  const std::size_t wall = cloud.points.size();
  add_grid(cloud, wall_patch({2.1, 1.0, 0}, kX, 7.8, 0.7, 3.0), 0.03, 0.005);  // the shop's back, through the glass
  const Judgement j = judge_refinement(coarse, refined, {front_wall(0.5, 0.0)}, cloud, MatchConfig{}, PlaneConfig{},
                                       {front}, MatchConfig{}.match_distance + 1.0);
  EXPECT_TRUE(j.ok) << j.refusal();
  EXPECT_EQ(j.building.points, wall);
  EXPECT_LT(j.building.rms_after, 0.02);
}
