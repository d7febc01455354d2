// A run folder evaluated building by building: what eval reads of a refine report (current keys
// only, report_version checked), discovery, and the buildings evaluated on a pool.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "lodrefine/city/refine_report.h"
#include "lodrefine/tools/run.h"
#include "support/cli_fixtures.h"
#include "support/run_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// The refine record of an evaluated (ok) building from `report`.
RunRow record_of(const json& report, const std::string& failed_line = "") {
  RunRow row;
  row.eval.id = "b";
  add_refine_record(row, report, failed_line, "run/b/report.json");
  return row;
}

}  // namespace

TEST(RunRecord, RefinedReportGivesItsFacadesTimeAndSelection) {
  json report = run_report("refined");
  report["facades"].push_back({{"input_faces", {3, 4}}, {"evidence", "corner"}, {"max_move", 0.25}});
  const RunRow r = record_of(report);
  EXPECT_EQ(r.outcome, Outcome::Refined);
  EXPECT_EQ(r.refine_outcome, "refined");
  EXPECT_EQ(r.reason, "");
  EXPECT_EQ(r.selection, "optimal");
  EXPECT_DOUBLE_EQ(r.refine_seconds, 1.25);
  ASSERT_EQ(r.moved.size(), 2u);
  EXPECT_EQ(r.moved[0].surface, json({2}));
  EXPECT_DOUBLE_EQ(r.moved[0].displacement, kRunWallOffset);  // |max_move|
  EXPECT_EQ(r.moved[1].surface, json({3, 4}));
  EXPECT_DOUBLE_EQ(r.moved[1].displacement, 0.25);
}

TEST(RunRecord, KeptBuildingMovedNothingAndKeepsItsReason) {
  json report = run_report("kept", "judge refused (gain): 12 points closer");
  report["facades"].push_back({{"input_faces", {1}}, {"max_move", 0.9}});
  const RunRow r = record_of(report);
  EXPECT_EQ(r.outcome, Outcome::Kept);
  EXPECT_EQ(r.reason, "judge refused (gain): 12 points closer");
  EXPECT_TRUE(r.moved.empty());
  // Every outcome is reported as refine decided it, not folded into "kept".
  const RunRow invalid = record_of(run_report("kept-invalid", "not closed"));
  EXPECT_EQ(invalid.outcome, Outcome::KeptInvalid);
  EXPECT_EQ(invalid.refine_outcome, "kept-invalid");
  EXPECT_EQ(record_of(run_report("repaired", "shell rebuilt on its planes")).outcome, Outcome::Repaired);
  EXPECT_EQ(record_of(run_report("no outcome of ours")).outcome, Outcome::Kept);  // a model is there
}

// The spellings of reports before the "facades" list settled are read no more: a facade without
// max_move, a replacement's moved_by and an outcome with its reason in brackets count for nothing.
TEST(RunRecord, RetiredSpellingsCountForNothing) {
  json report = run_report("refined");
  report["facades"] = {{{"surface", "wall-7"}, {"displacement", 0.5}}, {{"input_faces", {1}}, {"moved_by", 0.3}}};
  EXPECT_TRUE(record_of(report).moved.empty());

  report.erase("facades");
  report["matches"] = {{{"scan_plane", 0}, {"surface", "wall-7"}}};
  report["replacements"] = {{{"scan_plane", 0}, {"ok", true}, {"moved_by", 0.5}}};
  EXPECT_TRUE(record_of(report).moved.empty());

  const RunRow bracketed = record_of(run_report("refined (2 walls moved)"));
  EXPECT_EQ(bracketed.outcome, Outcome::Kept);
  EXPECT_EQ(bracketed.reason, "");
  EXPECT_TRUE(bracketed.moved.empty());
}

TEST(RunRecord, ReportWithoutVersionIsReadAsVersionOne) {
  json report = run_report("refined");
  report.erase("report_version");
  const RunRow r = record_of(report);
  EXPECT_EQ(r.outcome, Outcome::Refined);
  ASSERT_EQ(r.moved.size(), 1u);
  EXPECT_DOUBLE_EQ(r.moved[0].displacement, kRunWallOffset);
}

