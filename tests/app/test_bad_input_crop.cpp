// Bad input to `lodrefine crop` (a tile cut into a run folder of buildings): names that would
// leave --out, two models for one building, symbolic links, folders of other models, a write
// failing half-way (issue 15, the attack review of 2026-12-03, issue 36).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "lodrefine/base/files.h"
#include "support/bad_input_fixtures.h"
#include "support/test_paths.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

// ---------------------------------------------------------------------------------------------
// Untrusted ids, paths and files (issue 15): outputs stay in the output folder, never replace an
// input or a file already there, temporaries are ours, and every building is accounted for.

// A model named `...obj` (stem "..") must not make crop write into the parent of --out.
TEST(BadInputFiles, CropKeepsAModelNamedDotDotInsideOut) {
  const std::string dir = temp_dir("crop_dotdot");
  fs::create_directories(dir + "/models");
  write_text(dir + "/models/...obj", valid_model());
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"models", "run", "tile.ply"})) << "wrote beside --out";
  const auto folders = files_in(dir + "/run");
  ASSERT_EQ(folders.size(), 1u);
  EXPECT_TRUE(is_safe_name(folders[0])) << folders[0];
  EXPECT_EQ(files_in(dir + "/run/" + folders[0]), (std::vector<std::string>{"cloud.ply", "coarse.obj"}));
  add_row("crop: model `...obj` (stem `..`)", "stays in --out, folder " + folders[0], r.exit);
}

// After an unreadable model is skipped, every building still gets its own model (the kept list
// and the model list used to drift apart by one).
TEST(BadInputFiles, CropPairsEachBuildingWithItsOwnModelAfterASkip) {
  const std::string dir = temp_dir("crop_skip");
  fs::create_directories(dir + "/models");
  write_text(dir + "/models/a.obj", "v 0 0\n");  // unreadable: skipped with a warning
  std::string b = valid_model(), c = valid_model();
  b.replace(b.find("o bldg_0001"), 11, "o B");
  c.replace(c.find("o bldg_0001"), 11, "o C");
  write_text(dir + "/models/b.obj", b);
  write_text(dir + "/models/c.obj", c);
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_NE(r.err.find("skipping \"a\""), std::string::npos) << r.err;
  EXPECT_EQ(files_in(dir + "/run"), (std::vector<std::string>{"b", "c"}));
  EXPECT_EQ(read_text(dir + "/run/b/coarse.obj"), b);
  EXPECT_EQ(read_text(dir + "/run/c/coarse.obj"), c);
  add_row("crop: first model unreadable", "skipped; the others keep their own models", r.exit);
}

// A.obj and A/coarse.obj are two models for one building: refused, nothing written.
TEST(BadInputFiles, CropRefusesTwoModelsForOneBuilding) {
  const std::string dir = temp_dir("crop_twice");
  fs::create_directories(dir + "/models/A");
  write_text(dir + "/models/A.obj", valid_model());
  write_text(dir + "/models/A/coarse.obj", box_obj({0, 1, 2, 3, 4}));
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  expect_one_error_line(r, "two models for building \"A\"");
  EXPECT_FALSE(fs::exists(dir + "/run"));
  // The tile as an output of the crop (the run folder holding it) is refused too, the tile kept.
  fs::remove_all(dir + "/models/A");
  fs::create_directories(dir + "/run/A");
  write_text(dir + "/run/A/cloud.ply", valid_cloud());
  const CliRun t =
      run_cli("crop --tile " + dir + "/run/A/cloud.ply --models " + dir + "/models --out " + dir + "/run", dir);
  expect_one_error_line(t, "the tile would be overwritten");
  EXPECT_EQ(read_text(dir + "/run/A/cloud.ply"), valid_cloud());
  add_row("crop: A.obj and A/coarse.obj; tile inside --out", "refused: two models / tile would be overwritten", r.exit);
}

