// What the selection's program knows of each candidate (shell_describe.h), on a box 10 x 8 x 6
// with one scanned facade 1 m before its front wall, over x in (0, 4): numbers worked by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "refine/shell_describe.h"
#include "refine/shell_supports.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::detail;
using namespace lodrefine::fixtures;

namespace {

// The box's supports plus the facade y = -1, its points 5 cm apart at the centres of 5 cm
// squares over x in (0, 4), z in (0, 6): 80 x 120 points, 16 x 24 occupancy cells.
struct Scene {
  Mesh start = box({0, 0, 0}, {10, 8, 6});
  Supports s;
  CandidateSet cs;
  int front = -1, back = -1, roof = -1, facade = -1;  // supporting planes
};

Scene scene() {
  Scene sc;
  for (std::size_t f = 0; f < sc.start.faces.size(); ++f) sc.start.faces[f].source = 100 + int(f);
  add_start_planes(sc.start, 0.01, sc.s);
  for (std::size_t f = 0; f < sc.start.faces.size(); ++f) {
    const Vec3 c = polygon_centroid(face_points(sc.start, sc.start.faces[f]));
    if (c.y() < 1e-9) sc.front = sc.s.face_plane[f];
    if (c.y() > 8 - 1e-9) sc.back = sc.s.face_plane[f];
    if (c.z() > 6 - 1e-9) sc.roof = sc.s.face_plane[f];
  }
  std::vector<Vec3> pts;
  for (int i = 0; i < 80; ++i)
    for (int j = 0; j < 120; ++j) pts.emplace_back(0.025 + 0.05 * i, -1.0, 0.025 + 0.05 * j);
  sc.facade = int(sc.s.planes.size());
  sc.s.planes.push_back({Plane::through({0, -1, 0}, {0, -1, 0}), Semantic::Wall, true, 0, Provenance::Scan});
  sc.s.points.push_back(pts);
  sc.cs = build_candidates(sc.s.planes, building_region(sc.start, sc.s, 10.0));
  return sc;
}

// The candidate on supporting plane `k` whose centroid lies at `at`.
int candidate_at(const CandidateSet& cs, int k, const Vec3& at) {
  const auto support = cs.supports();
  const auto centroid = cs.centroids();
  for (int f = 0; f < cs.size(); ++f)
    if (support[CandidateFace(f)] == k && (centroid[CandidateFace(f)] - at).norm() < 1e-6) return f;
  return -1;
}

}  // namespace

TEST(ShellDescribe, ScannedFacadeHasItsCoveredShareAndTheAreaItsPointsExplain) {
  Scene sc = scene();
  const FaceProps props = describe_candidates(sc.cs, sc.start, sc.s, RefineConfig{});
  const int f = candidate_at(sc.cs, sc.facade, {5, -1, 3});  // 10 x 6, between x = 0, 10 and z = 0, 6
  ASSERT_GE(f, 0);
  const FaceIndex fi(f);
  EXPECT_FALSE(props.in_start[fi]);
  EXPECT_EQ(props.source[fi], -1);
  // The points' cells and 2 around: x in [-0.5, 4.5), all of z: 18 of the face's 40 columns.
  EXPECT_NEAR(props.confidence[fi], 0.45, 1e-12);
  // Every point on the plane (weight 1), each standing for 384 cells x 0.0625 m² / 9600 points.
  EXPECT_NEAR(props.fit[fi], 24.0, 1e-9);
  EXPECT_TRUE(props.in_zone[fi]);
  // The facade's piece past x = 10 lies beyond the evidence's reach (2.25 m past x = 4).
  const int beyond = candidate_at(sc.cs, sc.facade, {10.5, -1, 3});
  ASSERT_GE(beyond, 0);
  EXPECT_FALSE(props.in_zone[FaceIndex(beyond)]);
  EXPECT_NEAR(props.confidence[FaceIndex(beyond)], 0.0, 1e-12);
  EXPECT_NEAR(props.fit[FaceIndex(beyond)], 0.0, 1e-12);
}

TEST(ShellDescribe, StartFacesKeepThePriorWhereNoFacadeContradictsIt) {
  Scene sc = scene();
  const FaceProps props = describe_candidates(sc.cs, sc.start, sc.s, RefineConfig{});
  // The front wall: the facade 1 m before it covers 45 % of it, so its prior is 0.55; it has no
  // points of its own (scanned 0, no fit), and the evidence reaches it.
  const int front = candidate_at(sc.cs, sc.front, {5, 0, 3});
  ASSERT_GE(front, 0);
  EXPECT_TRUE(props.in_start[FaceIndex(front)]);
  EXPECT_EQ(props.source[FaceIndex(front)], 100 + 2);  // the fixture's wall y = lo
  EXPECT_NEAR(props.confidence[FaceIndex(front)], 0.55, 1e-12);
  EXPECT_EQ(props.fit[FaceIndex(front)], 0.0);
  EXPECT_TRUE(props.in_zone[FaceIndex(front)]);
  // The back wall: 9 m from the facade (beyond kSeeThrough, 3 m) keeps its prior whole; beyond
  // the evidence's reach.
  const int back = candidate_at(sc.cs, sc.back, {5, 8, 3});
  ASSERT_GE(back, 0);
  EXPECT_NEAR(props.confidence[FaceIndex(back)], 1.0, 1e-12);
  EXPECT_FALSE(props.in_zone[FaceIndex(back)]);
  // The roof: no facade contradicts a roof.
  const int roof = candidate_at(sc.cs, sc.roof, {5, 4, 6});
  ASSERT_GE(roof, 0);
  EXPECT_TRUE(props.in_start[FaceIndex(roof)]);
  EXPECT_NEAR(props.confidence[FaceIndex(roof)], 1.0, 1e-12);
  // Outside the box on the front plane: neither the start's nor scanned.
  const int aside = candidate_at(sc.cs, sc.front, {-0.5, 0, 3});
  ASSERT_GE(aside, 0);
  EXPECT_FALSE(props.in_start[FaceIndex(aside)]);
  EXPECT_NEAR(props.confidence[FaceIndex(aside)], 0.0, 1e-12);
}

TEST(ShellDescribe, PropsCarryToTheKeptCandidates) {
  Scene sc = scene();
  const FaceProps props = describe_candidates(sc.cs, sc.start, sc.s, RefineConfig{});
  std::vector<char> keep(std::size_t(sc.cs.size()), 0);
  for (int f = 0; f < sc.cs.size(); ++f) keep[std::size_t(f)] = props.in_zone[FaceIndex(f)];
  CandidateSet kept = kept_candidates(sc.cs, keep);
  const FaceProps carried = props.carried_to(kept.mesh, keep);
  ASSERT_GT(kept.size(), 0);
  ASSERT_LT(kept.size(), sc.cs.size());
  int g = 0;
  for (int f = 0; f < sc.cs.size(); ++f) {
    if (!keep[std::size_t(f)]) continue;
    const FaceIndex from(f), to(g++);
    EXPECT_EQ(bool(carried.in_start[to]), bool(props.in_start[from]));
    EXPECT_EQ(carried.source[to], props.source[from]);
    EXPECT_EQ(carried.confidence[to], props.confidence[from]);
    EXPECT_EQ(bool(carried.in_zone[to]), bool(props.in_zone[from]));
    EXPECT_EQ(carried.fit[to], props.fit[from]);
  }
  EXPECT_EQ(g, kept.size());
}
