// Bad input to `lodrefine eval` (one building, or a run folder with --dir, against a
// baseline): outputs that are inputs, ids that share a file name, point limits, options that
// are no finite number, baselines and reports with values of the wrong kind (issue 15, the
// attack review of 2026-12-03, issue 36).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "support/bad_input_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

// ---------------------------------------------------------------------------------------------
// Untrusted ids, paths and files (issue 15): outputs stay in the output folder, never replace an
// input or a file already there, temporaries are ours, and every building is accounted for.

// eval's outputs replaced its inputs without a word (--json r.obj --refined r.obj).
TEST(BadInputFiles, EvalRefusesOutputsThatAreInputs) {
  const std::string dir = temp_dir("eval_same");
  const std::string model = dir + "/model.obj", refined = dir + "/refined.obj", cloud = dir + "/cloud.ply";
  write_text(model, valid_model());
  write_text(refined, valid_model());
  write_text(cloud, valid_cloud());
  const std::string in = "eval --original " + model + " --refined " + refined + " --cloud " + cloud;
  for (const auto& [outputs, says] : std::vector<std::pair<std::string, std::string>>{
           {" --json " + refined, "--json is the --refined file"},
           {" --csv " + dir + "/./model.obj", "--csv is the --original file"},
           {" --json " + cloud, "--json is the --cloud file"},
           {" --json " + dir + "/e.json --csv " + dir + "/e.json", "--csv is the --json file"}}) {
    const CliRun r = run_cli(in + outputs, dir);
    expect_one_error_line(r, says);
    EXPECT_EQ(read_text(model), valid_model()) << outputs;
    EXPECT_EQ(read_text(refined), valid_model()) << outputs;
    EXPECT_EQ(read_text(cloud), valid_cloud()) << outputs;
    EXPECT_FALSE(fs::exists(dir + "/e.json")) << outputs;
  }
  add_row("eval: --json/--csv/... = --original/--refined/--cloud or each other", "refused before reading", 2);
}

// eval --svg-dir: one footprint file per building, whatever its id (the old per-character
// mapping gave `a b`, `a_b` and `a:b` one footprint_a_b.svg, written by two threads at once).
TEST(BadInputFiles, EvalFootprintsAreOneFilePerBuilding) {
  const std::string dir = temp_dir("eval_svg");
  for (const char* id : {"a b", "a_b", "a:b"}) {
    fs::create_directories(dir + "/run/" + id);
    write_text(dir + "/run/" + id + "/coarse.obj", valid_model());
    write_text(dir + "/run/" + id + "/refined.obj", valid_model());
    write_text(dir + "/run/" + id + "/cloud.ply", valid_cloud());
  }
  const CliRun r = run_cli("eval --dir " + dir + "/run --svg-dir " + dir + "/svg --jobs 3", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  std::vector<std::string> footprints;
  for (const auto& f : files_in(dir + "/svg"))
    if (f.rfind("footprint_", 0) == 0) footprints.push_back(f);
  EXPECT_EQ(footprints.size(), 3u) << r.out;
  EXPECT_TRUE(temp_leftovers(dir).empty());
  add_row("eval --svg-dir: ids `a b`, `a_b`, `a:b`", "three footprint files", r.exit);
}

// ---------------------------------------------------------------------------------------------
// Found by an attacker's review (2026-12-03): before its fix each input below crashed, hung,
// wrote outside --out, filled the memory, or was written back as garbage.

// A LAZ file of 150 KB announced 1e8 identical points: eval read them all and the city refine
// held them in its crops, until the memory ran out. Both are bounded now (--max-points,
// --max-crop-points), as the OBJ refine was.
TEST(BadInputAttack, PointLimitsBoundEvalAndTheCityRefine) {
  const std::string dir = temp_dir("attack_points");
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/city.json", box_city({"a"}));
  write_text(dir + "/cloud.ply", valid_cloud());
  const std::string m = dir + "/model.obj", c = dir + "/cloud.ply";
  const CliRun e = run_cli("eval --original " + m + " --refined " + m + " --cloud " + c + " --max-points 10", dir);
  expect_one_error_line(e, "more than --max-points 10");
  const std::string b = dir + "/run/a";  // a run folder's clouds too
  fs::create_directories(b);
  for (const char* name : {"/coarse.obj", "/refined.obj"}) write_text(b + name, valid_model());
  write_text(b + "/cloud.ply", valid_cloud());
  const CliRun d = run_cli("eval --quiet --dir " + dir + "/run --max-points 10 --json " + dir + "/eval.json", dir);
  EXPECT_NE(d.out.find("failed 1"), std::string::npos) << d.out << d.err;
  EXPECT_NE(read_text(dir + "/eval.json").find("more than --max-points 10"), std::string::npos);
  const CliRun k =
      run_cli("crop --quiet --tile " + c + " --models " + dir + "/run --out " + dir + "/crops --max-points 10", dir);
  expect_one_error_line(k, "holds more than 10 points (--max-points)");
  EXPECT_FALSE(fs::exists(dir + "/crops"));
  const CliRun r = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + c + " --out " + dir +
                               "/out.city.json --max-crop-points 10",
                           dir);
  expect_one_error_line(r, "hold more than 10 points (--max-crop-points)");
  EXPECT_FALSE(fs::exists(dir + "/out.city.json"));
  add_row("eval / city refine: more points than --max-points / --max-crop-points", "refused in one line", r.exit);
}

