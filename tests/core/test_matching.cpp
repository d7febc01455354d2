// Stage 3, matching: the model's planar surfaces (model_surfaces), scan planes matched to walls by point
// ownership (match_surfaces) and the matched points in front of their walls (points_in_front).
// Buildings are hand-made closed prisms; scan planes are noise-free grids built directly, or
// detect_planes on noisy ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lodrefine/core/matching.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

constexpr double kStep = 0.1;  // scan grid spacing (m)

// Box 12 × 8 × 6 m: surface k is face k (0 ground, 1 roof, 2 front y = 0, 3 x = 12, 4 y = 8,
// 5 x = 0).
constexpr int kFront = 2, kRight = 3;
Mesh building() { return box({0, 0, 0}, {12, 8, 6}); }

// Grid points per metre of length `len` at kStep, ends included.
int columns(double len) { return int(std::lround(len / kStep)) + 1; }
const int kRows = columns(5.0);  // z from 0.5 to 5.5

struct Scene {
  Mesh mesh;
  std::vector<ModelSurface> surfaces;
  PointCloud cloud;
  std::vector<ScanPlane> planes;

  explicit Scene(Mesh m) : mesh(std::move(m)), surfaces(model_surfaces(mesh)) {}
  // A facade scan plane along `along` from `start` for `length` m, z from 0.5 to 5.5.
  int scan(const Vec3& start, const Vec3& along, double length) {
    planes.push_back(grid_scan_plane(cloud, wall_patch(start, along, length, 0.5, 5.5), kStep));
    return int(planes.size()) - 1;
  }
  // A scan parallel to the front, at y, from x0 to x1.
  int front_scan(double y, double x0, double x1) { return scan({x0, y, 0}, Vec3::UnitX(), x1 - x0); }
  MatchResult match(const MatchConfig& prm = MatchConfig{}) const {
    return match_surfaces(mesh, surfaces, cloud, planes, prm);
  }
};

// The building with its front scanned at y from x0 to x1.
Scene front_scanned(double y, double x0, double x1) {
  Scene s(building());
  s.front_scan(y, x0, x1);
  return s;
}

const Match* match_of(const MatchResult& r, int surface) {
  for (const auto& m : r.matches)
    if (m.surface == surface) return &m;
  return nullptr;
}

int count_if_x(const PointCloud& cloud, const std::vector<int>& idx, bool (*pred)(double)) {
  return int(std::count_if(idx.begin(), idx.end(), [&](int i) { return pred(cloud.points[i].x()); }));
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// `r` is one match, of the front wall, and no rejection.
testing::AssertionResult only_front_match(const MatchResult& r) {
  if (!r.rejected.empty()) return testing::AssertionFailure() << "rejected:\n" << joined(r.rejected);
  if (r.matches.size() != 1) return testing::AssertionFailure() << r.matches.size() << " matches";
  if (r.matches[0].surface != kFront) return testing::AssertionFailure() << "matched surface " << r.matches[0].surface;
  return testing::AssertionSuccess();
}

}  // namespace

// ---------------------------------------------------------------------------------------
// model_surfaces

TEST(ModelSurfaces, BoxGivesSixOutwardSurfacesWithTheirSemantics) {
  const auto ss = model_surfaces(building());
  ASSERT_EQ(ss.size(), 6u);
  const Vec3 normals[6] = {-Vec3::UnitZ(), Vec3::UnitZ(), -Vec3::UnitY(), Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitX()};
  const Semantic sems[6] = {Semantic::Ground, Semantic::Roof, Semantic::Wall,
                            Semantic::Wall,   Semantic::Wall, Semantic::Wall};
  const double areas[6] = {96, 96, 72, 48, 72, 48};
  const Vec3 centroids[6] = {{6, 4, 0}, {6, 4, 6}, {6, 0, 3}, {12, 4, 3}, {6, 8, 3}, {0, 4, 3}};
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE("surface " + std::to_string(k));
    EXPECT_EQ(ss[k].faces, std::vector<int>{k});
    EXPECT_EQ(ss[k].sem, sems[k]);
    EXPECT_NEAR(ss[k].area, areas[k], 1e-9);
    EXPECT_NEAR((ss[k].plane.n - normals[k]).norm(), 0.0, 1e-9);
    EXPECT_NEAR(ss[k].plane.distance(centroids[k]), 0.0, 1e-9);
    EXPECT_LT(ss[k].plane.distance({6, 4, 3}), -2.9);  // the inside is behind every surface
    EXPECT_NEAR((ss[k].centroid - centroids[k]).norm(), 0.0, 1e-9);
  }
}

