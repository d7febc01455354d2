// Bad input to `lodrefine synth`, above all `--rescan` (a dev tile scanned again by the van):
// links planted in the output, hostile meta.json, buildings of kilometres, van options that would
// cast billions of rays (issue 47). Each refusal is one line, exit 2, with nothing written.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "support/bad_input_fixtures.h"
#include "support/rescan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

namespace {

// A dev tile in dir/tile (rescan_fixtures: B among its neighbours in dir/city.json) with meta's
// entry `building`; returns the arguments of a rescan into dir/<out>.
std::string rescan_args(const std::string& dir, const std::string& out,
                        const json& building = {{"id", "B"}, {"cityjson_id", "B"}, {"scanned_walls", {0}}}) {
  rescan_fixtures::write_tile(dir + "/in", building);
  return "synth --scanner van --rescan " + dir + "/in/tile --city " + dir + "/in/city.json --out " + dir + "/" + out;
}

bool is_link(const std::string& path) { return fs::is_symlink(fs::symlink_status(path)); }

// The peak resident memory (KB) of `lodrefine ARGS` (its own, by wait4), which must exit 0.
long peak_kb(const std::string& args) {
  const std::string cmd = "exec " + shell_quote(test_paths::lodrefine_binary()) + " " + args + " >/dev/null 2>&1";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int st = 0;
  struct rusage ru {};
  ::wait4(pid, &st, 0, &ru);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << args;
  return ru.ru_maxrss;
}

// Every folder below `dir` (itself included) that is empty.
std::vector<std::string> empty_folders(const std::string& dir) {
  std::vector<std::string> out;
  if (fs::is_directory(dir) && fs::is_empty(dir)) out.push_back(dir);
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_directory() && fs::is_empty(e.path())) out.push_back(e.path().string());
  return out;
}

mode_t mode_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? st.st_mode & 07777 : 0;
}

}  // namespace

