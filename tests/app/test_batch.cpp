// scripts/batch.mk over a small generated tile: resumable (a removed or older output redoes that
// building, and only that one), a summary that follows every change, one run per folder (lock),
// and SIGKILL at any point followed by a rerun giving exactly the outputs of an uninterrupted run;
// ids that are shell code pass through convert, crop and the dispatchers as data (BatchIds).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <set>
#include <thread>

#include "lodrefine/base/files.h"
#include "lodrefine/formats/obj.h"
#include "support/batch_fixtures.h"

using namespace lodrefine::batch_fixtures;

namespace {

// Runs the batch; returns the building ids it refined (its "ok <id>:" / "FAILED <id>:" lines).
std::vector<std::string> rerun(const fs::path& run) {
  const fs::path log = run.parent_path() / (run.filename().string() + ".log");
  EXPECT_EQ(shell(batch_command(run) + " > " + shell_quoted(log) + " 2>&1"), 0) << read_text(log);
  std::vector<std::string> ids;
  std::istringstream in(read_text(log));
  for (std::string line; std::getline(in, line);) {
    for (const std::string tag : {"ok ", "FAILED "})
      if (line.rfind(tag, 0) == 0) ids.push_back(line.substr(tag.size(), line.find(':') - tag.size()));
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

class Batch : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    TileRun t = tile_and_batch("batch", 4);
    inputs_ = new fs::path(t.inputs);
    done_ = new fs::path(t.done);
    reference_ = new std::map<std::string, std::string>(std::move(t.outputs));
    seconds_ = t.seconds;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*inputs_);
    fs::remove_all(*done_);
  }

  static std::vector<std::string> ids(const fs::path& run) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(run))
      if (fs::exists(e.path() / "coarse.obj")) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }

  static fs::path* inputs_;
  static fs::path* done_;
  static std::map<std::string, std::string>* reference_;
  static double seconds_;
};
fs::path* Batch::inputs_ = nullptr;
fs::path* Batch::done_ = nullptr;
std::map<std::string, std::string>* Batch::reference_ = nullptr;
double Batch::seconds_ = 0.0;

TEST_F(Batch, ReferenceRunRefinedEveryBuilding) {
  const auto building_ids = ids(*done_);
  ASSERT_EQ(building_ids.size(), 4u);
  for (const auto& id : building_ids) {
    EXPECT_EQ(reference_->count(id + "/refined.obj"), 1u) << id;
    EXPECT_EQ(reference_->count(id + "/report.json"), 1u) << id;
  }
  EXPECT_TRUE(fs::exists(*done_ / "summary.txt") && fs::exists(*done_ / "summary.json"));
  EXPECT_TRUE(temporaries(*done_).empty());
}

TEST_F(Batch, RemovedOrOlderOutputRedoesOnlyThatBuilding) {
  const fs::path run = fresh_dir("batch_resume");
  copy_run(*done_, run);
  EXPECT_TRUE(rerun(run).empty()) << "an up-to-date run must do nothing";
  const auto summary_time = fs::last_write_time(run / "summary.json");

  const auto building_ids = ids(run);
  fs::remove(run / building_ids[0] / "refined.obj");
  ASSERT_EQ(shell("touch -d 2000-01-01 " + shell_quoted(run / building_ids[2] / "report.json")), 0);
  EXPECT_EQ(rerun(run), (std::vector<std::string>{building_ids[0], building_ids[2]}));
  EXPECT_EQ(outcome_files(run), *reference_);
  EXPECT_GT(fs::last_write_time(run / "summary.json"), summary_time) << "summary not refreshed";
  EXPECT_TRUE(rerun(run).empty());
  fs::remove_all(run);
}