// The front wall in two faces (split at x = 5): one surface, whose semantic is the one covering
// most of its area.
TEST(ModelSurfaces, CoplanarEdgeConnectedFacesAreOneSurfaceOfTheLargerSemantic) {
  const Mesh split = extrusion({{0, 0}, {5, 0}, {12, 0}, {12, 8}, {0, 8}}, 0.0, 6.0);
  for (int mislabelled : {2, 3}) {
    Mesh m = split;
    m.faces[mislabelled].sem = Semantic::Roof;  // face 2 is 30 m², face 3 is 42 m²
    const auto ss = model_surfaces(m);
    ASSERT_EQ(ss.size(), 6u);
    const auto front = std::find_if(ss.begin(), ss.end(), [](const ModelSurface& s) { return s.faces.size() == 2; });
    ASSERT_NE(front, ss.end());
    std::vector<int> faces = front->faces;
    std::sort(faces.begin(), faces.end());
    EXPECT_EQ(faces, (std::vector<int>{2, 3}));
    EXPECT_EQ(front->sem, mislabelled == 2 ? Semantic::Wall : Semantic::Roof);
    EXPECT_NEAR(front->area, 72.0, 1e-9);
    EXPECT_NEAR((front->centroid - Vec3(6, 0, 3)).norm(), 0.0, 1e-9);
    EXPECT_NEAR((front->plane.n + Vec3::UnitY()).norm(), 0.0, 1e-9);
  }
}

// A U-shaped footprint: the two front walls either side of the notch are coplanar but share no
// edge, so they stay two surfaces.
TEST(ModelSurfaces, CoplanarFacesWithoutACommonEdgeStayApart) {
  const Mesh u = extrusion({{0, 0}, {4, 0}, {4, 5}, {8, 5}, {8, 0}, {12, 0}, {12, 8}, {0, 8}}, 0.0, 6.0);
  const auto ss = model_surfaces(u);
  ASSERT_EQ(ss.size(), 10u);
  int fronts = 0;
  for (const auto& s : ss)
    if (s.plane.n.y() < -0.999 && std::abs(s.plane.d) < 1e-9) {
      ++fronts;
      EXPECT_EQ(s.faces.size(), 1u);
      EXPECT_NEAR(s.area, 24.0, 1e-9);
    }
  EXPECT_EQ(fronts, 2);
}

// A face 15 mm off its neighbour's plane joins it at the default distance (2 cm), not at 1 cm.
TEST(ModelSurfaces, GroupingToleranceIsTheDistanceArgument) {
  const Mesh m = extrusion({{0, 0}, {5, 0}, {12, 0.015}, {12, 8}, {0, 8}}, 0.0, 6.0);
  EXPECT_EQ(model_surfaces(m).size(), 6u);
  EXPECT_EQ(model_surfaces(m, 1.0, 0.01).size(), 7u);
}

// ---------------------------------------------------------------------------------------
// match_surfaces and points_in_front

TEST(Matching, WallScannedInFrontIsMatchedToItsPlane) {
  Scene s = front_scanned(-0.4, 0.0, 12.0);
  const MatchResult r = s.match();
  ASSERT_TRUE(only_front_match(r));
  const Match& m = r.matches[0];
  EXPECT_EQ(m.scan_plane, 0);
  EXPECT_EQ(int(m.owned.size()), columns(12.0) * kRows);
  EXPECT_EQ(m.owned, s.planes[0].inliers);
  EXPECT_NEAR(m.s_normal, 1.0, 1e-12);
  EXPECT_NEAR(m.d_centroid, 0.4, 1e-9);
  EXPECT_NEAR(m.c_bbox, 60.0 / 72.0, 1e-9);  // 12 × 5 m of points on the 12 × 6 m wall
  EXPECT_NEAR(m.s_match, 0.5 * 1.0 + 0.5 * 60.0 / 72.0, 1e-9);
  EXPECT_NEAR(r.q_model, m.s_match, 1e-12);
}

