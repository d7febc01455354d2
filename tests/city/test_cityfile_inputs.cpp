// The inputs of a city refine: CityJSONSeq streamed through, a LAS tile with classes through the
// command line, ids unique in a sequence, a cloud in several files (CityJSON 1.x upgraded:
// test_cityjson_upgrade.cpp).
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

TEST(CityFile, CityJsonSeqStreamedThrough) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::Shed, BuildingType::Gable}, 31, 6000, 2, cloud);
  // One feature per building, each with its own vertices (as cjseq writes them).
  std::vector<json> lines;
  json header = synth_city({}, Vec3(93000, 436000, 0));
  lines.push_back(header);
  for (const auto& b : bs) {
    json one = synth_city({b}, Vec3(93000, 436000, 0));
    lines.push_back({{"type", "CityJSONFeature"},
                     {"id", b.id},
                     {"CityObjects", one["CityObjects"]},
                     {"vertices", one["vertices"]}});
  }
  std::string text;
  for (const auto& l : lines) text += l.dump() + "\n";
  write_file_atomic(dir + "/city.city.jsonl", text);
  write_ply(dir + "/cloud.ply", cloud);
  const CityRefineSummary s =
      refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, {});
  EXPECT_EQ(s.input_format, "CityJSONSeq 2.0");
  EXPECT_EQ(s.buildings, 3);
  EXPECT_EQ(s.untouched, 1);
  EXPECT_GE(s.refined, 1);
  EXPECT_EQ(s.refined + s.kept + s.kept_invalid + s.untouched, 3);
  std::ifstream in(dir + "/out.city.jsonl");
  std::vector<json> out;
  for (std::string l; std::getline(in, l);) out.push_back(json::parse(l));
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0], lines[0]);
  EXPECT_EQ(out[3], lines[3]);  // no cloud points: the feature exactly as read
  const CityJsonFile back = read_cityjson(dir + "/out.city.jsonl");
  ASSERT_EQ(back.buildings.size(), 3u);
  for (const auto& o : s.outcomes)
    for (const auto& b : back.buildings)
      if (b.mesh.id == o.id && o.outcome == Outcome::Refined) {
        EXPECT_EQ(geometry_problem(b.mesh), "") << b.mesh.id;
      }
  const std::string verdict = schema_verdict(dir + "/out.city.jsonl", true);
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
}

TEST(CityFile, LasTileWithClassesThroughTheCli) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::LShape}, 51, 6000, 2, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  // The same points as class 6, and as many class-1 points scattered through the buildings' boxes.
  PointCloud tile = cloud;
  std::vector<int> classes(cloud.points.size(), 6);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> jitter(-4.0, 4.0);
  for (const auto& p : cloud.points) {
    tile.points.push_back(p + Vec3(jitter(rng), jitter(rng), jitter(rng)));
    classes.push_back(1);
  }
  LasWriteOptions lo;
  lo.version_minor = 4, lo.point_format = 6, lo.scale = Vec3::Constant(1e-4), lo.offset = Vec3(93000, 436000, 0);
  write_las(dir + "/tile.las", tile, classes, lo);
  const Cli ply = run_cli("refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir +
                              "/a.city.json --report " + dir + "/a.json",
                          dir);
  const Cli las = run_cli("refine --model " + dir + "/city.json --cloud " + dir + "/tile.las --classes 6 --out " + dir +
                              "/b.city.json --report " + dir + "/b.json",
                          dir);
  ASSERT_EQ(ply.exit, 0) << ply.err;
  ASSERT_EQ(las.exit, 0) << las.err;
  const json a = load(dir + "/a.json"), b = load(dir + "/b.json");
  EXPECT_EQ(b["cloud_points"], cloud.points.size());
  ASSERT_EQ(a["outcomes"].size(), b["outcomes"].size());
  for (std::size_t i = 0; i < a["outcomes"].size(); ++i) {
    EXPECT_EQ(a["outcomes"][i]["outcome"], b["outcomes"][i]["outcome"]);
    EXPECT_EQ(a["outcomes"][i]["facades_moved"], b["outcomes"][i]["facades_moved"]);
  }
  EXPECT_GE(b["refined"].get<int>(), 1);
}

