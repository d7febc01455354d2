// A city file validated building by building under val3dity's codes (src/city/validity.cpp):
// each building's errors in file order, the count of invalid ones, a LoD no building has refused,
// the errors on one line, and the report in val3dity's shape (the command:
// tests/app/test_validate.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lodrefine/city/validity.h"
#include "support/cli_fixtures.h"
#include "support/validity_fixtures.h"

using namespace lodrefine;
using json = nlohmann::json;

namespace {

// The boxes' city file in a fresh folder.
std::string city_of(const std::vector<validity_fixtures::BoxBuilding>& buildings) {
  const std::string path = cli_fixtures::test_dir("validity") + "/city.json";
  std::ofstream(path) << validity_fixtures::box_city(buildings);
  return path;
}

std::vector<int> codes(const BuildingValidity& b) { return error_codes(b.validation.errors); }

}  // namespace

TEST(Validity, EachBuildingGetsItsCodesInFileOrder) {
  // box_city writes the objects in the order of their ids.
  const std::string path = city_of({{"a_valid", {}, {}, 0},
                                    {"b_open", {1}, {}, 20},
                                    {"c_flipped", {}, {3}, 40},
                                    {"d_inward", {}, {0, 1, 2, 3, 4, 5}, 60}});
  const CityValidity v = validate_city(path, "", ValidityTolerances{});
  EXPECT_EQ(v.path, path);
  EXPECT_EQ(v.input_format, "CityJSON 2.0");
  ASSERT_EQ(v.buildings.size(), 4u);
  EXPECT_EQ(v.buildings[0].id, "a_valid");
  EXPECT_EQ(v.buildings[3].id, "d_inward");
  EXPECT_TRUE(v.buildings[0].valid());
  EXPECT_EQ(v.buildings[0].type, "Building");
  EXPECT_EQ(v.buildings[0].lod, "2.2");
  EXPECT_EQ(v.buildings[0].geometry_type, "Solid");
  EXPECT_EQ(codes(v.buildings[1]), std::vector<int>({302}));
  EXPECT_EQ(codes(v.buildings[2]), std::vector<int>({307}));
  EXPECT_EQ(codes(v.buildings[3]), std::vector<int>({405}));
  EXPECT_EQ(v.invalid(), 3);
  EXPECT_TRUE(v.ids_without_lod.empty());
  EXPECT_EQ(errors_text(v.buildings[1].validation.errors), "302 SHELL_NOT_CLOSED (4 boundary edges (mesh not closed))");
  EXPECT_EQ(errors_text({}), "");
}

TEST(Validity, ALodNoBuildingHasIsRefusedInOneLine) {
  const std::string path = city_of({{"a", {}, {}, 0}});
  try {
    validate_city(path, "1.2", ValidityTolerances{});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Validity, ReportCountsFeaturesAndPrimitivesAndIsTheSameEachTime) {
  ValidityTolerances t;
  t.snap = 0.002;
  t.planarity = 0.02;
  const CityValidity v = validate_city(city_of({{"a_valid", {}, {}, 0}, {"b_open", {2}, {}, 20}}), "", t);
  const json rep = validity_report_json(v);
  EXPECT_EQ(rep["type"], "val3dity_report");
  EXPECT_EQ(rep["input_file_type"], "CityJSON 2.0");
  EXPECT_EQ(rep["parameters"]["snap_tol"], 0.002);
  EXPECT_EQ(rep["parameters"]["planarity_d2p_tol"], 0.02);
  EXPECT_EQ(rep["features_overview"], json::parse(R"([{"type": "Building", "total": 2, "valid": 1}])"));
  EXPECT_EQ(rep["primitives_overview"], json::parse(R"([{"type": "Solid", "total": 2, "valid": 1}])"));
  EXPECT_EQ(rep["all_errors"], json({302}));
  EXPECT_EQ(rep["validity"], false);
  EXPECT_EQ(rep["dataset_errors"], json::array());
  ASSERT_EQ(rep["features"].size(), 2u);
  EXPECT_EQ(rep["features"][0]["id"], "a_valid");
  EXPECT_EQ(rep["features"][0]["validity"], true);
  ASSERT_EQ(rep["features"][1]["errors"].size(), 1u);
  EXPECT_EQ(rep["features"][1]["errors"][0]["code"], 302);
  EXPECT_EQ(validity_report_json(v).dump(), rep.dump());  // no time in it
}
