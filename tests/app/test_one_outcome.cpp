// One building's outcome is decided once, by refine (core/outcome.h: decide_outcome): the same
// building refined alone, inside a city file, and evaluated in a run folder is reported with the
// same outcome by all three.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/formats/ply.h"
#include "support/cli_fixtures.h"
#include "support/validity_fixtures.h"

using cli_fixtures::run_cli;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

json load(const std::string& path) { return json::parse(cli_fixtures::slurp(path)); }

// A few scattered returns inside the box of validity_fixtures' first building (10 x 8 x 6 m at
// its translate): they reach the building (its crop is not empty) and hold no plane.
lodrefine::PointCloud scattered_points() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(1.0, 9.0), y(1.0, 7.0), z(1.0, 5.0);
  lodrefine::PointCloud pc;
  for (int i = 0; i < 30; ++i) pc.points.push_back(lodrefine::Vec3(92000.0 + x(rng), 437000.0 + y(rng), z(rng)));
  return pc;
}

}  // namespace

// A house exported as ground, roof and one end wall is rebuilt on its own planes: refine alone
// says repaired; the city refine writes lodrefine_outcome "repaired"; eval of the run folder
// reports "repaired" too (it reported every outcome but refined as "kept").
TEST(OneOutcome, ARepairedHouseIsRepairedAloneInACityAndInTheEvaluation) {
  const std::string dir = cli_fixtures::test_dir("one_outcome");
  std::ofstream(dir + "/city.json") << validity_fixtures::box_city({{"house", {2, 4, 5}, {}, 0}});
  lodrefine::write_ply(dir + "/cloud.ply", scattered_points());

  // The same building as an OBJ, as convert fans it out.
  cli_fixtures::Cli c = run_cli("convert --cityjson " + dir + "/city.json --out-dir " + dir + "/fan", dir);
  ASSERT_EQ(c.exit, 0) << c.err;
  const fs::path run = fs::path(dir) / "run", b = run / "house";
  fs::create_directories(b);
  fs::copy_file(fs::path(dir) / "fan" / "house.obj", b / "coarse.obj");
  fs::copy_file(fs::path(dir) / "cloud.ply", b / "cloud.ply");

  c = run_cli("refine --model " + (b / "coarse.obj").string() + " --cloud " + (b / "cloud.ply").string() + " --out " +
                  (b / "refined.obj").string() + " --report " + (b / "report.json").string(),
              dir);
  ASSERT_EQ(c.exit, 0) << c.err;
  const json alone = load((b / "report.json").string());
  ASSERT_EQ(alone["outcome"], "repaired") << alone["reason"];

  c = run_cli("refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir +
                  "/out.city.json --report " + dir + "/city_report.json --quiet",
              dir);
  ASSERT_EQ(c.exit, 0) << c.err;
  const json city = load(dir + "/out.city.json");
  EXPECT_EQ(city["CityObjects"]["house"]["attributes"]["lodrefine_outcome"], alone["outcome"]);
  EXPECT_EQ(city["CityObjects"]["house"]["attributes"]["lodrefine_reason"], alone["reason"]);

  c = run_cli("eval --dir " + run.string() + " --json " + dir + "/eval.json --quiet --jobs 1", dir);
  ASSERT_EQ(c.exit, 0) << c.err;
  const json eval = load(dir + "/eval.json");
  ASSERT_EQ(eval["buildings"].size(), 1u);
  EXPECT_EQ(eval["buildings"][0]["outcome"], alone["outcome"]);
  EXPECT_NE(c.out.find("outcomes: refined 0, kept 0, failed 0, repaired 1;"), std::string::npos) << c.out;
}