// ---------------------------------------------------------------------------------------------
// Third pass (issue 36): gates that waved regressions through, outputs over a run's files, a CR
// in an outcome line.

namespace {

// A run folder of one building (the box, refined as itself) with its baseline written.
std::string run_with_baseline(const std::string& dir) {
  fs::create_directories(dir + "/run/a");
  for (const char* name : {"/coarse.obj", "/refined.obj"}) write_text(dir + "/run/a" + name, valid_model());
  write_text(dir + "/run/a/cloud.ply", valid_cloud());
  const CliRun w = run_cli("eval --quiet --dir " + dir + "/run --write-baseline " + dir + "/b.json", dir);
  EXPECT_EQ(w.exit, 0) << w.err;
  return dir + "/b.json";
}

}  // namespace

// CLI::Range lets NaN through (no comparison with it is true): `--tolerance nan` passed every
// regression. Every floating option of every command must be finite.
TEST(BadInputAttack, FloatingOptionsMustBeFinite) {
  const std::string dir = temp_dir("attack_nan");
  const std::string baseline = run_with_baseline(dir);
  for (const std::string value : {"nan", "NaN", "inf", "-inf", "1e400"}) {
    const CliRun r =
        run_cli("eval --quiet --dir " + dir + "/run --baseline " + baseline + " --tolerance " + value, dir);
    expect_one_error_line(r, "--tolerance");
    if (value.find_first_of("nN") == 0) {
      EXPECT_NE(r.err.find("must be a finite number"), std::string::npos) << r.err;
    }
  }
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun p = run_cli("refine --model " + dir + "/model.obj --cloud " + dir + "/cloud.ply --out " + dir +
                               "/out.obj --ransac-epsilon nan",
                           dir);
  expect_one_error_line(p, "--ransac-epsilon: must be a finite number, not nan");
  EXPECT_FALSE(fs::exists(dir + "/out.obj"));
  add_row("--tolerance nan, --ransac-epsilon nan (any floating option)", "refused in one line", p.exit);
}

// A baseline's counts are non-negative integers: -1 was read as 2^64 - 1, so a newly failed
// building passed. A value of the wrong kind is named in our words, not the JSON library's.
TEST(BadInputAttack, BaselineValuesOfTheWrongKindAreNamed) {
  const std::string dir = temp_dir("attack_baseline");
  const std::string baseline = run_with_baseline(dir);
  const json good = json::parse(read_text(baseline));
  const std::vector<std::tuple<std::string, json, std::string>> lies = {
      {"failed", -1, "\"failed\" must be a non-negative integer, not -1"},
      {"refined", -3, "\"refined\" must be a non-negative integer, not -3"},
      {"failed", "none", "\"failed\" must be a non-negative integer, not \"none\""},
      {"failed", 1.5, "\"failed\" must be a non-negative integer"},
      {"watertight_rate", json::array({1}), "\"watertight_rate\" must be a finite number, not [1]"},
      {"watertight_rate", 7, "\"watertight_rate\" must be a share from 0 to 1"},
      {"c2m_rmse", "x", "\"c2m_rmse\" must be a finite number"}};
  for (const auto& [key, value, says] : lies) {
    json b = good;
    b["pooled"][key] = value;
    write_text(dir + "/bad.json", b.dump());
    const CliRun r = run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir);
    expect_one_error_line(r, says);
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
  }
  json b = good;
  b["buildings"][0]["facades_moved"] = -2;
  write_text(dir + "/bad.json", b.dump());
  expect_one_error_line(run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir),
                        "building \"a\": \"facades_moved\" must be a non-negative integer");
  add_row("baseline with \"failed\": -1, \"none\", [1] ...", "refused, naming the key", 2);
}