TEST(Matching, NonFacadePlanesAreNeverMatched) {
  Scene s = front_scanned(-0.4, 0.0, 12.0);
  s.planes[0].facade = false;
  const MatchResult r = s.match();
  EXPECT_TRUE(r.matches.empty());
  EXPECT_TRUE(r.rejected.empty()) << joined(r.rejected);
}

// Stage 2 into stage 3 (planes into matching): the front and the right side scanned 0.4 m out with 1 cm noise, plus
// the street; each wall gets its own detected plane, the ground none.
TEST(Matching, DetectedPlanesOfTwoScannedWallsMatchTheirWalls) {
  Scene s(building());
  const auto front = add_grid(s.cloud, wall_patch({0, -0.4, 0}, Vec3::UnitX(), 12.4, 0.0, 5.0), kStep, 0.01, 1);
  const auto right =
      add_grid(s.cloud, {{12.4, 0, 0}, Vec3::UnitY(), Vec3::UnitZ(), -0.3, 8.0, 0.0, 5.0}, kStep, 0.01, 2);
  add_grid(s.cloud, {{0, 0, 0}, Vec3::UnitX(), Vec3::UnitY(), 0.0, 12.4, -3.0, -0.5}, kStep, 0.01, 3);
  s.planes = detect_planes(s.cloud, PlaneConfig{});
  ASSERT_EQ(s.planes.size(), 3u);
  const MatchResult r = s.match();
  EXPECT_TRUE(r.rejected.empty()) << joined(r.rejected);
  ASSERT_EQ(r.matches.size(), 2u);
  double q = 0.0;
  for (const auto& [surface, points] : {std::pair{kFront, front}, std::pair{kRight, right}}) {
    SCOPED_TRACE("surface " + std::to_string(surface));
    const Match* m = match_of(r, surface);
    ASSERT_NE(m, nullptr);
    EXPECT_TRUE(s.planes[m->scan_plane].facade);
    EXPECT_GT(std::abs(m->s_normal), std::cos(radians(1.0)));
    EXPECT_NEAR(m->d_centroid, 0.4, 0.005);
    EXPECT_GE(m->owned.size(), std::size_t(0.96 * double(points.size())));
    EXPECT_LE(m->owned.size(), points.size() + std::size_t(kRows));
    q += m->s_match;
  }
  EXPECT_NE(r.matches[0].scan_plane, r.matches[1].scan_plane);
  EXPECT_NEAR(r.q_model, q, 1e-12);
}

// match_distance is a hard filter on each point: a facade 2 m off the wall owns nothing.
TEST(Matching, PlaneBeyondMatchDistanceIsNotMatched) {
  Scene s = front_scanned(-2.0, 0.0, 12.0);
  EXPECT_TRUE(s.match().matches.empty());
  MatchConfig far;
  far.match_distance = 2.5;
  const MatchResult r = s.match(far);
  ASSERT_TRUE(only_front_match(r));
  EXPECT_NEAR(r.matches[0].d_centroid, 2.0, 1e-9);
}

// MatchResult::rejected lists turned-down matches of walls in reach only: a plane beyond
// match_distance or match_angle_deg of every wall has no candidate and no line (else every
// roof, ground and neighbour plane would be listed against every wall).
TEST(Matching, PlanesOutOfReachAreNotListedAsRejections) {
  Scene far = front_scanned(-2.0, 0.0, 12.0);
  const MatchResult r_far = far.match();
  EXPECT_TRUE(r_far.matches.empty());
  EXPECT_TRUE(r_far.rejected.empty());
  Scene turned(building());
  const Vec3 u(std::cos(radians(20.0)), std::sin(radians(20.0)), 0.0);
  turned.scan(Vec3(6, -0.4, 0) - 2.0 * u, u, 4.0);
  const MatchResult r_turned = turned.match();
  EXPECT_TRUE(r_turned.matches.empty());
  EXPECT_TRUE(r_turned.rejected.empty());
}

