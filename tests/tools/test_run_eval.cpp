// `lodrefine eval` as one call: options checked before any work, the files a run writes, and the
// gate's exit code.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "lodrefine/tools/run_eval.h"
#include "support/cli_fixtures.h"
#include "support/run_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// run_eval()'s exit code and what it printed.
struct EvalRun {
  int exit = -1;
  std::string out;
};

EvalRun run(const EvalOptions& options) {
  char* buf = nullptr;
  std::size_t len = 0;
  std::FILE* f = open_memstream(&buf, &len);
  EvalRun r;
  try {
    r.exit = run_eval(options, f);
  } catch (...) {
    std::fclose(f);
    std::free(buf);
    throw;
  }
  std::fclose(f);
  r.out.assign(buf, len);
  std::free(buf);
  return r;
}

// A run of two buildings: "a" refined onto the scan, "b" without a refined model (failed).
fs::path two_building_run() {
  const fs::path dir = cli_fixtures::test_dir("lodrefine_eval_run_eval");
  write_run_building(dir / "run", "a", true, run_report("refined"));
  write_run_building(dir / "run", "b", false, run_report("kept", "nothing to change"));
  return dir;
}

}  // namespace

TEST(RunEval, RunFolderWritesTableJsonCsvAndPlots) {
  const fs::path dir = two_building_run();
  EvalOptions o;
  o.dir = (dir / "run").string();
  o.json_out = (dir / "e.json").string();
  o.csv_out = (dir / "e.csv").string();
  o.svg_dir = (dir / "svg").string();
  o.params_json = {{"seed", 42}};
  o.quiet = true;
  const EvalRun r = run(o);
  EXPECT_EQ(r.exit, 0);
  EXPECT_EQ(r.out.rfind("buildings: 2 (evaluated 1, failed 1), facade points: ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("\noutcomes: refined 1, kept 0, failed 1; facades moved 1 (max 0.400 m"), std::string::npos)
      << r.out;
  const json j = json::parse(cli_fixtures::slurp(o.json_out));
  EXPECT_EQ(j["params"]["seed"], 42);
  EXPECT_EQ(j["run_dir"], o.dir);
  ASSERT_EQ(j["buildings"].size(), 2u);
  EXPECT_EQ(j["buildings"][0]["id"], "b");  // failed first
  EXPECT_LT(j["buildings"][1]["c2m"]["refined"]["rmse"].get<double>(), 0.02);
  EXPECT_EQ(cli_fixtures::slurp(o.csv_out).substr(0, 11), "id,outcome,");
  for (const char* svg : {"c2m_histogram.svg", "c2m_boxplot.svg", "footprint_a.svg"})
    EXPECT_TRUE(fs::exists(dir / "svg" / svg)) << svg;
}

TEST(RunEval, GateBreachGivesExitOneAndALinePerBreach) {
  const fs::path dir = two_building_run();
  std::ofstream(dir / "gates.json") << R"({"max_failed_buildings": 0})";
  EvalOptions o;
  o.dir = (dir / "run").string();
  o.gates = (dir / "gates.json").string();
  o.baseline_out = (dir / "baseline.json").string();
  o.quiet = true;
  const EvalRun r = run(o);
  EXPECT_EQ(r.exit, 1);
  EXPECT_NE(r.out.find("\ngate: 2 building(s), 0 new, 1 pooled check(s): FAILED\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("breach: "), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(o.baseline_out));
}

TEST(RunEval, BadOptionsAreRefusedBeforeAnyWork) {
  const fs::path dir = two_building_run();
  EvalOptions neither;
  EXPECT_THROW(run(neither), InputError);
  EvalOptions classes;
  classes.dir = (dir / "run").string();
  classes.cloud_options.classes = {6};
  classes.json_out = (dir / "e.json").string();
  EXPECT_THROW(run(classes), InputError);
  EvalOptions junit;
  junit.dir = (dir / "run").string();
  junit.junit_out = (dir / "no" / "such" / "j.xml").string();
  junit.json_out = (dir / "e.json").string();
  EXPECT_THROW(run(junit), InputError);
  EXPECT_FALSE(fs::exists(dir / "e.json"));
}

TEST(RunEval, OneBuildingWithoutARefinedModelIsAFailedRow) {
  const fs::path dir = two_building_run();
  EvalOptions o;
  o.original = (dir / "run" / "b" / "coarse.obj").string();
  o.refined = (dir / "run" / "b" / "refined.obj").string();
  o.clouds = {(dir / "run" / "b" / "cloud.ply").string()};
  o.json_out = (dir / "one.json").string();
  const EvalRun r = run(o);
  EXPECT_EQ(r.exit, 0);
  EXPECT_EQ(r.out.rfind("buildings: 1 (evaluated 0, failed 1)", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("outcomes:"), std::string::npos) << "one building has no run totals";
  const json j = json::parse(cli_fixtures::slurp(o.json_out));
  EXPECT_EQ(j["buildings"][0]["status"], "failed");
  EXPECT_EQ(j["buildings"][0]["outcome"], "") << "no refine record: no outcome";
  EXPECT_EQ(j["pooled"]["outcomes"], json({{"", 1}, {"failed", 0}, {"kept", 0}, {"refined", 0}}));
  EXPECT_FALSE(j.contains("run_dir"));
}
