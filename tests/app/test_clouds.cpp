// A survey delivered as many files (issue 39, item 4): `refine`, `crop` and `eval` take --cloud
// (crop: --tile) several times, or a folder, and read the files as one cloud: the outputs are
// those of the one file holding their points in that order; the report names every file, and a
// file of another area gets its own warning; a list that cannot be read is refused in one line
// before anything is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "lodrefine/base/geometry.h"
#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"
#include "support/cli_fixtures.h"
#include "support/io_fixtures.h"

using namespace lodrefine;
namespace fs = std::filesystem;
using json = nlohmann::json;
using cli_fixtures::run_cli;
using cli_fixtures::slurp;

namespace {

// A generated building the defaults refine, its model written as DIR/model.obj.
SynthBuilding building(const std::string& dir) {
  SynthOptions o;
  o.target_points = 8000;
  o.scanned_facades = 2;
  const SynthBuilding b = make_building(BuildingType::Gable, 5, o);
  write_obj(dir + "/model.obj", b.coarse);
  return b;
}

// The one error line of a refused run, with the exit code and nothing on stdout.
void expect_refused(const cli_fixtures::Cli& r, const std::string& line) {
  EXPECT_EQ(r.exit, 2) << r.out << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "lodrefine: error: " + line + "\n");
}

}  // namespace

