#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include "lodrefine/base/geometry.h"
#include "lodrefine/city/crop.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"
#include "support/io_fixtures.h"

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
  EXPECT_EQ(crop_tile({path.string()}, targets), tile.points.size());
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

namespace {

// Three generated buildings 25 m apart (their boxes overlap) in one tile; their crop targets.
PointCloud overlapping_row(std::vector<CropTarget>& targets) {
  PointCloud tile;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SynthOptions opt;
    opt.target_points = 2000;
    const auto b = make_building(BuildingType::Flat, seed, opt);
    const Vec3 shift = Vec3(85000.0 + 25.0 * double(seed), 447000.0, 0.0) - b.frame_origin;
    for (const auto& p : b.cloud.points) tile.points.push_back(p + shift);
    targets.push_back(crop_target(translated(b.coarse, shift), 0.1, 3.0));
  }
  return tile;
}

}  // namespace

// The city-scale path: a tiny memory bound (spilling to disk all the time) writes exactly the
// in-memory crops, in the same order.
TEST(Crop, BoundedMemoryCropWritesTheSameClouds) {
  std::vector<CropTarget> targets;
  const PointCloud tile = overlapping_row(targets);
  const auto dir = std::filesystem::temp_directory_path() / ("lodrefine_crop_files_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = (dir / "tile.ply").string();
  write_ply(path, tile);
  std::vector<CropTarget> in_memory = targets;
  crop_tile({path}, in_memory);
  std::vector<std::string> outs;
  for (std::size_t i = 0; i < targets.size(); ++i)
    outs.push_back((dir / ("crop" + std::to_string(i) + ".ply")).string());
  // Links planted at the spill files' old, predictable names are not followed (issue 15).
  const auto victim = dir / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  for (const auto& out : outs)
    std::filesystem::create_symlink(victim, out + ".spill.tmp." + std::to_string(::getpid()));
  std::vector<std::size_t> counts;
  EXPECT_EQ(crop_tile_to_files({path}, targets, outs, 7, counts), tile.points.size());
  EXPECT_EQ(std::filesystem::file_size(victim), 9u);
  for (const auto& out : outs) std::filesystem::remove(out + ".spill.tmp." + std::to_string(::getpid()));
  std::filesystem::remove(victim);
  std::size_t total = 0;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PointCloud c = read_ply(outs[i]);
    EXPECT_EQ(counts[i], in_memory[i].cloud.points.size());
    ASSERT_EQ(c.points.size(), in_memory[i].cloud.points.size());
    for (std::size_t k = 0; k < c.points.size(); ++k)
      ASSERT_EQ(c.points[k], in_memory[i].cloud.points[k]) << i << " " << k;
    total += counts[i];
  }
  EXPECT_GT(total, tile.points.size()) << "the boxes overlap: some points belong to two crops";
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find("tmp"), std::string::npos) << e.path();
  std::filesystem::remove_all(dir);
}

namespace {

// Runs fn in a child process whose address space may grow by at most `bytes` (over what it
// holds at the fork: this works under AddressSanitizer too); true when fn returned.
bool runs_within(std::size_t bytes, const std::function<void()>& fn) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    long pages = 0;
    std::ifstream("/proc/self/statm") >> pages;
    rlimit r{};
    r.rlim_cur = r.rlim_max = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + bytes;
    ::setrlimit(RLIMIT_AS, &r);
    try {
      fn();
    } catch (...) {
      ::_exit(1);
    }
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

// Issue 15, item 11: one box 2000 km wide among 20 m ones made the crop grid span it cell by
// cell (billions of cells, ~4 GB). The grid now grows with the number of boxes: the crop runs
// in 200 MB more address space and each box still gets exactly its points.
TEST(Crop, HugeBoxAmongSmallOnesKeepsTheGridSmall) {
  std::vector<CropTarget> targets;
  PointCloud tile;
  for (int k = 0; k < 500; ++k) {
    CropTarget t;
    t.id = "small" + std::to_string(k);
    t.lo = Vec3(85000.0 + 30.0 * k, 447000.0, 0.0);
    t.hi = t.lo + Vec3(20, 20, 20);
    targets.push_back(t);
    tile.points.push_back(t.lo + Vec3(10, 10, 10));
  }
  CropTarget huge;
  huge.id = "huge";
  huge.lo = Vec3(-1e6, -1e6, 0.0);
  huge.hi = Vec3(1e6, 1e6, 100.0);
  targets.push_back(huge);
  tile.points.push_back(Vec3(-9e5, 9e5, 50.0));    // the huge box's alone
  tile.points.push_back(Vec3(5e6, 447000.0, 10));  // nobody's
  const auto path =
      std::filesystem::temp_directory_path() / ("lodrefine_crop_huge_" + std::to_string(::getpid()) + ".ply");
  write_ply(path.string(), tile);
  EXPECT_TRUE(runs_within(std::size_t(200) << 20, [&] {
    std::vector<CropTarget> copy = targets;
    crop_tile({path.string()}, copy);
    bool ok = copy.back().cloud.points.size() == 501;  // every point but the far one
    for (std::size_t k = 0; k + 1 < copy.size(); ++k) ok = ok && copy[k].cloud.points.size() == 1;
    if (!ok) throw std::runtime_error("wrong crops");
  }));
  std::filesystem::remove(path);
  // A model that wide is no building: crop_target refuses it by name.
  Mesh stray;
  stray.id = "stray";
  stray.vertices = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(1e6, 1e6, 5)};
  stray.faces = {{{0, 1, 2}, Semantic::Roof, 0}};
  try {
    crop_target(stray, 0.1, 3.0);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("\"stray\": spans 1000 km, more than a building can (5 km)", 0), 0u)
        << e.what();
  }
}

