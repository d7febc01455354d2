// A city refined on a pool (--jobs): the same bytes as one at a time whatever finishes first
// (the output, the review page, selections ending at the work budget), the hook and the
// progress line.
#include <gtest/gtest.h>

#include "support/city_fixtures.h"
#include "support/cli_fixtures.h"
#include "support/cpu_burners.h"
#include "support/io_fixtures.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"
#include "support/schema_fixtures.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <random>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/refine/selection.h"
#include "lodrefine/synth/synth.h"
#include "support/test_paths.h"

using namespace lodrefine;
using namespace lodrefine::city_fixtures;
namespace fs = std::filesystem;

// --jobs: buildings refined on a pool, written in file order: the same bytes as one at a time,
// for a CityJSON file and for a CityJSONSeq, with the progress callback called once a building
// (once a feature) in order and counting up to the file's buildings.
TEST(CityFile, JobsWriteTheSameBytesAsOneAtATime) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Flat, BuildingType::Hip,
                    BuildingType::Shed, BuildingType::Stepped, BuildingType::TShape},
                   41, 5000, 6, cloud);
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  std::string seq = synth_city({}, Vec3(93000, 436000, 0)).dump() + "\n";
  for (const auto& b : bs) {
    json one = synth_city({b}, Vec3(93000, 436000, 0));
    seq += json({{"type", "CityJSONFeature"},
                 {"id", b.id},
                 {"CityObjects", one["CityObjects"]},
                 {"vertices", one["vertices"]}})
               .dump() +
           "\n";
  }
  write_file_atomic(dir + "/city.city.jsonl", seq);
  write_ply(dir + "/cloud.ply", cloud);
  for (const std::string name : {"city.json", "city.city.jsonl"}) {
    std::map<int, std::string> written;
    std::map<int, std::vector<std::string>> order;
    for (int jobs : {1, 3}) {
      CityRefineOptions o;
      o.jobs = jobs;
      std::vector<int> done;
      o.progress = [&](const CityRefineSummary& s) {
        done.push_back(s.refined + s.kept + s.kept_invalid + s.untouched);
        EXPECT_EQ(s.buildings, int(bs.size()));
      };
      const std::string out = dir + "/out" + std::to_string(jobs) + "." + name;
      const CityRefineSummary s = refine_city(dir + "/" + name, {dir + "/cloud.ply"}, out, RefineConfig{}, o);
      EXPECT_EQ(s.refined + s.kept + s.kept_invalid, 6);
      EXPECT_GE(s.refined, 4) << name;
      ASSERT_EQ(done.size(), bs.size()) << name;
      for (std::size_t i = 0; i < done.size(); ++i) EXPECT_EQ(done[i], int(i) + 1);
      std::ifstream f(out, std::ios::binary);
      written[jobs].assign(std::istreambuf_iterator<char>(f), {});
      for (const auto& b : s.outcomes) order[jobs].push_back(b.id);
    }
    EXPECT_EQ(written[1], written[3]) << name << ": --jobs 3 wrote other bytes than --jobs 1";
    EXPECT_EQ(order[1], order[3]) << name << ": outcomes not in file order";
    EXPECT_GT(written[1].size(), 1000u);
  }
}

// Buildings whose selection ends at the work budget (made small here so that every search does)
// select the same faces on a pool of 2 and one at a time, while other threads load the CPU: the
// budget counts GLPK's work, not seconds.
TEST(CityFile, JobsWriteTheSameBytesWhenSelectionsEndAtTheBudget) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street(
      {BuildingType::LShape, BuildingType::TShape, BuildingType::Stepped, BuildingType::Hip}, 43, 5000, 4, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  RefineConfig prm;
  prm.selection.mip_work_limit = 0.02;
  fixtures::CpuBurners burners(2);
  std::map<int, std::string> written;
  int at_budget = 0;
  for (int jobs : {1, 2}) {
    CityRefineOptions o;
    o.jobs = jobs;
    o.on_building = [&](std::size_t, const Mesh&, const CityBuildingOutcome*, const RefineResult* r,
                        const PointCloud*) {
      if (jobs == 1 && r != nullptr && r->trace.selection &&
          r->trace.selection->selection.status == SolveStatus::FeasibleBudget)
        ++at_budget;
    };
    const std::string out = dir + "/out" + std::to_string(jobs) + ".city.json";
    const CityRefineSummary s = refine_city(dir + "/city.json", {dir + "/cloud.ply"}, out, prm, o);
    EXPECT_GE(s.refined, 1);
    std::ifstream f(out, std::ios::binary);
    written[jobs].assign(std::istreambuf_iterator<char>(f), {});
  }
  burners.stop();
  EXPECT_GE(at_budget, 1) << "no selection reached the budget: the test shows nothing";
  EXPECT_EQ(written[1], written[2]) << "--jobs 2 wrote other bytes than --jobs 1";
}