// Two parts of a drive (a PLY and a LAS) and a folder of tiles cut through the building: the
// refined model is byte for byte that of the merged file; the report lists each file.
TEST(Clouds, RefineOfACloudInSeveralFilesWritesTheMergedFilesModel) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_clouds");
  const SynthBuilding b = building(dir);
  PointCloud first;
  const std::size_t half = b.cloud.points.size() * 2 / 5;
  first.points.assign(b.cloud.points.begin(), b.cloud.points.begin() + std::ptrdiff_t(half));
  PointCloud second;
  second.points.assign(b.cloud.points.begin() + std::ptrdiff_t(half), b.cloud.points.end());
  write_ply(dir + "/first.ply", first);
  LasWriteOptions las;
  las.offset = Vec3(85000, 447000, 0);
  write_las(dir + "/second.las", second, {}, las);
  PointCloud merged = first;  // the LAS's millimetre grid as read back
  for (const Vec3& p : read_cloud(dir + "/second.las").points) merged.points.push_back(p);
  write_ply(dir + "/merged.ply", merged);
  const std::string model = " --model " + dir + "/model.obj";
  auto r = run_cli("refine" + model + " --cloud " + dir + "/merged.ply --out " + dir + "/merged.obj --report " + dir +
                       "/merged.json",
                   dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  ASSERT_NE(r.out.find(": refined ("), std::string::npos) << r.out;
  r = run_cli("refine" + model + " --cloud " + dir + "/first.ply --cloud " + dir + "/second.las --out " + dir +
                  "/two.obj --report " + dir + "/two.json",
              dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  EXPECT_TRUE(slurp(dir + "/two.obj") == slurp(dir + "/merged.obj"));
  const json one = json::parse(slurp(dir + "/merged.json")), two = json::parse(slurp(dir + "/two.json"));
  EXPECT_EQ(one["cloud"]["path"], dir + "/merged.ply");
  EXPECT_EQ(two["cloud"]["points"], one["cloud"]["points"]);
  EXPECT_EQ(two["cloud"]["points_near_model"], one["cloud"]["points_near_model"]);
  EXPECT_FALSE(two["cloud"].contains("path"));
  ASSERT_EQ(two["cloud"]["files"].size(), 2u);
  EXPECT_EQ(two["cloud"]["files"][0]["path"], dir + "/first.ply");
  EXPECT_EQ(two["cloud"]["files"][0]["points"], first.points.size());
  EXPECT_EQ(two["cloud"]["files"][1]["path"], dir + "/second.las");
  EXPECT_EQ(two["cloud"]["files"][1]["points"], second.points.size());
  const Eigen::AlignedBox3d box = bounding_box(first.points);
  EXPECT_EQ(two["cloud"]["files"][0]["bounds"]["min"], json({box.min().x(), box.min().y(), box.min().z()}));
  EXPECT_EQ(two["cloud"]["files"][0]["bounds"]["max"], json({box.max().x(), box.max().y(), box.max().z()}));
  EXPECT_EQ(two["outcome"], one["outcome"]);
  EXPECT_EQ(two["facades"], one["facades"]);

  // A folder of tiles (and a file that is no cloud), read by name: as their merged file.
  const std::vector<PointCloud> parts = fixtures::split_by_x(b.cloud, 3);
  const std::vector<std::string> tiles = fixtures::write_tiles(dir + "/tiles", parts);
  std::ofstream(dir + "/tiles/index.txt") << "three tiles\n";
  write_ply(dir + "/tiles.ply", fixtures::concatenated(parts));
  r = run_cli("refine" + model + " --cloud " + dir + "/tiles.ply --out " + dir + "/tiles_merged.obj", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  ASSERT_NE(r.out.find(": refined ("), std::string::npos) << r.out;
  r = run_cli(
      "refine" + model + " --cloud " + dir + "/tiles --out " + dir + "/tiles.obj --report " + dir + "/tiles.json", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_TRUE(slurp(dir + "/tiles.obj") == slurp(dir + "/tiles_merged.obj"));
  const json report = json::parse(slurp(dir + "/tiles.json"));
  ASSERT_EQ(report["cloud"]["files"].size(), 4u);  // the three tiles read, then the file skipped
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(report["cloud"]["files"][k]["path"], tiles[k]);
    EXPECT_EQ(report["cloud"]["files"][k]["points"], parts[k].points.size());
  }
  EXPECT_EQ(report["cloud"]["files"][3]["path"], dir + "/tiles/index.txt");
  EXPECT_NE(report["cloud"]["files"][3]["skipped"].get<std::string>().find("not a PLY, LAS or LAZ cloud"),
            std::string::npos);
  EXPECT_EQ(r.out.rfind("skipped 1 entry of the cloud folders, no cloud files: " + dir + "/tiles/index.txt (", 0), 0u)
      << r.out;
}

// A file of another area among the clouds: named on the outcome line and in the report's
// warnings; the building is refined on the others' points as without it.
TEST(Clouds, AFileOfAnotherAreaIsNamedInTheWarning) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_clouds");
  const SynthBuilding b = building(dir);
  PointCloud far = b.cloud;
  for (auto& p : far.points) p.x() += 10000.0;  // the neighbouring tile, or another false easting
  write_ply(dir + "/near.ply", b.cloud);
  write_ply(dir + "/far.ply", far);
  auto r =
      run_cli("refine --model " + dir + "/model.obj --cloud " + dir + "/near.ply --out " + dir + "/alone.obj", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  r = run_cli("refine --model " + dir + "/model.obj --cloud " + dir + "/near.ply --cloud " + dir + "/far.ply --out " +
                  dir + "/r.obj --report " + dir + "/r.json",
              dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("; warning: " + dir + "/far.ply: cloud x 94"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("warning: " + dir + "/near.ply"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  const json report = json::parse(slurp(dir + "/r.json"));
  ASSERT_EQ(report["warnings"].size(), 1u);
  EXPECT_EQ(report["warnings"][0].get<std::string>().rfind(dir + "/far.ply: cloud x 94", 0), 0u);
  EXPECT_NE(report["warnings"][0].get<std::string>().find("does not overlap the model x 84"), std::string::npos);
  EXPECT_EQ(report["cloud"]["files"][1]["points"], far.points.size());
  EXPECT_EQ(report["outcome"], "refined");
}

// Lists that cannot be read are refused in one line before anything is written, by refine,
// crop and eval alike; no output replaces a cloud file, also one found in a folder.
TEST(Clouds, BadCloudListsAreRefusedInOneLine) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_clouds");
  const SynthBuilding b = building(dir);
  const std::vector<std::string> tiles = fixtures::write_tiles(dir + "/tiles", fixtures::split_by_x(b.cloud, 2));
  fs::create_directories(dir + "/empty");
  fs::create_directories(dir + "/models");
  write_obj(dir + "/models/b.obj", b.coarse);
  const std::string refine = "refine --model " + dir + "/model.obj --out " + dir + "/r.obj";
  expect_refused(run_cli(refine + " --cloud " + dir + "/empty", dir),
                 dir + "/empty: no PLY, LAS or LAZ cloud in the --cloud folder (empty)");
  expect_refused(run_cli(refine + " --cloud " + tiles[1] + " --cloud " + dir + "/tiles", dir),
                 tiles[1] + ": the same file as " + tiles[1] + "; --cloud may name each cloud file once");
  const cli_fixtures::Cli obj = run_cli(refine + " --cloud " + dir + "/tiles --cloud " + dir + "/model.obj", dir);
  EXPECT_EQ(obj.exit, 2);
  EXPECT_EQ(obj.err.rfind("lodrefine: error: " + dir + "/model.obj: ", 0), 0u) << obj.err;
  EXPECT_EQ(std::count(obj.err.begin(), obj.err.end(), '\n'), 1) << obj.err;
  // --max-points bounds the files together.
  const std::size_t n = b.cloud.points.size();
  expect_refused(run_cli(refine + " --cloud " + dir + "/tiles --max-points " + std::to_string(n - 1), dir),
                 tiles[0] + " and 1 other cloud file: " + std::to_string(n) +
                     " points together, more than --max-points " + std::to_string(n - 1) +
                     "; cut a crop per building first (lodrefine crop)");
  expect_refused(run_cli(refine + " --cloud " + dir + "/tiles --report " + tiles[1], dir),
                 tiles[1] + ": --report is the --cloud file; it would be overwritten");
  EXPECT_FALSE(fs::exists(dir + "/r.obj"));
  expect_refused(
      run_cli("crop --quiet --tile " + dir + "/empty --models " + dir + "/models --out " + dir + "/run", dir),
      dir + "/empty: no PLY, LAS or LAZ cloud in the --tile folder (empty)");
  expect_refused(run_cli("crop --quiet --tile " + dir + "/tiles --tile " + tiles[0] + " --models " + dir +
                             "/models --out " + dir + "/run",
                         dir),
                 tiles[0] + ": the same file as " + tiles[0] + "; --tile may name each cloud file once");
  EXPECT_FALSE(fs::exists(dir + "/run"));
  expect_refused(run_cli("eval --original " + dir + "/model.obj --refined " + dir + "/model.obj --cloud " + dir +
                             "/tiles --json " + tiles[0],
                         dir),
                 tiles[0] + ": --json is the --cloud file; it would be overwritten");
}

// crop of a folder of tiles cuts the crops of their merged tile, byte for byte, and lists each
// tile; eval of a cloud in two files gives the merged file's figures.
TEST(Clouds, CropAndEvalReadTheFilesAsOne) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_clouds");
  const SynthBuilding b = building(dir);
  fs::create_directories(dir + "/models");
  write_obj(dir + "/models/b.obj", b.coarse);
  const std::vector<PointCloud> parts = fixtures::split_by_x(b.cloud, 3);
  const std::vector<std::string> tiles = fixtures::write_tiles(dir + "/tiles", parts);
  write_ply(dir + "/merged.ply", fixtures::concatenated(parts));
  auto r = run_cli("crop --quiet --tile " + dir + "/merged.ply --models " + dir + "/models --out " + dir + "/one", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  r = run_cli("crop --quiet --tile " + dir + "/tiles --models " + dir + "/models --out " + dir + "/three", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const std::string crop = slurp(dir + "/one/b/cloud.ply");
  EXPECT_GT(crop.size(), 1000u);
  EXPECT_TRUE(slurp(dir + "/three/b/cloud.ply") == crop);
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_NE(r.out.find("tile " + tiles[k] + ": " + std::to_string(parts[k].points.size()) + " points\n"),
              std::string::npos)
        << r.out;
  EXPECT_NE(r.out.find(std::to_string(b.cloud.points.size()) + " tile points, 1 buildings cropped"), std::string::npos)
      << r.out;
  // A tile of another area: a warning naming it; the crop is the same.
  PointCloud far = b.cloud;
  for (auto& p : far.points) p.y() += 10000.0;
  write_ply(dir + "/far.ply", far);
  r = run_cli("crop --quiet --tile " + dir + "/tiles --tile " + dir + "/far.ply --models " + dir + "/models --out " +
                  dir + "/four",
              dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.err.rfind("lodrefine: warning: " + dir + "/far.ply: cloud x ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("does not overlap the models x "), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(slurp(dir + "/four/b/cloud.ply") == crop);

  const std::string eval = "eval --original " + dir + "/model.obj --refined " + dir + "/model.obj";
  r = run_cli(eval + " --cloud " + dir + "/merged.ply --json " + dir + "/one.json", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  r = run_cli(eval + " --cloud " + tiles[0] + " --cloud " + dir + "/tiles/tile_01.ply --cloud " + tiles[2] +
                  " --json " + dir + "/three.json",
              dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  const std::string figures = slurp(dir + "/one.json");
  EXPECT_NE(figures.find("\"facade_points\""), std::string::npos) << figures.substr(0, 400);
  EXPECT_TRUE(slurp(dir + "/three.json") == figures);
}
