#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "lodrefine/io/crop.h"
#include "lodrefine/core/geometry.h"
#include "lodrefine/io/ply.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

TEST(Crop, OneStreamingPassCutsEachBuildingsCloud) {
  // Three generated buildings side by side in one tile, plus far-away points.
  std::vector<SynthBuilding> bs;
  PointCloud tile;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SynthOptions opt;
    opt.target_points = 3000;
    opt.origin = Vec3(85000.0 + 400.0 * double(seed), 447000.0, 0.0);  // well apart
    bs.push_back(make_building(BuildingType::Gable, seed, opt));
    tile.points.insert(tile.points.end(), bs.back().cloud.points.begin(), bs.back().cloud.points.end());
  }
  for (int i = 0; i < 500; ++i) tile.points.push_back(Vec3(90000.0 + i, 440000.0, 0.0));
  const auto path = std::filesystem::temp_directory_path() / "lodrefine_crop_tile.ply";
  write_ply(path.string(), tile);

  std::vector<CropTarget> targets;
  for (const auto& b : bs) targets.push_back(crop_target(b.coarse, 0.1, 3.0));
  EXPECT_EQ(crop_tile(path.string(), targets), tile.points.size());
  for (std::size_t i = 0; i < bs.size(); ++i) {
    // Every point of the building's own crop lies in its box; the crop has (nearly) all of it.
    const auto& t = targets[i];
    std::size_t own_inside = 0;
    for (const auto& p : bs[i].cloud.points)
      own_inside += (p.array() >= t.lo.array()).all() && (p.array() <= t.hi.array()).all();
    EXPECT_EQ(t.cloud.points.size(), own_inside) << bs[i].id;  // no point of another building
    EXPECT_GT(double(own_inside), 0.8 * double(bs[i].cloud.points.size())) << bs[i].id;
  }
  std::filesystem::remove(path);
}

// The city-scale path: a tiny memory bound (spilling to disk all the time) writes exactly the
// in-memory crops, in the same order.
TEST(Crop, BoundedMemoryCropWritesTheSameClouds) {
  PointCloud tile;
  std::vector<CropTarget> targets;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SynthOptions opt;
    opt.target_points = 2000;
    const auto b = make_building(BuildingType::Flat, seed, opt);
    // 25 m apart: the boxes overlap.
    const Vec3 shift = Vec3(85000.0 + 25.0 * double(seed), 447000.0, 0.0) - b.frame_origin;
    for (const auto& p : b.cloud.points) tile.points.push_back(p + shift);
    targets.push_back(crop_target(translated(b.coarse, shift), 0.1, 3.0));
  }
  const auto dir = std::filesystem::temp_directory_path() / ("lodrefine_crop_files_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = (dir / "tile.ply").string();
  write_ply(path, tile);
  std::vector<CropTarget> in_memory = targets;
  crop_tile(path, in_memory);
  std::vector<std::string> outs;
  for (std::size_t i = 0; i < targets.size(); ++i) outs.push_back((dir / ("crop" + std::to_string(i) + ".ply")).string());
  // Links planted at the spill files' old, predictable names are not followed (issue 15).
  const auto victim = dir / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  for (const auto& out : outs) std::filesystem::create_symlink(victim, out + ".spill.tmp." + std::to_string(::getpid()));
  std::vector<std::size_t> counts;
  EXPECT_EQ(crop_tile_to_files(path, targets, outs, 7, counts), tile.points.size());
  EXPECT_EQ(std::filesystem::file_size(victim), 9u);
  for (const auto& out : outs) std::filesystem::remove(out + ".spill.tmp." + std::to_string(::getpid()));
  std::filesystem::remove(victim);
  std::size_t total = 0;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PointCloud c = read_ply(outs[i]);
    EXPECT_EQ(counts[i], in_memory[i].cloud.points.size());
    ASSERT_EQ(c.points.size(), in_memory[i].cloud.points.size());
    for (std::size_t k = 0; k < c.points.size(); ++k) ASSERT_EQ(c.points[k], in_memory[i].cloud.points[k]) << i << " " << k;
    total += counts[i];
  }
  EXPECT_GT(total, tile.points.size()) << "the boxes overlap: some points belong to two crops";
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find("tmp"), std::string::npos) << e.path();
  std::filesystem::remove_all(dir);
}