TEST_F(Batch, SummaryFollowsAFailureAndARemovedBuilding) {
  const fs::path run = fresh_dir("batch_summary");
  copy_run(*done_, run);
  const auto building_ids = ids(run);
  // A new, unreadable cloud: the building is redone, fails, and the summary says why.
  std::ofstream(run / building_ids[1] / "cloud.ply") << "not a ply\n";
  EXPECT_EQ(rerun(run), std::vector<std::string>{building_ids[1]});
  const std::string reason = read_text(run / building_ids[1] / "FAILED");
  EXPECT_NE(reason.find("lodrefine: error:"), std::string::npos) << reason;
  EXPECT_FALSE(fs::exists(run / building_ids[1] / "refined.obj"));
  json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary["pooled"]["buildings"], 4);
  EXPECT_EQ(summary["pooled"]["failed"], 1);
  const std::string csv = read_text(run / "summary.csv");
  EXPECT_NE(csv.find(reason.substr(0, reason.size() - 1)), std::string::npos) << "csv lacks the FAILED reason:\n"
                                                                              << csv;
  EXPECT_EQ(csv.find("refined model missing"), std::string::npos) << csv;
  EXPECT_TRUE(rerun(run).empty()) << "a recorded failure is not retried until FAILED is removed";

  // A removed building leaves the summary.
  fs::remove_all(run / building_ids[3]);
  EXPECT_TRUE(rerun(run).empty());
  summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary["pooled"]["buildings"], 3);
  fs::remove_all(run);
}

TEST_F(Batch, SecondConcurrentRunIsRefusedWithOneLine) {
  const fs::path run = fresh_dir("batch_lock");
  copy_run(*inputs_, run);
  // A slow binary keeps the first run busy.
  const fs::path slow = run.parent_path() / (run.filename().string() + "_slow.sh");
  std::ofstream(slow) << "#!/bin/sh\nsleep 1\nexec '" << kBinary << "' \"$@\"\n";
  fs::permissions(slow, fs::perms::owner_all);
  const pid_t first = spawn_group(batch_command(run, "LODREFINE=" + shell_quoted(slow)) + " > /dev/null 2>&1");
  for (int i = 0; i < 200 && !fs::exists(run / ".batch.pid"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  ASSERT_TRUE(fs::exists(run / ".batch.pid"));
  const fs::path err = run.parent_path() / (run.filename().string() + "_second.err");
  const int second = shell(batch_command(run) + " > /dev/null 2> " + shell_quoted(err));
  const std::string message = read_text(err);
  EXPECT_NE(second, 0);
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_NE(message.find("in use by another batch run"), std::string::npos) << message;
  EXPECT_EQ(wait_exit(first), 0);
  EXPECT_EQ(outcome_files(run), *reference_);
  fs::remove_all(run);
}

// `make -j2` refines two buildings at once: batch.mk's outer make hands its job slots to the inner
// one (a '+' recipe; without it the inner make warned "jobserver unavailable" and ran one at a
// time). Each refine waits up to 10 s for another to be running beside it.
TEST_F(Batch, JobsRefineBuildingsAtOnce) {
  const fs::path run = fresh_dir("batch_jobs");
  copy_run(*inputs_, run);
  const fs::path meet = run.parent_path() / (run.filename().string() + "_meet.sh");
  std::ofstream(meet) << R"sh(#!/bin/sh
m=../.running.$$
touch "$m"
i=0
while [ $i -lt 200 ]; do
  [ "$(ls ../.running.* | wc -l)" -ge 2 ] && { touch ../.together; break; }
  sleep 0.05; i=$((i + 1))
done
')sh" << kBinary << R"sh(' "$@"
rc=$?
rm -f "$m"
exit $rc
)sh";
  fs::permissions(meet, fs::perms::owner_all);
  const fs::path log = run.parent_path() / (run.filename().string() + "_jobs.log");
  EXPECT_EQ(shell(batch_command(run, "LODREFINE=" + shell_quoted(meet)) + " > " + shell_quoted(log) + " 2>&1"), 0);
  EXPECT_TRUE(fs::exists(run / ".together")) << "no two buildings were refined at once";
  EXPECT_EQ(read_text(log).find("jobserver unavailable"), std::string::npos) << read_text(log);
  fs::remove(run / ".together");
  EXPECT_EQ(outcome_files(run), *reference_);
  fs::remove_all(run);
}

TEST_F(Batch, SigkillAnywhereThenRerunEqualsUninterruptedRun) {
  const fs::path run = fresh_dir("batch_kill");
  copy_run(*inputs_, run);
  // Kills spread over a whole run (measured on the reference), each followed by a restart.
  for (double at : {0.05, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9}) {
    const pid_t pid = spawn_group(batch_command(run) + " > /dev/null 2>&1");
    std::this_thread::sleep_for(std::chrono::duration<double>(at * seconds_));
    ::kill(-pid, SIGKILL);
    wait_exit(pid);
  }
  rerun(run);
  EXPECT_EQ(outcome_files(run), *reference_);
  EXPECT_TRUE(temporaries(run).empty()) << temporaries(run).front();
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary["pooled"]["buildings"], 4);
  EXPECT_EQ(summary["pooled"]["failed"], 0);
  EXPECT_TRUE(rerun(run).empty());
  fs::remove_all(run);
}

}  // namespace

