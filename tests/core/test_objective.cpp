// The selection program's costs per candidate face: the paper's sigmoid coverage cost.
#include <gtest/gtest.h>

#include <cmath>

#include "lodrefine/core/objective.h"

using namespace lodrefine;

TEST(Objective, SigmoidCostChangesSignAtTau) {
  EXPECT_NEAR(coverage_cost(2.0, 0.3, 0.3), 0.0, 1e-12);
  EXPECT_GT(coverage_cost(2.0, 0.0, 0.3), 0.0);
  EXPECT_LT(coverage_cost(2.0, 1.0, 0.3), 0.0);
  EXPECT_NEAR(coverage_cost(1.0, 1.0, 0.3), 1.0 / (1.0 + std::exp(0.7)) - 0.5, 1e-12);
}