// The progress line: redrawn in place on a terminal (a pty from script(1)), absent from a
// short run into a file and with --quiet; stdout and the exit code the same either way.
TEST(CityFile, ProgressLineOnATerminalOnly) {
  if (std::system("script -V >/dev/null 2>&1") != 0) GTEST_SKIP() << "script(1) absent";
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Hip}, 61, 6000, 3, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  const std::string args =
      "refine --jobs 2 --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/o.city.json";
  const Cli plain = run_cli(args, dir);
  ASSERT_EQ(plain.exit, 0) << plain.err;
  EXPECT_EQ(plain.err, "") << "a short run into a file prints no progress";
  EXPECT_NE(plain.out.find("3 building(s)"), std::string::npos) << plain.out;
  auto on_terminal = [&](const std::string& extra) {
    const std::string log = dir + "/tty.log";
    const int st = std::system(
        ("script -qec '" + test_paths::lodrefine_binary() + " " + args + extra + "' /dev/null > " + log + " 2>&1")
            .c_str());
    EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    std::ifstream in(log, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string tty = on_terminal("");
  EXPECT_NE(tty.find("\rrefine: "), std::string::npos) << tty;
  EXPECT_NE(tty.find("\x1b[K"), std::string::npos) << "the redrawn line clears its tail";
  EXPECT_NE(tty.find("refine: 3/3 buildings (100 %)"), std::string::npos) << "the last figures stay: " << tty;
  EXPECT_NE(tty.find(plain.out.substr(0, plain.out.find(" -> "))), std::string::npos) << "stdout unchanged";
  const std::string quiet = on_terminal(" --quiet");
  EXPECT_EQ(quiet.find("refine: "), std::string::npos) << quiet;
}

// The review page of a CityJSONSeq: its features are refined on the pool and finish in any
// order; the page lists them in file order, its map in the first building's frame, so runs with
// any --jobs write the same bytes (the page followed whichever building finished first).
TEST(CityFile, ReviewPageIsTheSameWhateverFinishesFirst) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Hip,
                                                      BuildingType::Shed, BuildingType::TShape, BuildingType::Flat},
                                                     71, 4000, 6, cloud);
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  std::vector<std::string> pages;
  for (const int jobs : {1, 4, 4, 3}) {
    const std::string page = dir + "/review" + std::to_string(pages.size()) + ".html";
    const Cli r = run_cli("refine --quiet --model " + dir + "/city.city.jsonl --cloud " + dir + "/cloud.ply --out " +
                              dir + "/out" + std::to_string(pages.size()) + ".city.jsonl --jobs " +
                              std::to_string(jobs) + " --html " + page,
                          dir);
    ASSERT_EQ(r.exit, 0) << r.err;
    pages.push_back(cli_fixtures::slurp(page));
    EXPECT_TRUE(pages.back() == pages.front()) << "--jobs " << jobs << " wrote another page";
  }
  // In file order: each id's first mention follows the previous one's.
  std::size_t at = 0;
  for (const auto& b : bs) {
    const std::size_t found = pages.front().find(b.id, at);
    ASSERT_NE(found, std::string::npos) << b.id;
    at = found;
  }
}

// The hook is told each building's place in the file, once for each, whatever the threads.
TEST(CityFile, HookSeesEveryBuildingOnceWithItsIndex) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street(
      {BuildingType::Gable, BuildingType::Shed, BuildingType::Hip, BuildingType::Gable}, 33, 3000, 3, cloud);
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  std::mutex m;
  std::map<std::size_t, std::string> seen;
  CityRefineOptions o;
  o.jobs = 3;
  o.on_building = [&](std::size_t index, const Mesh& model, const CityBuildingOutcome*, const RefineResult*,
                      const PointCloud*) {
    const std::lock_guard<std::mutex> lock(m);
    EXPECT_TRUE(seen.emplace(index, model.id).second) << index;
  };
  refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, o);
  ASSERT_EQ(seen.size(), bs.size());
  for (std::size_t i = 0; i < bs.size(); ++i) EXPECT_EQ(seen[i], bs[i].id);
}