namespace {

// The CSV lists the buildings of `rows` in the same order.
void expect_csv_rows(const fs::path& done, const json& rows) {
  std::istringstream csv(read_text(done / "summary.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("id,outcome,reason,facades_moved,displacement_max,displacement_mean,", 0), 0u) << line;
  for (const auto& row : rows) {
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_EQ(line.substr(0, line.find(',')), row["id"].get<std::string>());
  }
}

// A report's "facades" list is read as such: input faces with their largest move (the retired
// "surface"/"displacement" spelling counts for nothing); a kept building moved nothing
// whatever the list says.
void expect_facades_lists_read(const fs::path& done, const json& rows) {
  const fs::path run = fresh_dir("batch_facades");
  copy_run(done, run);
  const std::string a = rows[0]["id"], b = rows[1]["id"], c = rows[2]["id"];
  auto edit_report = [&](const std::string& id, const std::string& outcome, const json& facades) {
    json report = json::parse(read_text(run / id / "report.json"));
    report["outcome"] = outcome;
    report["facades"] = facades;
    std::ofstream(run / id / "report.json") << report.dump(2);
  };
  edit_report(a, "refined",
              {{{"input_faces", {7}}, {"evidence", "scan"}, {"max_move", 0.5}, {"mean_move", 0.5}},
               {{"input_faces", {8}}, {"evidence", "corner"}, {"max_move", -0.25}, {"mean_move", 0.1}}});
  edit_report(b, "refined",
              {{{"input_faces", {3, 4}}, {"evidence", "scan"}, {"max_move", 0.6}, {"mean_move", 0.4}},
               {{"surface", "wall-8"}, {"displacement", 0.9}}});
  edit_report(c, "kept", {{{"input_faces", {1}}, {"evidence", "scan"}, {"max_move", 0.9}, {"mean_move", 0.9}}});
  EXPECT_TRUE(rerun(run).empty());
  const json updated = json::parse(read_text(run / "summary.json"));
  for (const auto& row : updated["buildings"]) {
    const json& m = row["facades_moved"];
    if (row["id"] == a) {
      EXPECT_EQ(m["count"], 2);
      EXPECT_DOUBLE_EQ(m["max"].get<double>(), 0.5);
      EXPECT_DOUBLE_EQ(m["mean"].get<double>(), 0.375);
      EXPECT_EQ(m["facades"][1]["surface"], json({8}));
    } else if (row["id"] == b) {
      EXPECT_EQ(m["count"], 1);
      EXPECT_DOUBLE_EQ(m["max"].get<double>(), 0.6);
      EXPECT_EQ(m["facades"][0]["surface"], json({3, 4}));
    } else if (row["id"] == c) {
      EXPECT_EQ(row["outcome"], "kept");
      EXPECT_EQ(m["count"], 0);
    }
  }
  fs::remove_all(run);
}

// The tile table (summary.json / summary.csv): worst first, outcome and moved facades as the
// refine reports say, and a lead-style "facades" list (surface ids) used when present.
TEST_F(Batch, TileTableWorstFirstWithOutcomesAndMovedFacades) {
  const json summary = json::parse(read_text(*done_ / "summary.json"));
  const json& rows = summary["buildings"];
  ASSERT_EQ(rows.size(), 4u);
  double last_rmse = 1e300;
  std::size_t moved_total = 0;
  for (const auto& row : rows) {
    const std::string id = row["id"];
    const json report = json::parse(read_text(*done_ / id / "report.json"));
    // Worst first among watertight, evaluated buildings: refined C2M RMSE descending.
    ASSERT_TRUE(row["watertight"]["refined"].get<bool>()) << id;
    const double rmse = row["c2m"]["refined"]["rmse"];
    EXPECT_LE(rmse, last_rmse) << id;
    last_rmse = rmse;
    const std::string outcome = report["outcome"];
    EXPECT_EQ(row["outcome"], outcome == "refined" ? "refined" : "kept") << id;
    EXPECT_EQ(report["report_version"], 1) << id;
    // The report's moved facades: its "facades" list, each with its largest move.
    std::size_t moved = 0;
    double max_move = 0.0;
    if (outcome == "refined")
      for (const auto& f : report["facades"])
        ++moved, max_move = std::max(max_move, std::abs(f["max_move"].get<double>()));
    EXPECT_EQ(row["facades_moved"]["count"], moved) << id;
    if (moved) {
      EXPECT_NEAR(row["facades_moved"]["max"].get<double>(), max_move, 1e-9) << id;
    }
    for (const auto& f : row["facades_moved"]["facades"]) EXPECT_FALSE(f["surface"].is_null()) << id;
    EXPECT_GT(row["refine_seconds"].get<double>(), 0.0);
    moved_total += moved;
  }
  EXPECT_GT(moved_total, 0u) << "the generated buildings have misplaced scanned walls";
  EXPECT_EQ(summary["pooled"]["facades_moved"]["count"], moved_total);
  EXPECT_EQ(summary["pooled"]["outcomes"]["failed"], 0);
  expect_csv_rows(*done_, rows);
  expect_facades_lists_read(*done_, rows);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Untrusted ids (issue 15): ids are data all the way from a city file to the dispatchers.

namespace {

const std::vector<std::string> kHostileIds = {"$(touch PWNED)", "a';touch PWNED;'", "x;touch PWNED", "plain"};

// Every file named PWNED below `dir`, and in the test's working folder.
std::vector<std::string> pwned(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename() == "PWNED") found.push_back(e.path().string());
  if (fs::exists("PWNED")) found.push_back(fs::absolute("PWNED").string());
  return found;
}

// A CityJSON 2.0 file holding the given models (polygon soups) under the given ids.
std::string city_json(const std::vector<lodrefine::Mesh>& models, const std::vector<std::string>& ids) {
  json doc = {{"type", "CityJSON"},
              {"version", "2.0"},
              {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {0.0, 0.0, 0.0}}}},
              {"CityObjects", json::object()},
              {"vertices", json::array()}};
  for (std::size_t b = 0; b < models.size(); ++b) {
    const std::size_t first = doc["vertices"].size();
    for (const auto& v : models[b].vertices)
      doc["vertices"].push_back({std::llround(v.x() * 1000), std::llround(v.y() * 1000), std::llround(v.z() * 1000)});
    json boundaries = json::array();
    for (const auto& f : models[b].faces) {
      json ring = json::array();
      for (int i : f.v) ring.push_back(first + std::size_t(i));
      boundaries.push_back({ring});
    }
    doc["CityObjects"][ids[b]] = {
        {"type", "Building"}, {"geometry", {{{"type", "MultiSurface"}, {"lod", "2.2"}, {"boundaries", boundaries}}}}};
  }
  return doc.dump();
}

}  // namespace

// convert -> crop -> batch.mk (and GNU Parallel when installed) with ids that are shell code, in
// a RUN path with a space: nothing runs, every building is refined, the real ids reach the reports.
TEST(BatchIds, HostileIdsThroughConvertCropAndDispatchersRunNothing) {
  const fs::path base = fresh_dir("batch ids");
  const std::string in_base = "cd " + shell_quoted(base) + " && ";
  ASSERT_EQ(
      shell(in_base + shell_quoted(kBinary) + " synth --tile tile.ply --count 4 --points 3000 --out synth > /dev/null"),
      0);
  std::vector<lodrefine::Mesh> models;
  for (const auto& e : fs::directory_iterator(base / "synth"))
    models.push_back(lodrefine::read_obj((e.path() / "coarse.obj").string()));
  ASSERT_EQ(models.size(), kHostileIds.size());
  std::ofstream(base / "city.json") << city_json(models, kHostileIds);

  const fs::path run = base / "my run";
  const fs::path log = base / "log.txt";
  ASSERT_EQ(shell(in_base + shell_quoted(kBinary) + " convert --cityjson city.json --out-dir objs > log.txt 2>&1"), 0)
      << read_text(log);
  ASSERT_EQ(
      shell(in_base + shell_quoted(kBinary) + " crop --tile tile.ply --models objs --out 'my run' > log.txt 2>&1"), 0)
      << read_text(log);
  ASSERT_EQ(shell(in_base + batch_command(run) + " > log.txt 2>&1"), 0) << read_text(log);
  EXPECT_TRUE(pwned(base).empty()) << pwned(base).front();

  auto expect_all_refined = [&](const fs::path& r) {
    std::set<std::string> ids;
    for (const auto& e : fs::directory_iterator(r)) {
      if (!fs::exists(e.path() / "coarse.obj")) continue;
      EXPECT_TRUE(lodrefine::is_safe_name(e.path().filename().string())) << e.path();
      EXPECT_TRUE(fs::exists(e.path() / "refined.obj")) << e.path() << ": " << read_text(e.path() / "FAILED");
      if (fs::exists(e.path() / "report.json"))
        ids.insert(json::parse(read_text(e.path() / "report.json"))["id"].get<std::string>());
    }
    EXPECT_EQ(ids, std::set<std::string>(kHostileIds.begin(), kHostileIds.end())) << "the reports hold the real ids";
    EXPECT_EQ(json::parse(read_text(r / "summary.json"))["pooled"]["buildings"], 4);
  };
  expect_all_refined(run);

  if (shell("command -v parallel > /dev/null") == 0) {
    ASSERT_EQ(shell("make -s -f " + shell_quoted(kSource / "scripts" / "batch.mk") + " RUN=" + shell_quoted(run) +
                    " clean-results"),
              0);
    ASSERT_EQ(shell(in_base + "LODREFINE=" + shell_quoted(kBinary) + " HOME=" + shell_quoted(base) + " " +
                    shell_quoted(kSource / "scripts" / "parallel_batch.sh") + " " + shell_quoted(run) +
                    " --sshlogin : -j2 > log.txt 2>&1"),
              0)
        << read_text(log);
    EXPECT_TRUE(pwned(base).empty()) << pwned(base).front();
    expect_all_refined(run);
  }
  if (!HasFailure()) fs::remove_all(base);
}

// A folder name that is not a safe name (made by hand, or by an older crop) is refused with one
// line before anything runs, by make and by GNU Parallel; nothing is executed.
TEST(BatchIds, UnsafeFolderNamesAreRefusedBeforeAnythingRuns) {
  const fs::path base = fresh_dir("batch_unsafe");
  const fs::path run = base / "run";
  make_tile(run, 1);
  const fs::path good = fs::directory_iterator(run)->path();
  for (const std::string name : {"x;touch PWNED", "$(touch PWNED)", "-rf", "a'b"}) {
    const fs::path bad = run / name;
    fs::create_directories(bad);
    fs::copy_file(good / "coarse.obj", bad / "coarse.obj");
    fs::copy_file(good / "cloud.ply", bad / "cloud.ply");
    const fs::path err = base / "err.txt";
    EXPECT_EQ(shell("cd " + shell_quoted(base) + " && " + batch_command(run) + " > /dev/null 2> " + shell_quoted(err)),
              2)
        << name;
    const std::string message = read_text(err);
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_NE(message.find("is not a safe name"), std::string::npos) << message;
    if (shell("command -v parallel > /dev/null") == 0) {
      EXPECT_NE(shell("cd " + shell_quoted(base) + " && LODREFINE=" + shell_quoted(kBinary) +
                      " HOME=" + shell_quoted(base) + " " + shell_quoted(kSource / "scripts" / "parallel_batch.sh") +
                      " " + shell_quoted(run) + " --sshlogin : > /dev/null 2>&1"),
                0)
          << name;
    }
    EXPECT_EQ(shell("cd " + shell_quoted(base) + " && " + shell_quoted(kSource / "scripts" / "refine_one.sh") + " " +
                    shell_quoted(run) + " " + shell_quoted(name) + " 2> /dev/null"),
              2)
        << name;
    EXPECT_TRUE(pwned(base).empty()) << name;
    EXPECT_FALSE(fs::exists(good / "refined.obj")) << "nothing runs when a name is refused";
    fs::remove_all(bad);
  }
  fs::remove_all(base);
}

// A building folder that is a symbolic link (planted: Y -> /elsewhere) would take the building's
// outputs, and the batch's cleaning of temporaries, outside the run folder: refused with one
// line before anything runs, and by refine_one.sh itself.
TEST(BatchIds, SymlinkedBuildingFoldersAreRefusedBeforeAnythingRuns) {
  const fs::path base = fresh_dir("batch_symlink");
  const fs::path run = base / "run";
  make_tile(run, 1);
  const fs::path good = fs::directory_iterator(run)->path();
  const fs::path outside = base / "outside";
  fs::create_directories(outside);
  fs::copy_file(good / "coarse.obj", outside / "coarse.obj");
  fs::copy_file(good / "cloud.ply", outside / "cloud.ply");
  fs::create_directory_symlink(outside, run / "Y");
  const fs::path err = base / "err.txt";
  EXPECT_EQ(shell("cd " + shell_quoted(base) + " && " + batch_command(run) + " > /dev/null 2> " + shell_quoted(err)),
            2);
  const std::string message = read_text(err);
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_NE(message.find("is a symbolic link"), std::string::npos) << message;
  EXPECT_EQ(shell(shell_quoted(kSource / "scripts" / "refine_one.sh") + " " + shell_quoted(run) + " Y 2> /dev/null"),
            2);
  EXPECT_EQ(std::distance(fs::directory_iterator(outside), fs::directory_iterator()), 2) << "nothing written there";
  EXPECT_FALSE(fs::exists(good / "refined.obj")) << "nothing runs when a folder is refused";
  fs::remove_all(base);
}

// The run folder's own name reaches make's command line from the dispatchers: "$(shell ...)"
// in it ran the command (make expands "$" in a command-line variable).
TEST(BatchIds, RunFolderNamedWithMakeSyntaxRunsNothing) {
  const fs::path base = fresh_dir("batch_dollar");
  const fs::path run = base / "r$(shell touch PWNED)";
  make_tile(run, 1);
  for (const char* script : {"parallel_batch.sh", "slurm_batch.sh"}) {
    const fs::path err = base / "err.txt";
    EXPECT_EQ(shell("cd " + shell_quoted(base) + " && LODREFINE=" + shell_quoted(kBinary) +
                    " HOME=" + shell_quoted(base) + " " + shell_quoted(kSource / "scripts" / script) + " " +
                    shell_quoted(run) + " > /dev/null 2> " + shell_quoted(err)),
              2)
        << script;
    const std::string message = read_text(err);
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_EQ(message.rfind("lodrefine: error: ", 0), 0u) << message;
    EXPECT_NE(message.find("holding \"$\""), std::string::npos) << message;
    EXPECT_TRUE(pwned(base).empty()) << script;
  }
  fs::remove_all(base);
}

// Leftovers: the batch removes lodrefine's own temporaries of a killed run, and never a user's
// file that merely has ".tmp." in its name.
TEST(BatchIds, OnlyLodrefineTemporariesAreCleanedUp) {
  const fs::path base = fresh_dir("batch_leftovers");
  const fs::path run = base / "run";
  make_tile(run, 1);
  const fs::path building = fs::directory_iterator(run)->path();
  for (const fs::path& p : {run / "notes.tmp.1", building / "mine.tmp.2", building / "refined.obj.tmp.3"})
    std::ofstream(p) << "user data\n";
  std::ofstream(building / ".lodrefine-tmp-AbCdEf1234") << "killed writer\n";
  std::ofstream(run / ".lodrefine-tmp-XyZ") << "killed writer\n";
  ASSERT_EQ(shell(batch_command(run) + " > /dev/null 2>&1"), 0);
  EXPECT_TRUE(fs::exists(building / "refined.obj"));
  for (const fs::path& p : {run / "notes.tmp.1", building / "mine.tmp.2", building / "refined.obj.tmp.3"})
    EXPECT_EQ(read_text(p), "user data\n") << p;
  EXPECT_FALSE(fs::exists(building / ".lodrefine-tmp-AbCdEf1234"));
  EXPECT_FALSE(fs::exists(run / ".lodrefine-tmp-XyZ"));
  fs::remove_all(base);
}
