// Stage 4a: candidate confidence from model and cloud references, and the sigmoid coverage cost.
#include <gtest/gtest.h>

#include <cmath>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/confidence.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(Confidence, SigmoidCostChangesSignAtTau) {
  EXPECT_NEAR(coverage_cost(2.0, 0.3, 0.3), 0.0, 1e-12);
  EXPECT_GT(coverage_cost(2.0, 0.0, 0.3), 0.0);
  EXPECT_LT(coverage_cost(2.0, 1.0, 0.3), 0.0);
  EXPECT_NEAR(coverage_cost(1.0, 1.0, 0.3), 1.0 / (1.0 + std::exp(0.7)) - 0.5, 1e-12);
}

// The six box faces are covered by their own references (confidence 1); the pieces outside
// the box only touch a reference, the other planes' are filtered by angle (confidence 0).
TEST(Confidence, BoxFacesAreFullyCoveredByTheirModelReferences) {
  const double a = 10, b = 8, c = 6;
  const CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  const auto conf = candidate_confidence(cs, box_references(a, b, c), {}, ConfidenceConfig{});
  ASSERT_EQ(conf.size(), std::size_t(cs.size()));
  int full = 0;
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f) {
    if (inside_box(centroid_of(cs, f), a, b, c)) {
      ++full;
      EXPECT_NEAR(conf[f].value, 1.0, 1e-9) << "face " << f;
      EXPECT_EQ(conf[f].model_ref, cs.planes[plane_of(cs, f)].source) << "face " << f;
      EXPECT_EQ(conf[f].cloud_ref, -1);
    } else {
      EXPECT_NEAR(conf[f].value, 0.0, 1e-9) << "face " << f;
      EXPECT_EQ(conf[f].model_ref, -1) << "face " << f;
    }
  }
  EXPECT_EQ(full, 6);
}

// Scan points on half of the 10 × 6 m front (x from 0 to 5) cover half of it, if they lie
// within conf_cloud_distance (0.2 m) of its plane.
TEST(Confidence, CloudReferenceCoversTheShareItsPointsSpan) {
  const double a = 10, b = 8, c = 6;
  const CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  int front = -1;
  for (int f = 0; f < cs.size(); ++f)
    if (cs.planes[plane_of(cs, f)].source == 2 && inside_box(centroid_of(cs, f), a, b, c)) front = f;
  ASSERT_GE(front, 0);
  auto half_front = [](double y) {
    CloudReference ref;
    for (int i = 0; i <= 50; ++i)
      for (int j = 0; j <= 60; ++j) ref.points.emplace_back(0.1 * i, y, 0.1 * j);
    return ref;
  };
  for (double y : {0.0, -0.1}) {
    const auto conf = candidate_confidence(cs, {}, {half_front(y)}, ConfidenceConfig{});
    for (int f = 0; f < cs.size(); ++f) {
      if (f == front) continue;
      EXPECT_NEAR(conf[f].value, 0.0, 1e-9) << "face " << f;
    }
    EXPECT_NEAR(conf[front].value, 0.5, 1e-9) << "points at y = " << y;
    EXPECT_EQ(conf[front].cloud_ref, 0);
    EXPECT_EQ(conf[front].model_ref, -1);
  }
  const auto far = candidate_confidence(cs, {}, {half_front(-0.3)}, ConfidenceConfig{});
  EXPECT_EQ(far[front].value, 0.0);
  EXPECT_EQ(far[front].cloud_ref, -1);
}
