// What eval writes of evaluated buildings: moved-facade figures, worst-first order, Table 1 and
// the totals line, the JSON and CSV tile table, the HTML rows and the gate's figures.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "lodrefine/tools/run_table.h"

using namespace lodrefine;
using nlohmann::json;

namespace {

// An evaluated building: C2M RMSE before / after on `points` facade points, watertight or not.
RunRow row(const std::string& id, double rmse_before, double rmse_after, bool watertight, std::size_t points = 100) {
  RunRow r;
  r.eval.id = id;
  r.eval.facade_points = points;
  r.eval.before.count = r.eval.after.count = points;
  r.eval.before.rmse = rmse_before;
  r.eval.after.rmse = rmse_after;
  r.eval.watertight_before = true;
  r.eval.watertight_after = watertight;
  r.eval.delta_d = 0.25;
  r.outcome = Outcome::Refined;
  r.refine_outcome = "refined";
  return r;
}

RunRow failed_row(const std::string& id) {
  RunRow r = failure_row(id, "refined model missing");
  r.outcome = Outcome::Failed;
  r.reason = r.eval.error;
  return r;
}

std::vector<std::string> ids(const std::vector<const RunRow*>& order) {
  std::vector<std::string> out;
  for (const RunRow* r : order) out.push_back(r->eval.id);
  return out;
}

}  // namespace

TEST(RunTable, MovedSummaryCountMaxMean) {
  const MovedSummary none = summarize_moved({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_TRUE(std::isnan(none.max));
  EXPECT_TRUE(std::isnan(none.mean));
  const MovedSummary m = summarize_moved({{json({1}), 0.5}, {json({2}), 0.25}});
  EXPECT_EQ(m.count, 2u);
  EXPECT_DOUBLE_EQ(m.max, 0.5);
  EXPECT_DOUBLE_EQ(m.mean, 0.375);
}

TEST(RunTable, WorstFirstFailedThenLeakyThenLargestRmseThenId) {
  std::vector<RunRow> rows = {row("good", 0.4, 0.01, true),     row("leaky", 0.4, 0.001, false),
                              row("bad", 0.4, 0.30, true),      failed_row("gone"),
                              row("unmeasured", 0, 0, true, 0), row("also-bad", 0.4, 0.30, true)};
  EXPECT_EQ(ids(worst_first(rows)),
            (std::vector<std::string>{"gone", "leaky", "also-bad", "bad", "good", "unmeasured"}));
}

TEST(RunTable, TotalsCountOutcomesMovesAndSeconds) {
  std::vector<RunRow> rows = {row("a", 0.4, 0.01, true), row("b", 0.4, 0.01, true), failed_row("c")};
  rows[0].moved = {{json({2}), 0.4}, {json({3}), 0.2}};
  rows[0].refine_seconds = 2.0;
  rows[1].outcome = Outcome::Kept;
  rows[1].refine_seconds = 0.5;
  const RunTotals t = run_totals(rows);
  EXPECT_EQ(t.outcomes.at("refined"), 1u);
  EXPECT_EQ(t.outcomes.at("kept"), 1u);
  EXPECT_EQ(t.outcomes.at("failed"), 1u);
  EXPECT_EQ(t.moved.count, 2u);
  EXPECT_DOUBLE_EQ(t.moved.max, 0.4);
  EXPECT_DOUBLE_EQ(t.refine_seconds, 2.5);  // the failed building recorded none (NaN)
  EXPECT_EQ(
      totals_text(t),
      "\noutcomes: refined 1, kept 1, failed 1; facades moved 2 (max 0.400 m, mean 0.300 m); refine 2.5 s in all\n");
  // The other outcomes refine decides are counted and said after the three, when there are any.
  rows[1].outcome = Outcome::KeptInvalid;
  rows.push_back(row("d", 0.4, 0.4, true));
  rows.back().outcome = Outcome::Repaired;
  const RunTotals more = run_totals(rows);
  EXPECT_EQ(more.outcomes.at("kept-invalid"), 1u);
  EXPECT_EQ(more.outcomes.at("kept"), 0u);
  EXPECT_EQ(totals_text(more).substr(0, 67), "\noutcomes: refined 1, kept 0, failed 1, repaired 1, kept-invalid 1;");
}

TEST(RunTable, Table1LinesWithDashesForWhatWasNotMeasured) {
  PooledEval p;
  p.buildings = 2, p.evaluated = 1, p.failed = 1;
  p.before.count = p.after.count = 10;
  p.before.rmse = 0.4, p.after.rmse = 0.0123;
  p.delta_d_mean = 0.31;
  p.watertight_rate_before = 1.0, p.watertight_rate_after = 0.5;
  const std::string single = table1_text(p, false);
  std::istringstream in(single);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "buildings: 2 (evaluated 1, failed 1), facade points: 10");
  EXPECT_NE(single.find("C2M RMSE (m)                      0.400      0.012\n"), std::string::npos) << single;
  EXPECT_NE(single.find("Centroid offset red. (m)              -      0.310\n"), std::string::npos) << single;
  EXPECT_NE(single.find("Watertight rate (%)                 100         50\n"), std::string::npos) << single;
  EXPECT_NE(single.find("Truth facade RMSE (m)                 -          -\n"), std::string::npos) << single;
  EXPECT_EQ(single.find("(mean)"), std::string::npos);
  // A run adds the mean of the buildings' own figures: none measured here.
  const std::string batch = table1_text(p, true);
  EXPECT_NE(batch.find("Orig (mean)   Ref (mean)\n"), std::string::npos) << batch;
  EXPECT_NE(batch.find("C2M RMSE (m)                      0.400      0.012              -            -\n"),
            std::string::npos)
      << batch;
}

TEST(RunTable, JsonRowsInOrderWithCentroidsInTheInputFrame) {
  std::vector<RunRow> rows = {row("a", 0.4, 0.01, true), failed_row("b")};
  rows[0].origin = Vec3(85000, 447000, 0);
  rows[0].eval.c_ref = Vec3(1, 2, 3);
  rows[0].moved = {{json({2}), 0.4}};
  rows[0].selection = "optimal";
  const auto order = worst_first(rows);
  PooledEval pooled;
  pooled.buildings = 2;
  const json j = run_json(order, pooled, run_totals(rows), json{{"seed", 7}}, "RUN");
  EXPECT_EQ(j["run_dir"], "RUN");
  EXPECT_EQ(j["params"]["seed"], 7);
  EXPECT_EQ(j["pooled"]["buildings"], 2);
  EXPECT_EQ(j["pooled"]["outcomes"]["failed"], 1);
  EXPECT_EQ(j["pooled"]["facades_moved"]["count"], 1);
  ASSERT_EQ(j["buildings"].size(), 2u);
  const json& b = j["buildings"][0];
  EXPECT_EQ(b["id"], "b");
  EXPECT_EQ(b["status"], "failed");
  EXPECT_TRUE(b["c2m"]["refined"].is_null());
  EXPECT_TRUE(b["centroids"]["refined"].is_null());
  const json& a = j["buildings"][1];
  EXPECT_EQ(a["centroids"]["refined"], json({85001.0, 447002.0, 3.0}));
  EXPECT_EQ(a["facades_moved"]["facades"][0], json({{"surface", {2}}, {"displacement", 0.4}}));
  EXPECT_EQ(a["selection"], "optimal");
  EXPECT_EQ(a["refine_outcome"], "refined");
  EXPECT_FALSE(a.contains("truth"));
  EXPECT_FALSE(run_json(order, pooled, run_totals(rows), json(), "").contains("run_dir"));
}

TEST(RunTable, CsvQuotesFieldsAndLeavesUnmeasuredEmpty) {
  std::vector<RunRow> rows = {row("a,\"1\"", 0.4, 0.01, true), failed_row("b")};
  rows[0].reason = "line one\nline two";
  const std::string csv = csv_text(worst_first(rows));
  std::istringstream in(csv);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), 28);
  EXPECT_EQ(first, "b,failed,refined model missing,0,,,0,0,,0,,,,,,,,,,,,,,,,,,,");  // nothing measured
  EXPECT_NE(csv.find("\n\"a,\"\"1\"\"\",refined,\"line one\nline two\",0,,,1,1,,100,0.4000,"), std::string::npos)
      << csv;
}

