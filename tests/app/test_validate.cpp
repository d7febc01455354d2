// `lodrefine validate` (issue 50): every building of a city file checked as a solid, its defects
// under val3dity's codes, exit 0 when all are valid and 1 when not; the report in val3dity's shape.
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_fixtures.h"
#include "support/validity_fixtures.h"

using cli_fixtures::run_cli;
using json = nlohmann::json;
using validity_fixtures::box_city;

namespace {

std::string write_city(const std::string& dir, const std::vector<validity_fixtures::BoxBuilding>& buildings) {
  const std::string path = dir + "/city.json";
  std::ofstream(path) << box_city(buildings);
  return path;
}

}  // namespace

TEST(ValidateCommand, AllValidExitsZero) {
  const std::string dir = cli_fixtures::test_dir("validate");
  const std::string city = write_city(dir, {{"a", {}, {}, 0}, {"b", {}, {}, 20}});
  const cli_fixtures::Cli r = run_cli("validate " + city, dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("\"a\": valid\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"b\": valid\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CityJSON 2.0: 2 building(s) (LoD 2.x): 2 valid, 0 invalid (snap 0.001 m, planarity 0.01 m)"),
            std::string::npos)
      << r.out;
}

TEST(ValidateCommand, InvalidBuildingsExitOneWithTheirCodes) {
  const std::string dir = cli_fixtures::test_dir("validate");
  const std::string city = write_city(
      dir,
      {{"valid", {}, {}, 0}, {"open", {1}, {}, 20}, {"flipped", {}, {3}, 40}, {"inward", {}, {0, 1, 2, 3, 4, 5}, 60}});
  const cli_fixtures::Cli r = run_cli("validate " + city, dir);
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_NE(r.out.find("\"open\": 302 SHELL_NOT_CLOSED (4 boundary edges (mesh not closed))\n"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\"flipped\": 307 POLYGON_WRONG_ORIENTATION (4 inconsistently oriented edges)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\"inward\": 405 WRONG_ORIENTATION_SHELL"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4 building(s) (LoD 2.x): 1 valid, 3 invalid; buildings per code: 302 x1, 307 x1, 405 x1"),
            std::string::npos)
      << r.out;
}

// The report as val3dity writes one: features with id, type, validity and errors (code,
// description, id, info), the overviews, all_errors and the file's validity.
TEST(ValidateCommand, JsonReportHasValdititysShape) {
  const std::string dir = cli_fixtures::test_dir("validate");
  const std::string city = write_city(dir, {{"valid", {}, {}, 0}, {"open", {1}, {}, 20}, {"flipped", {}, {3}, 40}});
  const cli_fixtures::Cli r = run_cli("validate " + city + " --json " + dir + "/report.json", dir);
  ASSERT_EQ(r.exit, 1) << r.err;
  const json rep = json::parse(cli_fixtures::slurp(dir + "/report.json"));
  EXPECT_EQ(rep["type"], "val3dity_report");
  EXPECT_EQ(rep["validity"], false);
  EXPECT_EQ(rep["all_errors"], json({302, 307}));
  EXPECT_EQ(rep["parameters"]["snap_tol"], 0.001);
  EXPECT_EQ(rep["parameters"]["planarity_d2p_tol"], 0.01);
  EXPECT_EQ(rep["features_overview"], json::parse(R"([{"type": "Building", "total": 3, "valid": 1}])"));
  EXPECT_EQ(rep["primitives_overview"], json::parse(R"([{"type": "Solid", "total": 3, "valid": 1}])"));
  ASSERT_EQ(rep["features"].size(), 3u);
  std::set<std::string> ids;
  for (const json& f : rep["features"]) {
    ids.insert(f["id"].get<std::string>());
    EXPECT_EQ(f["type"], "Building");
    EXPECT_EQ(f["lod"], "2.2");
    EXPECT_TRUE(f["validity"].is_boolean());
    EXPECT_EQ(f["validity"], f["errors"].empty()) << f.dump();
    for (const json& e : f["errors"]) {
      EXPECT_TRUE(e["code"].is_number_integer());
      EXPECT_TRUE(e["description"].is_string());
      EXPECT_TRUE(e["id"].is_string());
      EXPECT_TRUE(e["info"].is_string());
    }
  }
  EXPECT_EQ(ids, std::set<std::string>({"valid", "open", "flipped"}));
  const json& open = rep["features"][1];
  ASSERT_EQ(open["errors"].size(), 1u);
  EXPECT_EQ(open["errors"][0]["code"], 302);
  EXPECT_EQ(open["errors"][0]["description"], "SHELL_NOT_CLOSED");
}

// The tolerances are val3dity's names and defaults: a corner 3 mm off splits at --snap-tol
// 0.001 and welds at 0.01.
TEST(ValidateCommand, SnapToleranceDecidesWhatIsOnePoint) {
  const std::string dir = cli_fixtures::test_dir("validate");
  json city = json::parse(box_city({{"a", {}, {}, 0}}));
  city["vertices"].push_back({3, 0, 0});  // the corner (0, 0, 0) 3 mm east, used by the ground only
  json& ground = city["CityObjects"]["a"]["geometry"][0]["boundaries"][0][0][0];
  for (json& v : ground)
    if (v == 0) v = 8;
  std::ofstream(dir + "/city.json") << city.dump();
  EXPECT_EQ(run_cli("validate " + dir + "/city.json", dir).exit, 1);
  EXPECT_EQ(run_cli("validate " + dir + "/city.json --snap-tol 0.01", dir).exit, 0);
}

// A Solid lodrefine wrote with a fin beside it (a MultiSurface of its LoD after it, in an object
// with lodrefine_outcome): the fin is a surface, not part of the solid. Validated with the solid
// it was 4 open edges and a second component (302, 305), on every building `repair` had written
// with fins (23 of Delfshaven's repaired ones).
TEST(ValidateCommand, FinsBesideASolidAreNotPartOfIt) {
  const std::string dir = cli_fixtures::test_dir("validate");
  json doc = json::parse(box_city({{"fin", {}, {}, 0}}));
  const long long base = (long long)doc["vertices"].size();
  for (const auto& p : std::vector<std::array<int, 3>>{{2, 2, 6}, {2, 6, 6}, {2, 6, 7}, {2, 2, 7}})  // on the roof
    doc["vertices"].push_back({p[0] * 1000, p[1] * 1000, p[2] * 1000});
  doc["CityObjects"]["fin"]["attributes"]["lodrefine_outcome"] = "repaired";
  doc["CityObjects"]["fin"]["geometry"].push_back(
      {{"type", "MultiSurface"}, {"lod", "2.2"}, {"boundaries", {{{base, base + 1, base + 2, base + 3}}}}});
  std::ofstream(dir + "/city.json") << doc.dump();
  const cli_fixtures::Cli r = run_cli("validate " + dir + "/city.json", dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("\"fin\": valid\n"), std::string::npos) << r.out;
}