// A tile delivered as several (issue 39): the crops of the tiles read as one are those of the one
// tile holding their points in that order, also through the bounded-memory path; the limits
// count the points of every tile.
TEST(Crop, TilesReadAsOneCropAsTheirMergedTile) {
  std::vector<CropTarget> targets;
  const PointCloud tile = overlapping_row(targets);
  const std::vector<PointCloud> parts = fixtures::split_by_x(tile, 3);
  const std::string dir = fixtures::temp_path("tiles");
  const std::vector<std::string> tiles = fixtures::write_tiles(dir, parts);
  const std::string merged = fixtures::temp_path("merged.ply");
  write_ply(merged, fixtures::concatenated(parts));

  std::vector<CropTarget> one = targets, several = targets;
  EXPECT_EQ(crop_tile({merged}, one), tile.points.size());
  std::vector<CloudFileRead> read;
  EXPECT_EQ(crop_tile(tiles, several, {}, &read), tile.points.size());
  std::size_t held = 0, straddling = 0;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    EXPECT_EQ(several[i].cloud.points, one[i].cloud.points) << i;
    held += one[i].cloud.points.size();
    std::size_t tiles_reached = 0;  // the tiles holding some of this crop
    for (const PointCloud& part : parts)
      tiles_reached += std::any_of(part.points.begin(), part.points.end(), [&](const Vec3& p) {
        return (p.array() >= targets[i].lo.array()).all() && (p.array() <= targets[i].hi.array()).all();
      });
    straddling += tiles_reached > 1;
  }
  EXPECT_GE(straddling, 2u) << "the cuts run through buildings";
  ASSERT_EQ(read.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(read[k].path, tiles[k]);
    EXPECT_EQ(read[k].points, parts[k].points.size());
    EXPECT_EQ(read[k].bounds.min(), bounding_box(parts[k].points).min());
  }

  // The bounded-memory path writes the same crops.
  std::vector<std::string> outs;
  for (std::size_t i = 0; i < targets.size(); ++i)
    outs.push_back(fixtures::temp_path("crop" + std::to_string(i) + ".ply"));
  std::vector<std::size_t> counts;
  EXPECT_EQ(crop_tile_to_files(tiles, targets, outs, 7, counts), tile.points.size());
  for (std::size_t i = 0; i < targets.size(); ++i) EXPECT_EQ(read_ply(outs[i]).points, one[i].cloud.points) << i;

  // --max-crop-points counts the crops' points over every tile read.
  std::vector<CropTarget> copy = targets;
  EXPECT_EQ(crop_tile(tiles, copy, {}, nullptr, {}, held), tile.points.size());
  copy = targets;
  try {
    crop_tile(tiles, copy, {}, nullptr, {}, held - 1);
    ADD_FAILURE() << "the crops hold more than --max-crop-points";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              tiles.back() + ": the buildings' crop boxes hold more than " + std::to_string(held - 1) +
                  " points (--max-crop-points), counting the tiles read before it; refine the district in parts");
  }
  // --max-points bounds each crop over every tile: a crop under it in each tile, over it in all.
  std::size_t largest = 0, largest_in_one_tile = 0;
  for (const auto& t : one) largest = std::max(largest, t.cloud.points.size());
  for (const std::string& path : tiles) {
    std::vector<CropTarget> alone = targets;
    crop_tile({path}, alone);
    for (const auto& t : alone) largest_in_one_tile = std::max(largest_in_one_tile, t.cloud.points.size());
  }
  ASSERT_LT(largest_in_one_tile, largest - 1);
  CloudOptions bounded;
  bounded.max_points = largest - 1;
  try {
    crop_tile_to_files(tiles, targets, outs, 7, counts, bounded);
    ADD_FAILURE() << "a crop holds more than --max-points";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(" points (--max-points), counting the tiles read before it"),
              std::string::npos)
        << e.what();
  }
}
