#include <gtest/gtest.h>

#include <map>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/confidence.h"
#include "lodrefine/core/selection.h"

using namespace lodrefine;

namespace {
// The six planes of the box [0,a]x[0,b]x[0,c], outward.
std::vector<SupportPlane> box_planes(double a, double b, double c) {
  std::vector<SupportPlane> p;
  p.push_back({Plane(Vec3(-1, 0, 0), 0), Semantic::Wall, false, 0});
  p.push_back({Plane(Vec3(1, 0, 0), -a), Semantic::Wall, false, 1});
  p.push_back({Plane(Vec3(0, -1, 0), 0), Semantic::Wall, false, 2});
  p.push_back({Plane(Vec3(0, 1, 0), -b), Semantic::Wall, false, 3});
  p.push_back({Plane(Vec3(0, 0, -1), 0), Semantic::Ground, false, 4});
  p.push_back({Plane(Vec3(0, 0, 1), -c), Semantic::Roof, false, 5});
  return p;
}

bool inside_box(const Vec3& p, double a, double b, double c) {
  return p.x() > -1e-9 && p.x() < a + 1e-9 && p.y() > -1e-9 && p.y() < b + 1e-9 && p.z() > -1e-9 && p.z() < c + 1e-9;
}
}  // namespace

TEST(Candidates, BoxArrangementHasNinePiecesPerPlane) {
  const auto planes = box_planes(10, 8, 6);
  const Region region = Region::around({Vec3(0, 0, 0), Vec3(10, 8, 6)}, 0.1, 1.0);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.faces.size(), 54u);  // each plane section is cut by 4 perpendicular planes into 3x3
  double total = 0.0;
  for (const auto& f : cs.faces) total += f.area;
  // Sections: planes x=const are (8+2*1.8)x(6+2*1.6) ... compare with the region's cross-sections.
  const double expect = 2 * (2 * region.half.y() * 2 * region.half.z()) + 2 * (2 * region.half.x() * 2 * region.half.z()) +
                        2 * (2 * region.half.x() * 2 * region.half.y());
  EXPECT_NEAR(total, expect, 1e-6);
  // Interior edges (not on the region boundary) are shared by exactly 4 faces (2 planes x 2 sides).
  for (const auto& e : cs.edges) {
    if (e.box_plane >= 0) EXPECT_EQ(e.faces.size(), 1u);
    else EXPECT_EQ(e.faces.size(), 4u);
  }
}

TEST(Candidates, NearAxisAlignedPlanesGiveFiniteVertices) {
  // Refitted planes carry normals like (1e-19, 1, 1e-17): the meets must stay on the box.
  auto planes = box_planes(10, 8, 6);
  planes[2].plane = Plane(Vec3(1e-19, -1, 3e-17), 1e-18);
  planes[5].plane = Plane(Vec3(2e-18, -1e-19, 1), -6);
  const Region region = Region::around({Vec3(0, 0, 0), Vec3(10, 8, 6)}, 0.1, 1.0);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.faces.size(), 54u);
  for (const auto& v : cs.vertices) EXPECT_TRUE(region.contains(v, 1e-6)) << v.transpose();
}

TEST(Selection, RecoversTheClosedBoxFromConfidence) {
  const double a = 10, b = 8, c = 6;
  const auto planes = box_planes(a, b, c);
  const Region region = Region::around({Vec3(0, 0, 0), Vec3(a, b, c)}, 0.1, 1.0);
  const CandidateSet cs = build_candidates(planes, region);
  // Model references: the six box faces.
  std::vector<ModelReference> refs = {
      {{Vec3(0, 0, 0), Vec3(0, 0, c), Vec3(0, b, c), Vec3(0, b, 0)}},
      {{Vec3(a, 0, 0), Vec3(a, b, 0), Vec3(a, b, c), Vec3(a, 0, c)}},
      {{Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, 0, c), Vec3(0, 0, c)}},
      {{Vec3(0, b, 0), Vec3(0, b, c), Vec3(a, b, c), Vec3(a, b, 0)}},
      {{Vec3(0, 0, 0), Vec3(0, b, 0), Vec3(a, b, 0), Vec3(a, 0, 0)}},
      {{Vec3(0, 0, c), Vec3(a, 0, c), Vec3(a, b, c), Vec3(0, b, c)}}};
  Params prm;
  const auto conf = candidate_confidence(cs, refs, {}, prm);
  std::vector<double> cost;
  int full = 0;
  for (std::size_t f = 0; f < cs.faces.size(); ++f) {
    cost.push_back(coverage_cost(cs.faces[f].area, conf[f].value, prm.tau_cov));
    full += conf[f].value > 0.99;
  }
  EXPECT_EQ(full, 6);
  const SelectionResult sel = select_faces(cs, cost, std::vector<int>(cs.edges.size(), 0), prm);
  ASSERT_TRUE(sel.ok) << sel.status_text();
  EXPECT_EQ(sel.status_text(), "optimal");
  double area = 0.0;
  int count = 0;
  for (std::size_t f = 0; f < cs.faces.size(); ++f)
    if (sel.selected[f]) {
      ++count;
      area += cs.faces[f].area;
      EXPECT_TRUE(inside_box(cs.faces[f].centroid, a, b, c));
    }
  EXPECT_EQ(count, 6);
  EXPECT_NEAR(area, 2 * (a * b + b * c + a * c), 1e-6);
  // Every edge carries 0 or 2 selected faces.
  for (const auto& e : cs.edges) {
    int n = 0;
    for (int f : e.faces) n += sel.selected[f];
    EXPECT_TRUE(n == 0 || n == 2);
  }
}

TEST(Selection, InfeasibleBoundaryIsReportedNotCrashed) {
  // One plane only: its faces can never close, yet the boundary demands a continuation.
  std::vector<SupportPlane> planes = {{Plane(Vec3(0, 0, 1), -1), Semantic::Roof, false, 0}};
  const Region region = Region::around({Vec3(0, 0, 0), Vec3(2, 2, 2)}, 0.0, 0.5);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.faces.size(), 1u);
  std::vector<int> outside(cs.edges.size(), 0);
  outside[0] = 1;  // one continuing edge: the face must be selected, then 3 edges are open
  Params prm;
  const SelectionResult sel = select_faces(cs, {-1.0}, outside, prm);
  EXPECT_FALSE(sel.ok);
  EXPECT_EQ(sel.status_text(), "infeasible");
}

TEST(Confidence, SigmoidCostChangesSignAtTau) {
  EXPECT_NEAR(coverage_cost(2.0, 0.3, 0.3), 0.0, 1e-12);
  EXPECT_GT(coverage_cost(2.0, 0.0, 0.3), 0.0);
  EXPECT_LT(coverage_cost(2.0, 1.0, 0.3), 0.0);
  EXPECT_NEAR(coverage_cost(1.0, 1.0, 0.3), 1.0 / (1.0 + std::exp(0.7)) - 0.5, 1e-12);
}