// match_angle_deg (10°) is a hard filter on the normals: a 4 m scan plane through the wall's
// centre line 0.4 m out, turned about the vertical, matches at 5° and not at 20°, unless the
// filter allows 25°.
TEST(Matching, PlaneTurnedBeyondMatchAngleIsNotMatched) {
  auto turned = [](double deg) {
    Scene s(building());
    const Vec3 u(std::cos(radians(deg)), std::sin(radians(deg)), 0.0);
    s.scan(Vec3(6, -0.4, 0) - 2.0 * u, u, 4.0);
    return s;
  };
  const MatchResult five = turned(5.0).match();
  ASSERT_TRUE(only_front_match(five));
  EXPECT_NEAR(five.matches[0].s_normal, std::cos(radians(5.0)), 1e-12);
  EXPECT_NEAR(five.matches[0].d_centroid, 0.4, 1e-9);

  const Scene twenty = turned(20.0);
  EXPECT_TRUE(twenty.match().matches.empty());
  MatchConfig wide;
  wide.match_angle_deg = 25.0;
  const MatchResult r = twenty.match(wide);
  ASSERT_TRUE(only_front_match(r));
  EXPECT_NEAR(r.matches[0].s_normal, std::cos(radians(20.0)), 1e-12);
  EXPECT_EQ(int(r.matches[0].owned.size()), columns(4.0) * kRows);
}

// A facade plane running on along a flush neighbour (x from 12 to 24, not in the model): the
// wall owns only the points in front of its outline grown by match_margin (x <= 12.5). The
// grid is offset by half a step so that no point lies on a margin's edge.
TEST(Matching, FlushNeighbourPointsBeyondTheMarginAreNotOwned) {
  Scene s = front_scanned(-0.4, 0.05, 23.95);
  const MatchResult r = s.match();
  ASSERT_TRUE(only_front_match(r));
  const Match& m = r.matches[0];
  EXPECT_EQ(int(m.owned.size()), columns(12.4) * kRows);  // x = 0.05 ... 12.45
  EXPECT_EQ(count_if_x(s.cloud, m.owned, [](double x) { return x > 12.5; }), 0);
  // Points 12.4 × 5 m, 11.95 × 5 m of them on the 12 × 6 m wall.
  EXPECT_NEAR(m.c_bbox, 59.75 / (72.0 + 62.0 - 59.75), 1e-9);

  // points_in_front: the same points at the same margin, in index order; the wall's own extent
  // at margin 0, 1.5 m more of the neighbour at margin 2.
  EXPECT_EQ(points_in_front(s.mesh, s.surfaces, s.planes, r, s.cloud, 0.5), m.owned);
  const auto exact = points_in_front(s.mesh, s.surfaces, s.planes, r, s.cloud, 0.0);
  EXPECT_EQ(int(exact.size()), columns(11.9) * kRows);  // x = 0.05 ... 11.95
  EXPECT_TRUE(std::is_sorted(exact.begin(), exact.end()));
  EXPECT_EQ(count_if_x(s.cloud, exact, [](double x) { return x > 12.0; }), 0);
  EXPECT_EQ(int(points_in_front(s.mesh, s.surfaces, s.planes, r, s.cloud, 2.0).size()), columns(13.9) * kRows);
}

// Only the neighbour's facade, flush with the front and starting just past the corner: the
// points within the margin are too few of the wall, and the rejection says so.
TEST(Matching, NeighbourFacadeAloneIsRejectedForCoverage) {
  Scene s(building());
  s.front_scan(-0.4, 12.05, 23.95);  // within the margin: x = 12.05 ... 12.45
  const MatchResult r = s.match();
  EXPECT_TRUE(r.matches.empty());
  ASSERT_EQ(r.rejected.size(), 1u);
  EXPECT_NE(r.rejected[0].find("scan plane 0 / wall surface 2"), std::string::npos) << r.rejected[0];
  EXPECT_NE(r.rejected[0].find("cover too little"), std::string::npos) << r.rejected[0];
}