// A write that fails half-way (here a file size limit, as a full disk would) leaves no half run
// folder: crop and convert remove what they created.
TEST(BadInputFiles, FailedWriteLeavesNoHalfRunFolder) {
  const std::string dir = temp_dir("full_disk");
  fs::create_directories(dir + "/models");
  for (const char* id : {"a", "b", "c"}) write_text(dir + "/models/" + id + ".obj", valid_model());
  write_text(dir + "/tile.ply", valid_cloud());
  write_text(dir + "/city.json", box_city({"a", "b", "c"}));
  // SIGXFSZ ignored: a write beyond 64 KB fails with EFBIG, as on a full disk.
  auto limited = [&](const std::string& args) {
    return std::system(("cd " + shell_quote(dir) + " && sh -c \"trap '' XFSZ; ulimit -f 64; exec " +
                        shell_quote(test_paths::lodrefine_binary()) + " " + args + "\" > /dev/null 2> err.txt")
                           .c_str());
  };
  EXPECT_NE(limited("crop --tile tile.ply --models models --out run"), 0);
  EXPECT_NE(read_text(dir + "/err.txt").find("lodrefine: error: "), std::string::npos) << read_text(dir + "/err.txt");
  EXPECT_FALSE(fs::exists(dir + "/run")) << "a half run folder is left";
  // convert: a model too big for the limit (many faces) after small ones.
  json doc = json::parse(box_city({"a", "b", "c"}));
  const json box = doc["CityObjects"]["c"]["geometry"][0]["boundaries"];
  json& big = doc["CityObjects"]["c"]["geometry"][0]["boundaries"];
  for (int k = 0; k < 800; ++k) big.insert(big.end(), box.begin(), box.end());  // ~100 KB of faces
  write_text(dir + "/city.json", doc.dump());
  EXPECT_NE(limited("convert --cityjson city.json --out-dir objs"), 0);
  EXPECT_FALSE(fs::exists(dir + "/objs")) << "half the models are left";
  EXPECT_TRUE(temp_leftovers(dir).empty());
  add_row("crop / convert hitting a full disk (file size limit)", "nothing half written left", 1);
}

// ---------------------------------------------------------------------------------------------
// Found by an attacker's review (2026-12-03): before its fix each input below crashed, hung,
// wrote outside --out, filled the memory, or was written back as garbage.

// With --out the --models folder, a building folder that is a symbolic link took crop's files
// wherever it pointed.
TEST(BadInputAttack, CropDoesNotWriteThroughASymlinkedBuildingFolder) {
  const std::string dir = temp_dir("attack_symlink");
  fs::create_directories(dir + "/run");
  fs::create_directories(dir + "/outside");
  write_text(dir + "/run/Y.obj", valid_model());
  fs::create_directory_symlink(dir + "/outside", dir + "/run/Y");
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r =
      run_cli("crop --quiet --tile " + dir + "/tile.ply --models " + dir + "/run --out " + dir + "/run", dir);
  expect_one_error_line(r, "is a symbolic link");
  EXPECT_TRUE(files_in(dir + "/outside").empty());
  add_row("crop: a building folder in --out is a symlink", "refused; nothing written through it", r.exit);
}

// Third pass (issue 36).

// With --out the --models folder, the hashed folder of `a b.obj` can be where the model
// `a_b--<hash>/coarse.obj` lies (that one then renamed): its model was replaced by the other's.
TEST(BadInputFiles, CropNeverWritesOverAnotherModel) {
  const std::string dir = temp_dir("crop_over_model");
  const std::string run = dir + "/run";
  fs::create_directories(run);
  write_text(run + "/a b.obj", valid_model());
  const std::string folder = safe_name("a b");
  ASSERT_NE(folder, "a b");
  fs::create_directories(run + "/" + folder);
  const std::string victim = "# the other building\n" + valid_model();
  write_text(run + "/" + folder + "/coarse.obj", victim);
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --quiet --tile " + dir + "/tile.ply --models " + run + " --out " + run, dir);
  expect_one_error_line(r, "would be overwritten by \"a b\"'s");
  EXPECT_EQ(read_text(run + "/" + folder + "/coarse.obj"), victim);
  EXPECT_FALSE(fs::exists(run + "/" + folder + "/cloud.ply"));
  add_row("crop --models R --out R where a hashed folder is another model's", "refused, nothing written", r.exit);
}

// Fourth pass (issue 47).

// Issue 47: crop cut the tiles of a folder but for those it could not read, without a word.
TEST(BadInputAttack, CropRefusesATileFolderWithATileItCannotRead) {
  const std::string dir = temp_dir("attack_tiles_crop");
  fs::create_directories(dir + "/models");
  write_text(dir + "/models/b.obj", valid_model());
  const CliRun r = expect_bad_tiles_refused("crop --quiet --models " + dir + "/models --out " + dir + "/run --tile ",
                                            dir, {dir + "/run"});
  EXPECT_NE(r.out.find(std::to_string(wall_scan().size()) + " tile points, 1 buildings cropped"), std::string::npos)
      << r.out;
  add_row("crop --tile tiles/ with a 0-byte, dangling, folder or truncated c.laz", "refused naming it", 2);
}