// A link planted at an output file was followed: the file it named was overwritten with the
// model and made read-only (the copy took the input's permissions). It is replaced now; a
// linked output folder is refused before anything is written.
TEST(BadInputSynth, RescanReplacesALinkAtAnOutputAndRefusesALinkedFolder) {
  const std::string dir = temp_dir("synth_rescan_links");
  const std::string args = rescan_args(dir, "out");
  fs::permissions(dir + "/in/tile/models/B.obj", fs::perms::owner_read | fs::perms::group_read);
  write_text(dir + "/victim.txt", "victim\n");
  fs::create_directories(dir + "/out/models");
  fs::create_symlink(dir + "/victim.txt", dir + "/out/models/B.obj");
  const CliRun r = run_cli(args, dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(read_text(dir + "/victim.txt"), "victim\n");
  EXPECT_EQ(mode_of(dir + "/victim.txt"), mode_t(0644));
  EXPECT_FALSE(is_link(dir + "/out/models/B.obj"));
  EXPECT_EQ(read_text(dir + "/out/models/B.obj"), read_text(dir + "/in/tile/models/B.obj"));
  add_row("synth --rescan: out/models/<id>.obj a link to a file elsewhere", "the link replaced, the file kept", r.exit);
  for (const char* folder : {"truth", "clouds", "models"}) {
    fs::remove_all(dir + "/out2");
    fs::remove_all(dir + "/elsewhere");
    fs::create_directories(dir + "/out2");
    fs::create_directories(dir + "/elsewhere");
    write_text(dir + "/elsewhere/keep.txt", "keep\n");
    fs::create_directory_symlink(dir + "/elsewhere", dir + "/out2/" + folder);
    const CliRun linked = run_cli(rescan_args(dir, "out2"), dir);
    expect_one_error_line(linked, "is a symbolic link");
    EXPECT_EQ(files_in(dir + "/elsewhere"), std::vector<std::string>{"keep.txt"}) << folder;
    EXPECT_EQ(files_in(dir + "/out2"), std::vector<std::string>{folder}) << "nothing written beside it";
  }
  add_row("synth --rescan: out/truth (clouds, models) a link to a folder", "refused, nothing written", 2);
}

// The same rule for the generated buildings: a building folder planted as a link is refused, a
// link at a building's file or at the tile is replaced.
TEST(BadInputSynth, SynthRefusesALinkedBuildingFolderAndReplacesLinkedFiles) {
  const std::string dir = temp_dir("synth_links");
  fs::create_directories(dir + "/elsewhere");
  fs::create_directories(dir + "/out");
  fs::create_directory_symlink(dir + "/elsewhere", dir + "/out/synth_flat_0001");
  const CliRun r = run_cli("synth --type flat --out " + dir + "/out --points 500", dir);
  expect_one_error_line(r, "out/synth_flat_0001: is a symbolic link");
  EXPECT_TRUE(files_in(dir + "/elsewhere").empty());
  // The second building's folder a link: refused before the first was made (and printed).
  fs::rename(dir + "/out/synth_flat_0001", dir + "/out/synth_gable_0001");
  const CliRun second = run_cli("synth --type all --out " + dir + "/out --points 500", dir);
  expect_one_error_line(second, "out/synth_gable_0001: is a symbolic link");
  EXPECT_EQ(second.out, "") << "nothing said written";
  EXPECT_EQ(files_in(dir + "/out"), std::vector<std::string>{"synth_gable_0001"});
  fs::rename(dir + "/out/synth_gable_0001", dir + "/out/synth_flat_0001");
  write_text(dir + "/victim.txt", "victim\n");
  fs::create_symlink(dir + "/victim.txt", dir + "/tile.ply");
  const CliRun tile =
      run_cli("synth --quiet --count 2 --points 500 --out " + dir + "/out --tile " + dir + "/tile.ply", dir);
  expect_one_error_line(tile, "is a symbolic link");
  EXPECT_TRUE(is_link(dir + "/tile.ply")) << "the tile untouched";
  fs::remove(dir + "/out/synth_flat_0001");
  fs::create_directories(dir + "/out/synth_flat_0001");
  fs::create_symlink(dir + "/victim.txt", dir + "/out/synth_flat_0001/truth.obj");
  const CliRun ok =
      run_cli("synth --quiet --count 2 --points 500 --out " + dir + "/out --tile " + dir + "/tile.ply", dir);
  ASSERT_EQ(ok.exit, 0) << ok.err;
  EXPECT_EQ(read_text(dir + "/victim.txt"), "victim\n");
  EXPECT_FALSE(is_link(dir + "/out/synth_flat_0001/truth.obj"));
  EXPECT_FALSE(is_link(dir + "/tile.ply"));
  add_row("synth: a building folder a link; a link at a file or the tile", "folder refused; links replaced", r.exit);
}

// --van-rate 1000 --van-speed 5 --van-step 0.01 --van-drives 8, each within its range, grew past
// 1 GB towards tens of GB: the ray count is bounded and refused before anything is made.
TEST(BadInputSynth, AVanOfTooManyRaysIsRefusedUpFront) {
  const std::string dir = temp_dir("synth_van_rays");
  const std::string van = " --van-rate 1000 --van-speed 5 --van-step 0.01 --van-drives 8 --van-range 1000";
  for (const std::string& args :
       {"synth --scanner van --type flat --out " + dir + "/out" + van, rescan_args(dir, "out") + van}) {
#if defined(__SANITIZE_ADDRESS__)  // ASan reserves terabytes of address space: ulimit -v does not apply
    const CliRun r = run_cli(args, dir, 60);
#else
    const CliRun r = run_limited(2000000, args, dir);  // 2 GB: the unbounded scan runs out of memory at once
#endif
    EXPECT_EQ(r.exit, 2) << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find("the van would cast 1248.6 M rays, more than the 10 M a building's scan may"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir + "/out"));
  }
  add_row("synth --scanner van: 1000 Hz, 5 m/s, 0.01 deg, 8 drives", "refused up front: 1,248.6 M rays", 2);
}

