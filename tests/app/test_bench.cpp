// `lodrefine bench` (apps/cmd_bench.cpp): the speed targets are read off its table, so every
// stage the pipeline times must have a column, the summary must be the buildings' median and
// maximum, and a tile's buildings must be benched as generated ones are.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "lodrefine/refine/refine.h"
#include "support/cli_fixtures.h"

using namespace lodrefine;
using cli_fixtures::run_cli;
using cli_fixtures::test_dir;

namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// The whitespace-separated words of the part of `line` between its n-th and (n+1)-th '|'.
std::vector<std::string> section(const std::string& line, int n) {
  std::size_t at = 0;
  for (int k = 0; k < n; ++k) at = line.find('|', at) + 1;
  const std::size_t end = line.find('|', at);
  std::istringstream in(line.substr(at, end == std::string::npos ? std::string::npos : end - at));
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The cells as numbers; "-" (a stage not reached) is NaN.
std::vector<double> numbers(const std::vector<std::string>& words) {
  std::vector<double> out;
  for (const auto& w : words) out.push_back(w == "-" ? std::nan("") : std::stod(w));
  return out;
}

// The line starting with `prefix` (after leading blanks); empty when none.
std::string line_starting(const std::vector<std::string>& lines, const std::string& prefix) {
  for (const auto& l : lines) {
    const std::size_t first = l.find_first_not_of(' ');
    if (first != std::string::npos && l.compare(first, prefix.size(), prefix) == 0) return l;
  }
  return {};
}

std::vector<std::string> stage_columns() {
  std::vector<std::string> names(kRefineStageNames.begin(), kRefineStageNames.end());
  names.push_back("total");
  return names;
}

}  // namespace