// Ids are unique in a CityJSONSeq as in a document: a second feature with an id already seen is
// refused in one line naming both, by the reader and by the city refine (both copies were
// refined and written).
TEST(CityFile, SequenceWithAnIdTwiceIsRefused) {
  const std::string dir = test_dir();
  PointCloud cloud;
  std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::Shed}, 35, 3000, 2, cloud);
  bs[1].id = bs[0].id;
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  const std::string says = "line 3: CityObject \"" + bs[0].id + "\" is in an earlier feature too";
  try {
    read_cityjson(dir + "/city.city.jsonl");
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
  try {
    refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, {});
    ADD_FAILURE() << "refined";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/out.city.jsonl"));
}

// Issue 39: a survey delivered as several files (two parts of a drive; tiles cut along x through
// the buildings, in a folder with a file that is no cloud) refines the city as the one file
// holding their points in that order: the same bytes out, CityJSON and CityJSONSeq; every file
// accounted for.
TEST(CityFile, CloudInSeveralFilesRefinesAsTheMergedFile) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Flat}, 11, 8000, 3, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  PointCloud first, second;  // a drive in two parts
  const std::size_t half = cloud.points.size() * 9 / 20;
  first.points.assign(cloud.points.begin(), cloud.points.begin() + std::ptrdiff_t(half));
  second.points.assign(cloud.points.begin() + std::ptrdiff_t(half), cloud.points.end());
  write_ply(dir + "/merged.ply", cloud);
  write_ply(dir + "/first.ply", first);
  write_ply(dir + "/second.ply", second);
  const CityRefineSummary one = refine_city(dir + "/city.json", {dir + "/merged.ply"}, dir + "/one.city.json", {}, {});
  const CityRefineSummary two =
      refine_city(dir + "/city.json", {dir + "/first.ply", dir + "/second.ply"}, dir + "/two.city.json", {}, {});
  EXPECT_GE(one.refined, 2);
  EXPECT_TRUE(cli_fixtures::slurp(dir + "/two.city.json") == cli_fixtures::slurp(dir + "/one.city.json"));
  ASSERT_EQ(two.outcomes.size(), one.outcomes.size());
  for (std::size_t i = 0; i < one.outcomes.size(); ++i) {
    EXPECT_EQ(two.outcomes[i].outcome, one.outcomes[i].outcome) << one.outcomes[i].id;
    EXPECT_EQ(two.outcomes[i].points, one.outcomes[i].points) << one.outcomes[i].id;
  }
  EXPECT_EQ(two.cloud_points, cloud.points.size());
  EXPECT_EQ(two.cropped_points, one.cropped_points);
  ASSERT_EQ(two.clouds.size(), 2u);
  EXPECT_EQ(two.clouds[0].path, dir + "/first.ply");
  EXPECT_EQ(two.clouds[0].points, first.points.size());
  EXPECT_EQ(two.clouds[1].path, dir + "/second.ply");
  EXPECT_EQ(two.clouds[1].points, second.points.size());
  EXPECT_TRUE(two.warnings.empty());

  // Tiles cut along x, each building's scan in two of them.
  const std::vector<PointCloud> parts = fixtures::split_by_x(cloud, 4);
  fixtures::write_tiles(dir + "/tiles", parts);
  write_file_atomic(dir + "/tiles/index.txt", "tile_00 tile_01 tile_02 tile_03\n");
  write_ply(dir + "/tiles.ply", fixtures::concatenated(parts));
  const std::vector<std::string> tiles = cloud_files({dir + "/tiles"});
  ASSERT_EQ(tiles.size(), 4u);
  for (const std::string name : {"city.json", "city.city.jsonl"}) {
    const std::string model = dir + "/" + name, merged = dir + "/tiles_" + name, split = dir + "/split_" + name;
    const CityRefineSummary m = refine_city(model, {dir + "/tiles.ply"}, merged, {}, {});
    const CityRefineSummary s = refine_city(model, tiles, split, {}, {});
    EXPECT_GE(m.refined, 2) << name;
    EXPECT_EQ(s.refined, m.refined) << name;
    EXPECT_TRUE(cli_fixtures::slurp(split) == cli_fixtures::slurp(merged)) << name;
    ASSERT_EQ(s.clouds.size(), 4u);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(s.clouds[k].points, parts[k].points.size()) << k;
  }
}