// meta.json's buildings, hostile: a wall listed 200,000 times (90-140 s, 680 MB), a stray vertex
// 50 km away (the van drove it: killed at 60 s), cityjson_id 5 (the JSON library's message), a
// missing truth and an id of 300 bytes (clean errors, but out/{clouds,models,truth} left).
TEST(BadInputSynth, RescanOfAHostileTileIsBoundedAndLeavesNothing) {
  const std::string dir = temp_dir("synth_rescan_meta");
  const CliRun once = run_cli(rescan_args(dir, "once"), dir);
  ASSERT_EQ(once.exit, 0) << once.err;
  const CliRun again = run_cli(
      rescan_args(dir, "again", {{"id", "B"}, {"cityjson_id", "B"}, {"scanned_walls", std::vector<int>(200000, 0)}}),
      dir, 60);
  ASSERT_EQ(again.exit, 0) << again.err;
  EXPECT_TRUE(read_text(dir + "/again/tile.ply") == read_text(dir + "/once/tile.ply")) << "a wall again adds nothing";
  add_row("synth --rescan: one wall listed 200,000 times", "merged: the same cloud", again.exit);
  // Without cityjson_id the building's own city copy stood in its street: found by where it stands.
  const CliRun unnamed = run_cli(rescan_args(dir, "unnamed", {{"id", "B"}, {"scanned_walls", {0}}}), dir);
  ASSERT_EQ(unnamed.exit, 0) << unnamed.err;
  EXPECT_TRUE(read_text(dir + "/unnamed/tile.ply") == read_text(dir + "/once/tile.ply")) << "the copy kept out";
  add_row("synth --rescan --city: no cityjson_id", "the building's copy found: the same cloud", unnamed.exit);
  struct Case {
    std::string what, says;
    json building;
    std::string truth = rescan_fixtures::box_obj_text(0, 0);
  };
  const std::string stray = "v " + std::to_string(rescan_fixtures::kTileOrigin.x() + 50000) + " 447000 0\nf 1 5 9\n";
  const std::vector<Case> cases = {
      {"a stray vertex 50 km away",
       "truth/B.obj: spans 50 km, more than a building can (5 km)",
       {{"id", "B"}, {"scanned_walls", {0}}},
       rescan_fixtures::box_obj_text(0, 0, stray)},
      {"cityjson_id 5", "building \"B\": cityjson_id is no string", {{"id", "B"}, {"cityjson_id", 5}}},
      {"a missing truth", "truth/B.obj", {{"id", "B"}}, ""},
      {"an id of 300 bytes", "a building without a safe id", {{"id", std::string(300, 'a')}}}};
  for (const Case& c : cases) {
    const std::string args = rescan_args(dir, "out", c.building);
    if (c.truth.empty()) fs::remove(dir + "/in/tile/truth/B.obj");
    else write_text(dir + "/in/tile/truth/B.obj", c.truth);
    const CliRun r = run_cli(args, dir, 30);
    expect_one_error_line(r, c.says);
    EXPECT_LT(r.seconds, 5.0) << c.what;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c.what;
    add_row("synth --rescan: " + c.what, "one line, nothing written", r.exit);
  }
}