// Every timed stage has its column (the selection and the judge among them: a column of a
// stage the pipeline no longer has read 0 for every building before), in the trace's order,
// and a refined building's stages add up to at most its total.
TEST(Bench, EveryTimedStageHasAColumnAndTheSummaryIsTheMedianAndMax) {
  const std::string dir = test_dir("bench");
  const auto r = run_cli("bench --type recess --count 1 --repeat 2", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  const auto lines = lines_of(r.out);
  const std::string header = line_starting(lines, "building");
  ASSERT_FALSE(header.empty()) << r.out;
  EXPECT_EQ(section(header, 1), stage_columns());

  const std::string row = line_starting(lines, "synth_recess_0001");
  ASSERT_FALSE(row.empty()) << r.out;
  EXPECT_EQ(section(row, 3), std::vector<std::string>{"refined"});
  const std::vector<std::string> cells = section(row, 1);
  ASSERT_EQ(cells.size(), stage_columns().size());
  for (const auto& c : cells) EXPECT_NE(c, "-") << row;  // a refined building reaches every stage
  const std::vector<double> stages = numbers(cells);
  const double total = stages.back();
  EXPECT_GT(stages[std::size_t(RefineStage::Planes)], 0.0);
  // Each printed to 1 ms: the stages' least times add up to at most the least total.
  EXPECT_LE(std::accumulate(stages.begin(), stages.end() - 1, 0.0), total + 0.0005 * double(stages.size()));
  const std::vector<double> facade = numbers(section(row, 2));
  ASSERT_EQ(facade.size(), 2u);
  EXPECT_LT(facade[1], 0.5 * facade[0]);

  // One building: its median and maximum are its own times.
  const std::string summary = line_starting(lines, "seconds per building, best of 2");
  EXPECT_FALSE(summary.empty()) << r.out;
  EXPECT_EQ(section(summary, 1), stage_columns());
  EXPECT_EQ(numbers(section(line_starting(lines, "median"), 1)), stages);
  EXPECT_EQ(numbers(section(line_starting(lines, "max"), 1)), stages);
  EXPECT_FALSE(line_starting(lines, "1 buildings, 1 refined, 1 valid+watertight, 0 skipped").empty()) << r.out;
}

// --tile without --polyfit benches a run folder's buildings, truth read from its files; a
// folder without buildings is one line and a non-zero exit, before any table, and options that
// generate buildings are refused beside it.
TEST(Bench, ATilesBuildingsAreBenchedAsGeneratedOnesAre) {
  const std::string dir = test_dir("bench");
  ASSERT_EQ(run_cli("synth --type flat --seed 3 --out " + dir + "/run", dir).exit, 0);
  const auto r = run_cli("bench --tile " + dir + "/run", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  const auto lines = lines_of(r.out);
  const std::string row = line_starting(lines, "synth_flat_0003");
  ASSERT_FALSE(row.empty()) << r.out;
  const std::vector<double> facade = numbers(section(row, 2));
  ASSERT_EQ(facade.size(), 2u);
  EXPECT_GT(facade[0], 0.05);
  EXPECT_LT(facade[1], 0.5 * facade[0]);
  EXPECT_FALSE(line_starting(lines, "seconds per building, best of 1").empty()) << r.out;

  std::filesystem::create_directories(dir + "/empty");
  const auto none = run_cli("bench --tile " + dir + "/empty", dir);
  EXPECT_NE(none.exit, 0);
  EXPECT_TRUE(none.out.empty()) << none.out;
  EXPECT_EQ(std::count(none.err.begin(), none.err.end(), '\n'), 1) << none.err;
  const auto both = run_cli("bench --tile " + dir + "/run --count 3", dir);
  EXPECT_NE(both.exit, 0);
  EXPECT_TRUE(both.out.empty()) << both.out;
}

// A building kept before the matching (no scan point near it) shows "-" for the stages it did not
// reach, and the medians are over the buildings that reached each stage (zeros there made them
// read low); a building whose files cannot be read is a "skipped" row and exit code 1, the others
// still benched.
TEST(Bench, StagesNotReachedAreNoZerosAndUnreadableBuildingsAreSkipped) {
  const std::string dir = test_dir("bench");
  const std::string run = dir + "/run";
  ASSERT_EQ(run_cli("synth --type flat --seed 3 --out " + run, dir).exit, 0);
  const std::string far = run + "/a_building_far_from_its_scan_with_a_long_id";
  std::filesystem::create_directories(far);
  std::filesystem::copy_file(run + "/synth_flat_0003/coarse.obj", far + "/coarse.obj");
  std::ofstream(far + "/cloud.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float "
                                       "y\nproperty float z\nend_header\n1e5 1e5 0\n1e5 1e5 1\n1e5 1e5 2\n";
  std::filesystem::create_directories(run + "/broken");
  std::ofstream(run + "/broken/coarse.obj") << "garbage\n";
  std::filesystem::copy_file(run + "/synth_flat_0003/cloud.ply", run + "/broken/cloud.ply");

  const auto r = run_cli("bench --tile " + run, dir);
  EXPECT_EQ(r.exit, 1) << r.err;
  const auto lines = lines_of(r.out);
  EXPECT_FALSE(line_starting(lines, "broken: skipped:").empty()) << r.out;
  const std::string kept = line_starting(lines, "a_building_far_from_its_scan_with_a_long_id");
  const std::string refined = line_starting(lines, "synth_flat_0003");
  ASSERT_FALSE(kept.empty() || refined.empty()) << r.out;
  EXPECT_EQ(section(kept, 3), std::vector<std::string>{"kept"});
  const std::vector<std::string> kept_cells = section(kept, 1);
  ASSERT_EQ(kept_cells.size(), stage_columns().size());
  for (RefineStage s : {RefineStage::Matching, RefineStage::Substitution, RefineStage::Selection, RefineStage::Judge})
    EXPECT_EQ(kept_cells[std::size_t(s)], "-") << stage_name(s);
  EXPECT_NE(kept_cells[std::size_t(RefineStage::Planes)], "-");
  // The long id widens the id column: every row's first '|' stands where the header's does.
  const std::string header = line_starting(lines, "building");
  EXPECT_EQ(kept.find('|'), header.find('|'));
  EXPECT_EQ(refined.find('|'), header.find('|'));
  EXPECT_EQ(line_starting(lines, "median").find('|'), header.find('|'));
  // The selection's median is the refined building's own: the kept one has none.
  const std::vector<double> median = numbers(section(line_starting(lines, "median"), 1));
  const std::size_t sel = std::size_t(RefineStage::Selection);
  EXPECT_EQ(median[sel], numbers(section(refined, 1))[sel]);
  EXPECT_FALSE(line_starting(lines, "2 buildings, 1 refined").empty()) << r.out;
  EXPECT_NE(r.out.find("1 skipped"), std::string::npos) << r.out;
}

// --repeat is for lodrefine's own stage times: with PolyFit beside it, it is refused.
TEST(Bench, RepeatWithPolyfitIsRefused) {
  const std::string dir = test_dir("bench");
  const auto r = run_cli("bench --polyfit --repeat 2 --count 1 --type flat", dir);
  EXPECT_NE(r.exit, 0);
  EXPECT_NE(r.err.find("--repeat"), std::string::npos) << r.err;
}

// The app allocates with jemalloc (CMakeLists.txt, LODREFINE_JEMALLOC): asked through its
// MALLOC_CONF, jemalloc prints its statistics at exit. glibc's malloc ignores the variable.
TEST(Bench, TheAppAllocatesWithJemalloc) {
  if (!LODREFINE_APP_JEMALLOC) GTEST_SKIP() << "built without jemalloc (LODREFINE_JEMALLOC off, or the sanitizers)";
  const std::string dir = test_dir("bench");
  ASSERT_EQ(::setenv("MALLOC_CONF", "stats_print:true", 1), 0);
  const auto r = run_cli("--version", dir);
  ::unsetenv("MALLOC_CONF");
  EXPECT_EQ(r.exit, 0);
  EXPECT_NE(r.out.find("lodrefine"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("jemalloc statistics"), std::string::npos) << r.err.substr(0, 300);
}
