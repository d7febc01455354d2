// A generated building written to its folder (src/synth/tiles.cpp): truth, coarse model, cloud
// and meta.json, the meta naming what the generator did; outputs checked before anything is made.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

TEST(SynthWrite, WritesFourFilesAndMeta) {
  const auto dir = std::filesystem::temp_directory_path() / "lodrefine_test_synth";
  std::filesystem::remove_all(dir);
  SynthOptions o;
  o.target_points = 3000;
  const auto b = make_building(BuildingType::TShape, 3, o);
  OutputTree out(dir.string());
  write_synth_building(out, b);
  out.keep();
  const auto d = dir / b.id;
  for (const char* f : {"truth.obj", "coarse.obj", "cloud.ply", "meta.json"})
    EXPECT_TRUE(std::filesystem::exists(d / f)) << f;
  std::ifstream in(d / "meta.json");
  const auto meta = nlohmann::json::parse(in);
  EXPECT_EQ(meta["id"], b.id);
  EXPECT_EQ(meta["type"], "tshape");
  EXPECT_EQ(meta["seed"], 3);
  EXPECT_EQ(meta["moved_walls"].size(), b.moved_walls.size());
  EXPECT_EQ(meta["scanned_truth_faces"].get<std::vector<int>>(), b.scanned_truth_faces);
  EXPECT_EQ(meta["counts"]["points"], b.cloud.points.size());
  // Binary PLY: header + 3 doubles + 1 float per point.
  EXPECT_GT(std::filesystem::file_size(d / "cloud.ply"), b.cloud.points.size() * 28);
  std::filesystem::remove_all(dir);
}

TEST(SynthWrite, ABuildingFolderThatIsALinkIsRefusedBeforeAnythingIsWritten) {
  const auto dir = std::filesystem::temp_directory_path() / "lodrefine_test_synth_link";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "elsewhere");
  const std::string id = synth_building_id(BuildingType::Flat, 5);
  EXPECT_EQ(id, "synth_flat_0005");
  std::filesystem::create_directory_symlink(dir / "elsewhere", dir / id);
  OutputTree out(dir.string());
  try {
    check_synth_outputs(out, {id});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(id), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir / "elsewhere"));
  std::filesystem::remove_all(dir);
}
