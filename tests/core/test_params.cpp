#include <gtest/gtest.h>

#include <set>
#include <string>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"

using namespace lodrefine;

TEST(Params, DefaultsAreValidAndMatchThePaper) {
  RefineConfig p;
  EXPECT_NO_THROW(p.validate());
  EXPECT_DOUBLE_EQ(p.selection.tau_cov, 0.3);
  EXPECT_DOUBLE_EQ(p.selection.merge_angle_deg, 5.0);
  EXPECT_DOUBLE_EQ(p.selection.bbox_expand, 0.1);
}

TEST(Params, OutOfRangeIsRejectedWithTheName) {
  RefineConfig p;
  p.selection.tau_cov = 1.5;
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

TEST(Params, ValidateNamesTheStage) {
  RefineConfig c;
  c.plane.ransac_epsilon = 5.0;
  try {
    c.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("plane: parameter ransac_epsilon = 5 ", 0), 0u) << e.what();
  }
  c = RefineConfig{};
  c.selection.tau_cov = -1.0;
  EXPECT_THROW(c.selection.validate(), InputError);
  EXPECT_NO_THROW(c.plane.validate());  // a stage checks only its own rows
  try {
    c.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("selection: ", 0), 0u) << e.what();
  }
}

TEST(Params, EveryRowBelongsToOneStageInPipelineOrder) {
  const auto& stages = stage_table();
  ASSERT_EQ(stages.size(), 4u);
  EXPECT_EQ(stages.front().name, "repair");
  std::set<std::string> names;
  std::size_t stage = 0;
  for (const auto& p : param_table()) {
    EXPECT_TRUE(names.insert(p.name).second) << p.name << " twice";
    while (stage < stages.size() && stages[stage].name != p.stage) ++stage;  // rows grouped, in stage order
    EXPECT_LT(stage, stages.size()) << p.name << " of stage " << p.stage;
  }
  EXPECT_EQ(param_table().size(), names.size());
}

TEST(Params, ForEachFieldVisitsEveryRowWithItsValue) {
  RefineConfig c;
  c.match.match_distance = 2.5;
  c.plane.seed = 7;
  std::size_t n = 0;
  for_each_field(c, [&](const auto& field, auto& value) {
    EXPECT_EQ(field.name, param_table()[n].name);
    if (std::string(field.name) == "match_distance") {
      EXPECT_DOUBLE_EQ(double(value), 2.5);
      EXPECT_STREQ(field.stage, "match");
      value = 3.0;  // the field is the config's member
    }
    if (std::string(field.name) == "seed") {
      EXPECT_EQ(double(value), 7.0);
    }
    ++n;
  });
  EXPECT_EQ(n, param_table().size());
  EXPECT_DOUBLE_EQ(c.match.match_distance, 3.0);
  std::size_t in_match = 0;
  for_each_field(c.match, [&](const auto& field, auto) { in_match += std::string(field.stage) == "match"; });
  EXPECT_EQ(in_match, 8u);  // a stage config visits its own rows only
}

TEST(Params, EachStageConfigIsTheMemberOfItsName) {
  EXPECT_STREQ(decltype(RefineConfig::repair)::stage, "repair");
  EXPECT_STREQ(decltype(RefineConfig::plane)::stage, "plane");
  EXPECT_STREQ(decltype(RefineConfig::match)::stage, "match");
  EXPECT_STREQ(decltype(RefineConfig::selection)::stage, "selection");
  RefineConfig c;
  c.match.match_distance = 2.0;
  c.selection.bbox_margin = 0.5;
  EXPECT_DOUBLE_EQ(c.scan_reach(), 2.5);
}
