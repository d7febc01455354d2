// Issue 50, item 5: `lodrefine --version`, refine's report and eval's JSON say one version, the
// one CMake declares (project(VERSION) -> lodrefine/version.h).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/version.h"
#include "support/cli_fixtures.h"
#include "support/test_paths.h"

using cli_fixtures::run_cli;
using json = nlohmann::json;

TEST(Version, ProgramAndReportsSayCMakesVersion) {
  const std::string dir = cli_fixtures::test_dir("version");
  const cli_fixtures::Cli v = run_cli("--version", dir);
  ASSERT_EQ(v.exit, 0) << v.err;
  EXPECT_EQ(v.out, "lodrefine " LODREFINE_VERSION "\n");
  const std::string sample = test_paths::source_dir() + "/data/samples/synth_gable_0001/";
  const cli_fixtures::Cli r = run_cli("refine --model " + sample + "coarse.obj --cloud " + sample + "cloud.ply --out " +
                                          dir + "/refined.obj --report " + dir + "/report.json",
                                      dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  const json report = json::parse(cli_fixtures::slurp(dir + "/report.json"));
  EXPECT_EQ(report["lodrefine_version"], LODREFINE_VERSION);
  EXPECT_TRUE(report["output_validation"]["errors"].is_array());
  const cli_fixtures::Cli e = run_cli("eval --original " + sample + "coarse.obj --refined " + dir +
                                          "/refined.obj --cloud " + sample + "cloud.ply --json " + dir + "/eval.json",
                                      dir);
  ASSERT_EQ(e.exit, 0) << e.err;
  EXPECT_EQ(json::parse(cli_fixtures::slurp(dir + "/eval.json"))["lodrefine_version"], LODREFINE_VERSION);
}

// The version CMake declares is the CHANGELOG's newest released section.
TEST(Version, ChangelogHasASectionOfTheVersion) {
  const std::string log = cli_fixtures::slurp(test_paths::source_dir() + "/CHANGELOG.md");
  EXPECT_NE(log.find("\n## " LODREFINE_VERSION " ("), std::string::npos);
  EXPECT_LT(log.find("\n## Unreleased\n"), log.find("\n## " LODREFINE_VERSION " ("));
}
