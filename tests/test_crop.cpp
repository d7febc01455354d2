#include <gtest/gtest.h>

#include <filesystem>

#include "lodrefine/crop.h"
#include "lodrefine/io.h"
#include "lodrefine/synth.h"

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
