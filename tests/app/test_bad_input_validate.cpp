// Bad input to `lodrefine validate` and `lodrefine repair` (issue 50): one line
// `lodrefine: error: ...`, exit 2, nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "support/cli_fixtures.h"
#include "support/validity_fixtures.h"

using cli_fixtures::run_cli;

namespace {

void expect_one_error_line(const cli_fixtures::Cli& r, const std::string& says) {
  EXPECT_EQ(r.exit, 2) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
}

}  // namespace

TEST(BadInputValidate, NoCityFileExitsTwo) {
  const std::string dir = cli_fixtures::test_dir("bad_validate");
  std::ofstream(dir + "/cloud.ply") << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                       "property float z\nend_header\n0 0 0\n";
  expect_one_error_line(run_cli("validate " + dir + "/cloud.ply", dir), "cloud.ply");
  std::ofstream(dir + "/broken.json") << "{\"type\": \"CityJSON\", ";
  expect_one_error_line(run_cli("validate " + dir + "/broken.json --json " + dir + "/r.json", dir), "broken.json");
  EXPECT_FALSE(std::filesystem::exists(dir + "/r.json"));
  expect_one_error_line(run_cli("validate " + dir + "/missing.json", dir), "missing.json");
}

TEST(BadInputValidate, NoBuildingOfTheLodAskedForExitsTwo) {
  const std::string dir = cli_fixtures::test_dir("bad_validate");
  std::ofstream(dir + "/city.json") << validity_fixtures::box_city({{"a", {}, {}, 0}});
  expect_one_error_line(run_cli("validate " + dir + "/city.json --lod 1.2", dir),
                        "no Building/BuildingPart with an LoD 1.2");
  expect_one_error_line(run_cli("repair " + dir + "/city.json --lod 1.2 --out " + dir + "/out.json", dir),
                        "no Building/BuildingPart with an LoD 1.2");
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.json"));
}

TEST(BadInputValidate, OutputsNeverReplaceTheInput) {
  const std::string dir = cli_fixtures::test_dir("bad_validate");
  const std::string city = validity_fixtures::box_city({{"a", {1}, {}, 0}});
  std::ofstream(dir + "/city.json") << city;
  expect_one_error_line(run_cli("validate " + dir + "/city.json --json " + dir + "/city.json", dir), "--json");
  expect_one_error_line(run_cli("repair " + dir + "/city.json --out " + dir + "/city.json", dir), "--out");
  expect_one_error_line(run_cli("repair " + dir + "/city.json --out " + dir + "/nowhere/out.json", dir),
                        "does not exist");
  EXPECT_EQ(cli_fixtures::slurp(dir + "/city.json"), city);
}
