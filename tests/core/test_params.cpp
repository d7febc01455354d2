#include <gtest/gtest.h>

#include "lodrefine/core/params.h"
#include "lodrefine/core/types.h"

using namespace lodrefine;

TEST(Params, DefaultsAreValidAndMatchThePaper) {
  Params p;
  EXPECT_NO_THROW(p.validate());
  EXPECT_DOUBLE_EQ(p.tau_cov, 0.3);
  EXPECT_DOUBLE_EQ(p.merge_angle_deg, 5.0);
  EXPECT_DOUBLE_EQ(p.conf_angle_deg, 5.0);
  EXPECT_DOUBLE_EQ(p.conf_cloud_distance, 0.2);
  EXPECT_DOUBLE_EQ(p.conf_bbox_iou, 0.3);
  EXPECT_DOUBLE_EQ(p.bbox_expand, 0.1);
}

TEST(Params, OutOfRangeIsRejectedWithTheName) {
  Params p;
  p.tau_cov = 1.5;
  try {
    p.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tau_cov"), std::string::npos);
  }
}

TEST(Params, TableListsEveryParameter) {
  EXPECT_GE(param_table().size(), 25u);
  for (const auto& p : param_table()) {
    EXPECT_FALSE(p.description.empty()) << p.name;
    EXPECT_LE(p.min, p.default_value) << p.name;
    EXPECT_GE(p.max, p.default_value) << p.name;
  }
}