TEST(RunRecord, ReportOfAnotherVersionIsRefusedInOneLine) {
  for (const json& version : {json(kRefineReportVersion + 1), json(0), json("1"), json(1.5)}) {
    json report = run_report("refined");
    report["report_version"] = version;
    try {
      record_of(report);
      ADD_FAILURE() << "report_version " << version.dump() << " was read";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("run/b/report.json: report_version " + version.dump()), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

TEST(RunRecord, FailedFileMissingReportAndWrongTypes) {
  const RunRow failed = record_of(run_report("refined"), "lodrefine: error: cloud.ply: truncated");
  EXPECT_EQ(failed.outcome, Outcome::Failed);
  EXPECT_EQ(failed.reason, "lodrefine: error: cloud.ply: truncated");
  EXPECT_TRUE(failed.moved.empty());
  EXPECT_EQ(failed.selection, "optimal");  // what the report says is still shown

  const RunRow none = record_of(nullptr);
  EXPECT_EQ(none.outcome, Outcome::Kept);
  EXPECT_EQ(none.reason, "no report.json");

  json report = run_report("kept");
  report["reason"] = 42;
  const RunRow odd = record_of(report);
  EXPECT_EQ(odd.outcome, Outcome::Kept);
  EXPECT_EQ(odd.reason, "report.json: \"reason\" is no text");
  report["reason"] = "kept";
  report["seconds"] = 5;  // not an object: the report is unreadable, in our words
  EXPECT_EQ(record_of(report).reason, "unreadable report.json (a value of the wrong kind)");
}

TEST(RunDiscover, BuildingFoldersSortedWithTheirOptionalFiles) {
  const fs::path run = cli_fixtures::test_dir("lodrefine_eval_run");
  write_run_building(run, "b2", true, run_report("refined"));
  write_run_building(run, "a1", false, nullptr);
  fs::create_directories(run / "not-a-building");
  std::ofstream(run / "a1" / "FAILED") << "boom\n";
  const auto found = discover_run(run.string());
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].id, "a1");
  EXPECT_EQ(found[0].failed, (run / "a1" / "FAILED").string());
  EXPECT_EQ(found[0].report, "");
  EXPECT_EQ(found[0].refined, (run / "a1" / "refined.obj").string());  // named even when absent
  EXPECT_EQ(found[1].id, "b2");
  EXPECT_EQ(found[1].report, (run / "b2" / "report.json").string());
  EXPECT_EQ(found[1].truth, "");
  EXPECT_THROW(discover_run((run / "not-a-building").string()), InputError);
  EXPECT_THROW(discover_run((run / "no-such-dir").string()), InputError);
}

// Three buildings: refined (the front wall on the scan), refined model missing, unreadable
// cloud. Rows in id order whatever the pool's order; one failure does not stop the run.
TEST(RunEvaluate, RowsInIdOrderWithFiguresAndFailures) {
  const fs::path run = cli_fixtures::test_dir("lodrefine_eval_run");
  write_run_building(run, "a", true, run_report("refined"));
  write_run_building(run, "b", false, run_report("kept", "nothing to change"));
  write_run_building(run, "c", true, run_report("refined"));
  std::ofstream(run / "c" / "cloud.ply") << "ply\nformat nonsense\n";
  for (int jobs : {1, 3}) {
    PooledSeries series;
    const auto rows = evaluate_run(run.string(), RefineConfig{}, "", jobs, series, Progress::Mode::Off);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0].eval.id, "a");
    EXPECT_EQ(rows[1].eval.id, "b");
    EXPECT_EQ(rows[2].eval.id, "c");
    const BuildingEval& a = rows[0].eval;
    ASSERT_TRUE(a.ok()) << a.error;
    EXPECT_GT(a.facade_points, 5000u);
    EXPECT_NEAR(a.before.rmse, kRunWallOffset, 0.02);
    EXPECT_LT(a.after.rmse, 0.02);
    EXPECT_TRUE(a.watertight_after);
    EXPECT_TRUE(a.c2m_after.empty()) << "the series go into the bins and are dropped";
    EXPECT_EQ(series.c2m_after.count(), a.facade_points);
    EXPECT_NEAR((rows[0].origin - kRunOrigin).norm(), 0.0, 1e-9);
    EXPECT_EQ(rows[0].outcome, Outcome::Refined);
    ASSERT_EQ(rows[0].moved.size(), 1u);
    EXPECT_EQ(rows[1].outcome, Outcome::Failed);
    EXPECT_NE(rows[1].reason.find("refined model missing"), std::string::npos) << rows[1].reason;
    EXPECT_EQ(rows[2].outcome, Outcome::Failed);
    EXPECT_NE(rows[2].reason.find("cloud.ply"), std::string::npos) << rows[2].reason;
  }
}