// A file of another area among the cloud files is named on its own line, in the summary, on
// stdout and in the report, and the buildings get the other files' points; when no file reaches
// the model the run is refused as with one file.
TEST(CityFile, ACloudFileOfAnotherAreaIsNamed) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable}, 5, 4000, 1, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  PointCloud far = cloud;
  for (auto& p : far.points) p += Vec3(-50000, 70000, 0);  // another tile, or another CRS
  const std::string near_path = dir + "/near.ply", far_path = dir + "/far.ply", far2_path = dir + "/far2.ply";
  write_ply(near_path, cloud);
  write_ply(far_path, far);
  write_ply(far2_path, far);
  const CityRefineSummary alone = refine_city(dir + "/city.json", {near_path}, dir + "/alone.city.json", {}, {});
  const CityRefineSummary s = refine_city(dir + "/city.json", {near_path, far_path}, dir + "/out.city.json", {}, {});
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind(far_path + ": cloud x 4", 0), 0u) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("does not overlap the city model x 92"), std::string::npos) << s.warnings[0];
  EXPECT_TRUE(alone.warnings.empty());
  EXPECT_EQ(s.cloud_points, 2 * cloud.points.size());
  EXPECT_EQ(s.cropped_points, alone.cropped_points);
  EXPECT_TRUE(cli_fixtures::slurp(dir + "/out.city.json") == cli_fixtures::slurp(dir + "/alone.city.json"));
  try {
    refine_city(dir + "/city.json", {far_path, far2_path}, dir + "/none.city.json", {}, {});
    ADD_FAILURE() << "no file reaches the model";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(far_path + " and 1 other cloud file: cloud x 4", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not overlap the city model"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/none.city.json"));

  // The command line: a warning line per file on stdout, every file in the report.
  const Cli r = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + near_path + " --cloud " + far_path +
                            " --out " + dir + "/cli.city.json --report " + dir + "/report.json",
                        dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.rfind("warning: " + far_path + ": cloud x 4", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("warning: " + near_path), std::string::npos) << r.out;
  const json report = load(dir + "/report.json");
  ASSERT_EQ(report["warnings"].size(), 1u);
  EXPECT_EQ(report["warnings"][0], s.warnings[0]);
  EXPECT_FALSE(report["cloud"].contains("path")) << "several files: each in files";
  ASSERT_EQ(report["cloud"]["files"].size(), 2u);
  EXPECT_EQ(report["cloud"]["files"][0]["path"], near_path);
  EXPECT_EQ(report["cloud"]["files"][0]["points"], cloud.points.size());
  EXPECT_EQ(report["cloud"]["files"][1]["path"], far_path);
  const Eigen::AlignedBox3d far_box = bounding_box(far.points);
  EXPECT_EQ(report["cloud"]["files"][1]["bounds"]["min"],
            json({far_box.min().x(), far_box.min().y(), far_box.min().z()}));
  EXPECT_EQ(report["cloud"]["files"][1]["bounds"]["max"],
            json({far_box.max().x(), far_box.max().y(), far_box.max().z()}));
  const Cli single = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + near_path + " --out " + dir +
                                 "/single.city.json --report " + dir + "/single.json",
                             dir);
  ASSERT_EQ(single.exit, 0) << single.err;
  const json single_report = load(dir + "/single.json");
  EXPECT_EQ(single_report["cloud"]["path"], near_path);
  EXPECT_EQ(single_report["cloud"]["files"].size(), 1u);
  EXPECT_FALSE(single_report.contains("warnings"));
}