// A face of 60,000 vertices in a truth or in a --city neighbour made every van ray slow; refine
// refuses such models (size_problem: faces of 1,000 vertices, 20,000 corners). So does the
// rescan now, naming the file (and the city's building), before anything is written.
TEST(BadInputSynth, RescanRefusesAModelOrNeighbourBeyondRefinesBounds) {
  const std::string dir = temp_dir("synth_rescan_huge_face");
  const std::string args = rescan_args(dir, "out");
  write_text(dir + "/in/tile/truth/B.obj",
             rescan_fixtures::box_obj_text(0, 0, rescan_fixtures::circle_face_obj(1001, 9)));
  const CliRun truth = run_cli(args, dir, 60);
  expect_one_error_line(truth, "truth/B.obj: face 6 has 1001 vertices, more than 1000 (LoD2 faces have tens)");
  EXPECT_FALSE(fs::exists(dir + "/out"));
  add_row("synth --rescan: a truth face of 1,001 vertices", "refused as refine does", truth.exit);
  rescan_args(dir, "out");  // the tile as it was; A, B's neighbour, gets the face
  json city = json::parse(rescan_fixtures::terrace_city());
  json& a = city["CityObjects"]["A"]["geometry"][0];
  json ring = json::array();
  for (int k = 0; k < 1001; ++k) {
    const double t = 2 * M_PI * k / 1001;
    ring.push_back(city["vertices"].size());
    city["vertices"].push_back(
        {std::llround((-6 + 3 * std::cos(t)) * 1000), std::llround((4 + 3 * std::sin(t)) * 1000), 3000});
  }
  a["boundaries"][0].push_back({ring});
  a["semantics"]["values"][0].push_back(1);
  write_text(dir + "/in/city.json", city.dump());
  const CliRun neighbour = run_cli(args, dir, 60);
  expect_one_error_line(neighbour, "city.json: building \"A\": face 6 has 1001 vertices, more than 1000");
  EXPECT_FALSE(fs::exists(dir + "/out"));
  add_row("synth --rescan --city: a neighbour's face of 1,001 vertices", "refused, naming the building",
          neighbour.exit);
}

// Neighbours each within those bounds but stacked by the dozen at one spot made the van's scene,
// built for every scanned building, grow without end: a street holds 1,000,000 face corners at
// most (53 buildings of 19,024 here, beside A and C: 1,008,320), refused naming the scanned building.
TEST(BadInputSynth, RescanRefusesAStreetOfMoreThanAMillionCorners) {
  const std::string dir = temp_dir("synth_rescan_huge_street");
  const std::string args = rescan_args(dir, "out");
  json city = json::parse(rescan_fixtures::terrace_city());
  json shell = city["CityObjects"]["A"]["geometry"][0]["boundaries"][0];
  json values = city["CityObjects"]["A"]["geometry"][0]["semantics"]["values"][0];
  for (int ring = 0; ring < 19; ++ring) {  // 19 rings of 1,000 vertices, shared by every copy
    json r = json::array();
    for (int k = 0; k < 1000; ++k) {
      const double t = 2 * M_PI * k / 1000;
      r.push_back(city["vertices"].size());
      city["vertices"].push_back(
          {std::llround((-6 + 3 * std::cos(t)) * 1000), std::llround((4 + 3 * std::sin(t)) * 1000), 100 + 300 * ring});
    }
    shell.push_back({r});
    values.push_back(2);
  }
  for (int copy = 0; copy < 53; ++copy) {
    json b = city["CityObjects"]["A"];
    b["geometry"][0]["boundaries"][0] = shell;
    b["geometry"][0]["semantics"]["values"][0] = values;
    city["CityObjects"]["N" + std::to_string(copy)] = b;
  }
  write_text(dir + "/in/city.json", city.dump());
  const CliRun r = run_cli(args, dir, 60);
  expect_one_error_line(r,
                        "meta.json: building \"B\": the --city buildings within 40 m of it hold 1008320 face "
                        "corners, more than 1000000");
  EXPECT_FALSE(fs::exists(dir + "/out"));
  add_row("synth --rescan --city: 53 neighbours of 19,024 corners at one spot", "refused, naming the building", r.exit);
}