// No output of `eval --dir` may be a file the run reads: `--json RUN/<id>/coarse.obj` replaced
// that building's model.
TEST(BadInputAttack, EvalOutputsNeverReplaceTheRunsFiles) {
  const std::string dir = temp_dir("attack_eval_run");
  run_with_baseline(dir);
  write_text(dir + "/run/a/report.json", "{}");
  for (const std::string option : {"--json", "--csv", "--html", "--junit", "--write-baseline"})
    for (const char* file : {"coarse.obj", "cloud.ply", "refined.obj", "report.json"}) {
      const std::string target = dir + "/run/a/" + file;
      const std::string before = read_text(target);
      const CliRun r = run_cli("eval --quiet --dir " + dir + "/run " + option + " " + target, dir);
      expect_one_error_line(r, option + " is the run's file; it would be overwritten");
      EXPECT_EQ(read_text(target), before) << option << " " << file;
    }
  add_row("eval --dir RUN --json RUN/<id>/coarse.obj (any output)", "refused before reading", 2);
}

// A baseline building's outcome and watertightness of the wrong kind were read as "failed" and
// false, so its regressions were never flagged: refused, naming the key.
TEST(BadInputAttack, BaselineBuildingValuesOfTheWrongKindAreNamed) {
  const std::string dir = temp_dir("attack_baseline_building");
  const std::string baseline = run_with_baseline(dir);
  const json good = json::parse(read_text(baseline));
  for (const auto& [key, value, says] : std::vector<std::tuple<std::string, json, std::string>>{
           {"outcome", json::array({"refined"}), "building \"a\": \"outcome\" must be a string, not [\"refined\"]"},
           {"watertight", 1, "building \"a\": \"watertight\" must be true or false, not 1"},
           {"reason", 7, "building \"a\": \"reason\" must be a string, not 7"}}) {
    json b = good;
    b["buildings"][0][key] = value;
    write_text(dir + "/bad.json", b.dump());
    expect_one_error_line(run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir), says);
  }
  add_row("baseline building with \"outcome\": [\"refined\"], \"watertight\": 1", "refused, naming the key", 2);
}

// A run folder's report.json is the refine's, or anyone's: a reason of the wrong kind is a row's
// reason in our words (the JSON library's text reached the gate lines, the CSV and the JSON); an
// unknown report_version names it in at most 40 characters (3,000 made a 3,095-byte error line).
TEST(BadInputAttack, RunReportsOfTheWrongKindStayOurWords) {
  const std::string dir = temp_dir("attack_run_report");
  run_with_baseline(dir);
  write_text(dir + "/run/a/report.json", R"({"outcome":"kept","reason":5})");
  const CliRun r = run_cli("eval --quiet --dir " + dir + "/run --csv " + dir + "/t.csv", dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(read_text(dir + "/t.csv").find("report.json: \"\"reason\"\" is no text"), std::string::npos)
      << read_text(dir + "/t.csv");
  write_text(dir + "/run/a/report.json", R"({"outcome":"kept","seconds":5})");
  EXPECT_EQ(run_cli("eval --quiet --dir " + dir + "/run --csv " + dir + "/t.csv", dir).exit, 0);
  EXPECT_NE(read_text(dir + "/t.csv").find("unreadable report.json (a value of the wrong kind)"), std::string::npos)
      << read_text(dir + "/t.csv");
  EXPECT_EQ(read_text(dir + "/t.csv").find("json.exception"), std::string::npos);
  write_text(dir + "/run/a/report.json", "{\"report_version\":\"" + std::string(3000, '9') + "\"}");
  const CliRun v = run_cli("eval --quiet --dir " + dir + "/run", dir);
  expect_one_error_line(v, "is not one this lodrefine reads");
  EXPECT_LT(v.err.size(), 400u) << v.err.size();
  add_row("run folder report.json with \"reason\": 5 / a 3,000-character report_version", "our words, one short line",
          v.exit);
}

// Fourth pass (issue 47).

// Issue 47: eval measured a building on the tiles of a folder but for those it could not read.
TEST(BadInputAttack, EvalRefusesACloudFolderWithATileItCannotRead) {
  const std::string dir = temp_dir("attack_tiles_eval");
  write_text(dir + "/model.obj", valid_model());
  const CliRun r = expect_bad_tiles_refused(
      "eval --original " + dir + "/model.obj --refined " + dir + "/model.obj --json " + dir + "/e.json --cloud ", dir,
      {dir + "/e.json"});
  EXPECT_NE(r.out.find("C2M"), std::string::npos) << r.out;  // Table 1 after the line
  add_row("eval --cloud tiles/ with a 0-byte, dangling, folder or truncated c.laz", "refused naming it", 2);
}