TEST(RunEvaluate, ANewerReportStopsTheRun) {
  const fs::path run = cli_fixtures::test_dir("lodrefine_eval_run");
  write_run_building(run, "a", true, run_report("refined"));
  json newer = run_report("refined");
  newer["report_version"] = kRefineReportVersion + 1;
  write_run_building(run, "b", true, newer);
  PooledSeries series;
  EXPECT_THROW(evaluate_run(run.string(), RefineConfig{}, "", 2, series, Progress::Mode::Off), InputError);
}

// The buildings' series go into the pooled bins in the run's order whatever --jobs (issue 47
// moved them onto the pool that bounds those waiting): sums pooled in another order differ in
// their last bits, so each pooled figure is compared bit for bit.
TEST(RunEvaluate, PooledSeriesAreTheSameBitsForAnyJobs) {
  const fs::path run = cli_fixtures::test_dir("lodrefine_eval_run_jobs");
  for (int k = 0; k < 8; ++k) {
    const std::string id = "b" + std::to_string(k);
    write_run_building(run, id, true, run_report("refined"));
    PointCloud cloud = read_ply((run / id / "cloud.ply").string());  // each building its own distances
    for (Vec3& p : cloud.points) p.y() += 0.0137 * k + 1e-4 * double((&p - cloud.points.data()) % 7);
    write_ply((run / id / "cloud.ply").string(), cloud);
  }
  std::vector<DistanceStats> pooled[2];
  for (int jobs : {1, 2}) {
    PooledSeries series;
    evaluate_run(run.string(), RefineConfig{}, "", jobs, series, Progress::Mode::Off);
    for (const DistanceHistogram* h : {&series.c2m_before, &series.c2m_after}) pooled[jobs - 1].push_back(h->stats());
  }
  ASSERT_EQ(pooled[0].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const DistanceStats &a = pooled[0][i], &b = pooled[1][i];
    EXPECT_GT(a.count, 8000u);
    EXPECT_EQ(a.count, b.count);
    for (auto field : {&DistanceStats::rmse, &DistanceStats::mae, &DistanceStats::mean, &DistanceStats::std,
                       &DistanceStats::median, &DistanceStats::p95, &DistanceStats::max_abs})
      EXPECT_EQ(std::memcmp(&(a.*field), &(b.*field), sizeof(double)), 0) << i << ": " << a.*field << " " << b.*field;
  }
}

// A repaired building's refined.obj holds its fins after the solid (the fins group): eval judges
// the solid, watertight with its volume centroid. Before, the fin's face made the building not
// watertight and its centroid an area centroid pulled up the fin.
TEST(RunEvaluate, TheFinsGroupIsNoPartOfTheSolidEvalJudges) {
  const fs::path run = cli_fixtures::test_dir("lodrefine_eval_fins");
  write_run_building(run, "a", true, run_report("repaired", "shell rebuilt on its planes"));
  const Mesh solid = translated(box(Vec3(0, -kRunWallOffset, 0), Vec3(12, 8, 6)), kRunOrigin);
  Mesh fin;
  for (const Vec3& p : {Vec3(0, 8, 6), Vec3(12, 8, 6), Vec3(12, 8, 16), Vec3(0, 8, 16)})
    fin.vertices.push_back(p + kRunOrigin);
  fin.faces.push_back({{0, 1, 2, 3}, Semantic::Wall, 6});
  write_obj((run / "a" / "refined.obj").string(), solid, fin);
  PooledSeries series;
  const auto rows = evaluate_run(run.string(), RefineConfig{}, "", 1, series, Progress::Mode::Off);
  ASSERT_EQ(rows.size(), 1u);
  const BuildingEval& a = rows[0].eval;
  ASSERT_TRUE(a.ok()) << a.error;
  EXPECT_TRUE(a.watertight_after);
  EXPECT_NEAR(a.c_ref.z() + rows[0].origin.z(), 3.0, 1e-6);  // the box's volume centroid
  EXPECT_NEAR(a.after.rmse, 0.0, 0.02);
  // A refined model whose every face is a fin has no solid to judge: a failure row that says so.
  std::ofstream(run / "a" / "refined.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\ng fins\nf 1 2 3\n";
  const auto again = evaluate_run(run.string(), RefineConfig{}, "", 1, series, Progress::Mode::Off);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_NE(again[0].eval.error.find("every face is in the fins group"), std::string::npos) << again[0].eval.error;
}