// Two flush buildings in one mesh: their front walls are coplanar but separate surfaces. One
// scan plane along both gives each wall the points in front of it: the points only one grown
// outline covers go to that wall, the strip both cover (x in [11.5, 12.5]) to one of them.
TEST(Matching, PlaneSpanningTwoCollinearWallsIsSharedByOwnership) {
  Scene s(merged(building(), box({12, 0, 0}, {20, 8, 6})));
  ASSERT_EQ(s.surfaces.size(), 12u);
  const int left = kFront, right = 6 + kFront;
  s.front_scan(-0.4, 0.05, 19.95);
  const MatchResult r = s.match();
  EXPECT_TRUE(r.rejected.empty()) << joined(r.rejected);
  ASSERT_EQ(r.matches.size(), 2u);
  const Match *a = match_of(r, left), *b = match_of(r, right);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->owned.size() + b->owned.size(), s.planes[0].inliers.size());
  EXPECT_EQ(count_if_x(s.cloud, a->owned, [](double x) { return x > 12.5; }), 0);
  EXPECT_EQ(count_if_x(s.cloud, b->owned, [](double x) { return x < 11.5; }), 0);
  EXPECT_EQ(count_if_x(s.cloud, a->owned, [](double x) { return x < 11.5; }), columns(11.4) * kRows);  // 0.05 ... 11.45
  EXPECT_EQ(count_if_x(s.cloud, b->owned, [](double x) { return x > 12.5; }), columns(7.4) * kRows);  // 12.55 ... 19.95
}

// A setback: the front is y = 0 for x in [0, 6] and y = 1.5 for x in [6, 12]. The front's scan
// lies 0.3 m behind its wall (1.2 m in front of the setback wall, inside match_distance), the
// setback's scan 0.3 m in front of it: each wall keeps its own plane, all of its points.
TEST(Matching, SetbackWallDoesNotStealTheFrontsPoints) {
  const Mesh stepped = extrusion({{0, 0}, {6, 0}, {6, 1.5}, {12, 1.5}, {12, 8}, {0, 8}}, 0.0, 6.0);
  constexpr int kFrontWall = 2, kSetback = 4;
  Scene s(stepped);
  ASSERT_EQ(s.surfaces.size(), 8u);
  s.front_scan(0.3, 0.0, 6.0);
  const MatchResult alone = s.match();
  ASSERT_EQ(alone.matches.size(), 1u);
  EXPECT_EQ(alone.matches[0].surface, kFrontWall);
  EXPECT_EQ(int(alone.matches[0].owned.size()), columns(6.0) * kRows);

  s.front_scan(1.2, 6.0, 12.0);
  const MatchResult both = s.match();
  EXPECT_TRUE(both.rejected.empty()) << joined(both.rejected);
  ASSERT_EQ(both.matches.size(), 2u);
  const Match *f = match_of(both, kFrontWall), *b = match_of(both, kSetback);
  ASSERT_TRUE(f && b);
  EXPECT_EQ(f->scan_plane, 0);
  EXPECT_EQ(b->scan_plane, 1);
  EXPECT_EQ(f->owned, s.planes[0].inliers);
  EXPECT_EQ(b->owned, s.planes[1].inliers);
  EXPECT_NEAR(f->d_centroid, 0.3, 1e-9);
  EXPECT_NEAR(b->d_centroid, 0.3, 1e-9);
}

// Two planes in front of one wall: the wall takes the one whose points span it (the higher
// S_match; here also the one with more points in front of it), whatever their order.
TEST(Matching, WallTakesThePlaneWhosePointsSpanIt) {
  for (bool big_first : {false, true}) {
    Scene s(building());
    if (big_first) s.front_scan(-0.3, 0.0, 12.0);
    s.front_scan(-0.6, 0.0, 4.0);
    if (!big_first) s.front_scan(-0.3, 0.0, 12.0);
    const MatchResult r = s.match();
    ASSERT_TRUE(only_front_match(r));
    EXPECT_EQ(r.matches[0].scan_plane, big_first ? 0 : 1);
    EXPECT_EQ(int(r.matches[0].owned.size()), columns(12.0) * kRows);
    EXPECT_NEAR(r.matches[0].d_centroid, 0.3, 1e-9);
  }
}

