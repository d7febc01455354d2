// Bad input to `lodrefine synth`, above all `--rescan` (a dev tile scanned again by the van):
// links planted in the output, hostile meta.json, buildings of kilometres, van options that would
// cast billions of rays (issue 47). Each refusal is one line, exit 2, with nothing written.
#include <gtest/gtest.h>

#include <sys/stat.h>

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
