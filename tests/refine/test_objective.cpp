// The selection program's costs (objective.h): each term on numbers worked by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "lodrefine/refine/objective.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(Objective, SigmoidCostChangesSignAtTau) {
  EXPECT_NEAR(coverage_cost(2.0, 0.3, 0.3), 0.0, 1e-12);
  EXPECT_GT(coverage_cost(2.0, 0.0, 0.3), 0.0);
  EXPECT_LT(coverage_cost(2.0, 1.0, 0.3), 0.0);
  EXPECT_NEAR(coverage_cost(1.0, 1.0, 0.3), 1.0 / (1.0 + std::exp(0.7)) - 0.5, 1e-12);
  // Proportional to the area: 4 m² fully covered at tau 0.3 is a reward of 0.6728 m².
  EXPECT_NEAR(coverage_cost(4.0, 1.0, 0.3), -0.672751, 1e-6);
  EXPECT_NEAR(coverage_cost(4.0, 0.0, 0.3), 4.0 * (1.0 / (1.0 + std::exp(-0.3)) - 0.5), 1e-12);
}

TEST(Objective, ConfidenceIsTheScannedShareOrTheModelsPrior) {
  // A face of the start nothing contradicts: the prior, 1, whatever the scan covers.
  EXPECT_DOUBLE_EQ(face_confidence(0.4, 0.0, true), 1.0);
  // A parallel facade before 30 % of it: the prior drops to 0.7, still above the scanned 0.4.
  EXPECT_DOUBLE_EQ(face_confidence(0.4, 0.3, true), 0.7);
  // Before 80 % of it: the scanned share, 0.4, is the larger.
  EXPECT_DOUBLE_EQ(face_confidence(0.4, 0.8, true), 0.4);
  // Not in the start: the scanned share alone, whatever `contradicted` says.
  EXPECT_DOUBLE_EQ(face_confidence(0.4, 0.0, false), 0.4);
  EXPECT_DOUBLE_EQ(face_confidence(0.0, 0.0, false), 0.0);
}

TEST(Objective, FitWeightFallsQuadraticallyToZeroAtTheTolerance) {
  EXPECT_DOUBLE_EQ(fit_weight(0.0, 0.08), 1.0);
  EXPECT_DOUBLE_EQ(fit_weight(0.04, 0.08), 0.75);
  EXPECT_DOUBLE_EQ(fit_weight(-0.04, 0.08), 0.75);  // either side of the plane
  EXPECT_DOUBLE_EQ(fit_weight(0.08, 0.08), 0.0);
  EXPECT_DOUBLE_EQ(fit_weight(0.2, 0.08), 0.0);  // beyond: nothing, never negative
  // The defaults: ransac_epsilon 0.03 + merge_distance 0.05.
  RefineConfig prm;
  EXPECT_DOUBLE_EQ(fit_tolerance(prm), 0.08);
  prm.plane.ransac_epsilon = 0.1;
  prm.selection.merge_distance = 0.2;
  EXPECT_NEAR(fit_tolerance(prm), 0.3, 1e-15);
}

TEST(Objective, CandidateCostWeighsCoverageAndSubtractsTheFit) {
  SelectionConfig prm;  // lambda_coverage 1, lambda_data 0.1, tau_cov 0.3
  // 4 m² fully covered (-0.672751) whose points explain 2 m² (0.1 x 2 = 0.2 more reward).
  EXPECT_NEAR(candidate_cost(4.0, 1.0, 2.0, prm), -0.872751, 1e-6);
  prm.lambda_coverage = 2.0;
  prm.lambda_data = 0.5;
  EXPECT_NEAR(candidate_cost(4.0, 1.0, 2.0, prm), 2.0 * -0.672751 - 1.0, 1e-6);
  prm.lambda_data = 0.0;  // no data term: the coverage alone
  EXPECT_DOUBLE_EQ(candidate_cost(4.0, 0.3, 2.0, prm), 2.0 * coverage_cost(4.0, 0.3, 0.3));
}

TEST(Objective, SharpEdgesCostTheirLengthTimesAWidth) {
  SelectionConfig prm;  // lambda_complexity 0.2
  EXPECT_DOUBLE_EQ(sharp_edge_cost(2.0, prm), 0.2 * 2.0 * 0.25);
  prm.lambda_complexity = 0.0;
  EXPECT_DOUBLE_EQ(sharp_edge_cost(2.0, prm), 0.0);
  // PolyFit's uniform cost: lambda_complexity x total area / edges. Three faces of 1, 2 and 3 m²
  // on two fans: 0.2 x 6 / 2.
  prm.lambda_complexity = 0.2;
  const CandidateSet cs = hand_built({0, 1, 2}, {1.0, 2.0, 3.0}, {{0, 1}, {1, 2}});
  EXPECT_NEAR(uniform_sharp_cost(cs, prm), 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(uniform_sharp_cost(hand_built({0}, {5.0}, {}), prm), 0.0);  // no edge: none
}

TEST(Objective, SelectionCostsArePerCandidateAndPerEdge) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  auto confidence = candidate_props::confidence.add(cs.mesh);
  auto fit = candidate_props::fit.add(cs.mesh);
  for (int f = 0; f < cs.size(); ++f) {
    confidence[CandidateFace(f)] = inside_box(centroid_of(cs, f), a, b, c) ? 1.0 : 0.0;
    fit[CandidateFace(f)] = 0.5 * area_of(cs, f);
  }
  SelectionConfig prm;
  SelectionProgram pg;
  pg.cost = {7.0};  // replaced, not appended to
  set_selection_costs(cs, confidence, fit, prm, pg);
  ASSERT_EQ(int(pg.cost.size()), cs.size());
  ASSERT_EQ(pg.sharp_cost.size(), cs.edges.size());
  int rewarded = 0;
  for (int f = 0; f < cs.size(); ++f) {
    const double conf = confidence[CandidateFace(f)];
    EXPECT_DOUBLE_EQ(pg.cost[f], candidate_cost(area_of(cs, f), conf, 0.5 * area_of(cs, f), prm));
    rewarded += pg.cost[f] < 0.0;
    // Per m²: -0.1682 - 0.05 in the box, +0.0744 - 0.05 beyond it.
    const double per_m2 = conf > 0 ? -0.218188 : 0.024443;
    EXPECT_NEAR(pg.cost[f] / area_of(cs, f), per_m2, 1e-5) << f;
  }
  EXPECT_EQ(rewarded, 6);  // the box's six faces (the middle of each plane's 3 x 3 pieces)
  for (std::size_t e = 0; e < cs.edges.size(); ++e) EXPECT_DOUBLE_EQ(pg.sharp_cost[e], 0.05 * cs.length(cs.edges[e]));
}

TEST(Objective, MendCostIsTheChangedArea) {
  EXPECT_DOUBLE_EQ(mend_cost(2.0, false, 1.0), 2.0);    // added: its area
  EXPECT_DOUBLE_EQ(mend_cost(2.0, true, 1.0), -2.0);    // kept: its area as a reward
  EXPECT_DOUBLE_EQ(mend_cost(2.0, true, 10.0), -20.0);  // a rebuild's cover: dropping costs 10x
  const CandidateSet cs = hand_built({0, 1, 2}, {1.0, 2.0, 3.0}, {{0, 1}, {1, 2}});
  SelectionProgram pg;
  set_mend_costs(cs, {1, 0, 1}, 10.0, pg);
  EXPECT_EQ(pg.cost, (std::vector<double>{-10.0, 2.0, -30.0}));
  EXPECT_EQ(pg.sharp_cost, (std::vector<double>{0.0, 0.0}));  // the mend weighs no complexity
}