// A bay: the facade line scanned 0.3 m in front of the wall on both sides of it (x in [0, 3] and
// [9, 12]), the bay's front 1.2 m in front for x in [3, 9], nearer the scanner and sampled four
// times as densely: it has more points in front of the wall (12221 against 3162), but the
// facade line's span the wall (C_bbox 0.83 against 0.42). The wall takes the facade line; the
// selection adds the bay where its points are.
TEST(Matching, ABaysDenserFrontDoesNotTakeTheFacadeLineItStandsOn) {
  for (bool bay_first : {false, true}) {
    Scene s(building());
    auto bay = [&] {
      s.planes.push_back(grid_scan_plane(s.cloud, wall_patch({3, -1.2, 0}, Vec3::UnitX(), 6.0, 0.5, 5.5), kStep / 2));
    };
    if (bay_first) bay();
    s.front_scan(-0.3, 0.0, 3.0);
    const ScanPlane right = grid_scan_plane(s.cloud, wall_patch({9, -0.3, 0}, Vec3::UnitX(), 3.0, 0.5, 5.5), kStep);
    const int line_plane = int(s.planes.size()) - 1;
    ScanPlane& line = s.planes[line_plane];
    line.inliers.insert(line.inliers.end(), right.inliers.begin(), right.inliers.end());
    line.centroid = Vec3(6.0, -0.3, 3.0);
    if (!bay_first) bay();
    const std::size_t line_points = s.planes[line_plane].inliers.size();
    ASSERT_GT(s.planes[1 - line_plane].inliers.size(), 3 * line_points);
    const MatchResult r = s.match();
    ASSERT_TRUE(only_front_match(r));
    EXPECT_EQ(r.matches[0].scan_plane, line_plane);
    EXPECT_EQ(r.matches[0].owned.size(), line_points);
    EXPECT_NEAR(r.matches[0].d_centroid, 0.3, 1e-9);
  }
}

// The front scanned 1.1 m out to x = 12.4, the right side seen only from y = 3 on: the corner the
// two planes make lies 4.1 m beyond the side's points and 1.1 m beyond the side wall's end in the
// model (a front moved onto something standing before the building). Both matches conflict; the
// one with the lower S_match (the side's) goes, with its reason.
TEST(Matching, CornerBeyondTheAdjacentFacadesPointsIsRejected) {
  Scene s = front_scanned(-1.1, 0.0, 12.4);
  s.scan({12.4, 3.0, 0}, Vec3::UnitY(), 5.0);
  const MatchResult r = s.match();
  ASSERT_EQ(r.matches.size(), 1u);
  EXPECT_EQ(r.matches[0].surface, kFront);
  ASSERT_EQ(r.rejected.size(), 1u);
  EXPECT_NE(r.rejected[0].find("scan plane 1 / wall surface 3"), std::string::npos) << r.rejected[0];
  EXPECT_NE(r.rejected[0].find("corner"), std::string::npos) << r.rejected[0];
  // Seen to the corner, the side is consistent: both kept.
  Scene full = front_scanned(-1.1, 0.0, 12.4);
  full.scan({12.4, -1.0, 0}, Vec3::UnitY(), 9.0);
  EXPECT_EQ(full.match().matches.size(), 2u);
}

// The front 0.4 m out, the right side seen only from y = 3 on (a tree, a van, the scanner's range
// hid its first metres): the corner lies 3.4 m beyond the side's points but only 0.4 m beyond the
// side wall's end in the model, where a wall 0.4 m off puts it. Both walls are the building's:
// both kept (the side was rejected, and the building kept half its error).
TEST(Matching, CornerTheScanDoesNotReachIsKept) {
  Scene s = front_scanned(-0.4, 0.0, 12.4);
  s.scan({12.4, 3.0, 0}, Vec3::UnitY(), 5.0);
  const MatchResult r = s.match();
  EXPECT_EQ(r.matches.size(), 2u) << joined(r.rejected);
  EXPECT_TRUE(r.rejected.empty()) << joined(r.rejected);
}