// `synth --tile X/synth_flat_0001/truth.obj --out X` renamed the tile over the truth it had just
// written; a rescan's --city file where a truth goes was overwritten by it. Both are refused up
// front, as crop refuses a tile where a building's cloud goes.
TEST(BadInputSynth, AnOutputOverAnInputOrAnotherOutputIsRefused) {
  const std::string dir = temp_dir("synth_overwrites");
  const std::string synth = "synth --quiet --count 2 --points 500 --out " + dir + "/X --tile ";
  ASSERT_EQ(run_cli(synth + dir + "/tile.ply", dir).exit, 0);
  const std::string truth = read_text(dir + "/X/synth_flat_0001/truth.obj");
  for (const std::string& tile : {dir + "/X/synth_flat_0001/truth.obj", dir + "/X/synth_gable_0002"}) {
    const CliRun r = run_cli(synth + tile, dir);
    expect_one_error_line(r, tile + ": the tile would be overwritten by \"synth_");
  }
  EXPECT_EQ(read_text(dir + "/X/synth_flat_0001/truth.obj"), truth);
  add_row("synth --tile X/synth_flat_0001/truth.obj --out X", "refused: the tile is a building's file", 2);
  const std::string args = rescan_args(dir, "out");
  fs::create_directories(dir + "/out/truth");
  fs::rename(dir + "/in/city.json", dir + "/out/truth/B.obj");
  const std::string city = read_text(dir + "/out/truth/B.obj");
  const std::string moved =
      args.substr(0, args.find(" --city ")) + " --city " + dir + "/out/truth/B.obj --out " + dir + "/out";
  const CliRun r = run_cli(moved, dir);
  expect_one_error_line(r, "out/truth/B.obj: the --city file would be overwritten by the rescan's truth of \"B\"");
  EXPECT_EQ(read_text(dir + "/out/truth/B.obj"), city);
  EXPECT_EQ(files_in(dir + "/out/truth"), std::vector<std::string>{"B.obj"});
  add_row("synth --rescan --city out/truth/B.obj", "refused: the city is where a truth goes", r.exit);
}

// A 100 kB cityjson_id gave a 100 kB error line: every id quoted is cut (shown_id).
TEST(BadInputSynth, AHugeIdIsCutInTheMessage) {
  const std::string dir = temp_dir("synth_huge_id");
  const std::string id(100000, 'x');
  const CliRun r = run_cli(rescan_args(dir, "out", {{"id", "B"}, {"cityjson_id", id}, {"scanned_walls", {0}}}), dir);
  expect_one_error_line(r, "cityjson_id \"" + std::string(kMaxShownId, 'x') + "...\" (100000 bytes) is no building of");
  EXPECT_LT(r.err.size(), 500u);
  EXPECT_FALSE(fs::exists(dir + "/out"));
  add_row("synth --rescan: cityjson_id of 100 kB", "one line of < 500 bytes, the id cut", r.exit);
}

#if !defined(__SANITIZE_ADDRESS__)  // ASan's quarantine keeps what is freed: its peak grows with the run
// --rescan held the whole tile's cloud until the end (223 MB for 40 buildings): the tile is
// streamed now, one building's crop in memory at a time. 12 buildings need no more than 3.
TEST(BadInputSynth, RescanMemoryDoesNotGrowWithTheTile) {
  const std::string dir = temp_dir("synth_rescan_memory");
  long peak[2] = {0, 0};
  for (int k : {0, 1}) {
    const std::string tile = rescan_fixtures::write_row_tile(dir + "/in" + std::to_string(k), k == 0 ? 3 : 12);
    peak[k] = peak_kb("synth --scanner van --rescan " + tile + " --out " + dir + "/out" + std::to_string(k));
  }
  EXPECT_LT(peak[1] - peak[0], 12000) << "3 buildings: " << peak[0] << " KB, 12: " << peak[1] << " KB";
  add_row("synth --rescan: 3 and 12 buildings",
          "peak " + std::to_string(peak[0] / 1024) + " and " + std::to_string(peak[1] / 1024) + " MB", 0);
}
#endif

// A --rescan killed while the van scanned left out/{clouds,models,truth} empty: a folder is made
// when its first file is written now.
TEST(BadInputSynth, AKilledRescanLeavesNoEmptyFolders) {
  const std::string dir = temp_dir("synth_rescan_killed");
  const std::string tile = rescan_fixtures::write_row_tile(dir + "/in", 2);
  const std::string cmd = "timeout -s KILL 1 " + shell_quote(test_paths::lodrefine_binary()) +
                          " synth --scanner van --rescan " + tile + " --van-drives 8 --van-rate 200 --out " + dir +
                          "/out >/dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 137) << "killed while the van scans (the first building takes 5 s)";
  EXPECT_EQ(empty_folders(dir + "/out"), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(dir + "/out")) << "nothing written before the first building's scan ends";
  add_row("synth --rescan killed (SIGKILL) during the first scan", "no folders left", 137);
}