TEST(RunTable, HtmlRowAndGateFigures) {
  RunRow r = row("a", 0.4, 0.01, true);
  r.moved = {{json({2}), 0.4}, {json({3}), 0.2}};
  r.refine_seconds = 3.5;
  const json h = html_row(r);
  EXPECT_EQ(h["moved"], 2);
  EXPECT_DOUBLE_EQ(h["moved_max"].get<double>(), 0.4);
  EXPECT_DOUBLE_EQ(h["c2m_after"].get<double>(), 0.01);
  EXPECT_EQ(h["watertight"], true);
  EXPECT_EQ(html_columns().size(), h.size());
  for (const auto& column : html_columns()) EXPECT_TRUE(h.contains(column[0].get<std::string>())) << column;

  const BuildingFigures f = building_figures(r);
  EXPECT_EQ(f.outcome, Outcome::Refined);
  EXPECT_EQ(f.facades_moved, 2u);
  EXPECT_DOUBLE_EQ(*f.moved_max, 0.4);
  EXPECT_DOUBLE_EQ(*f.c2m_rmse, 0.01);
  RunRow invalid = row("b", 0.4, 0.4, false);
  invalid.outcome = Outcome::KeptInvalid, invalid.refine_outcome = "kept-invalid";
  EXPECT_EQ(building_figures(invalid).outcome, Outcome::KeptInvalid);
  EXPECT_FALSE(building_figures(invalid).watertight);
  EXPECT_FALSE(building_figures(failed_row("c")).c2m_rmse);

  PooledEval p;
  p.failed = 1, p.watertight_rate_after = 0.5;
  p.after.count = 10, p.after.rmse = 0.02;
  const RunFigures run = run_figures({r, invalid, failed_row("c")}, p);
  EXPECT_EQ(run.buildings.size(), 3u);
  EXPECT_EQ(run.refined, 1u);
  EXPECT_EQ(run.failed, 1u);
  EXPECT_DOUBLE_EQ(*run.c2m_rmse, 0.02);
  EXPECT_FALSE(run.c2m_rmse_original);  // nothing measured before
}
