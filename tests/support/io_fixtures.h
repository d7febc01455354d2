// Files for the io tests: per-test temporary paths, and the check that a reader refuses a file
// with one line naming it and the fault.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/formats/ply.h"

namespace lodrefine::fixtures {

// A fresh per-test path under the GoogleTest temp dir.
inline std::string temp_path(const std::string& name) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / ("lodrefine_io_" + std::to_string(::getpid())) / info->name();
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

inline std::string write_bytes(const std::string& name, const std::string& content) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// Expects InputError whose one-line message starts with the file's path and contains `fault`.
template <class F>
void expect_input_error(const std::string& path, const std::string& fault, F&& read) {
  try {
    read(path);
    ADD_FAILURE() << "no InputError for " << path << " (expected '" << fault << "')";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(fault), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// Writes `bytes` to the test's file `name` and expects `read` to refuse it (expect_input_error).
template <class F>
void expect_bytes_refused(const std::string& name, const std::string& bytes, const std::string& fault, F&& read) {
  expect_input_error(write_bytes(name, bytes), fault, std::forward<F>(read));
}

// Overwrites sizeof(T) bytes at `at` with `v` (the test machine is little-endian, as LAS is):
// header lies made to order.
template <class T>
void poke(std::string& bytes, std::size_t at, T v) {
  std::memcpy(&bytes[at], &v, sizeof v);
}

// A survey delivered per tile: the cloud cut along x into `n` tiles of about equal counts (cut at
// the x quantiles, so buildings straddle tiles), each keeping the cloud's order.
inline std::vector<PointCloud> split_by_x(const PointCloud& cloud, std::size_t n) {
  std::vector<double> xs;
  for (const Vec3& p : cloud.points) xs.push_back(p.x());
  std::sort(xs.begin(), xs.end());
  std::vector<double> cuts;  // tile k: cuts[k-1] <= x < cuts[k]
  for (std::size_t k = 1; k < n; ++k) cuts.push_back(xs[k * xs.size() / n]);
  std::vector<PointCloud> tiles(n);
  for (const Vec3& p : cloud.points)
    tiles[std::size_t(std::upper_bound(cuts.begin(), cuts.end(), p.x()) - cuts.begin())].points.push_back(p);
  return tiles;
}

// The tiles one after another: the one file that reading them in this order equals.
inline PointCloud concatenated(const std::vector<PointCloud>& tiles) {
  PointCloud all;
  for (const PointCloud& t : tiles) all.points.insert(all.points.end(), t.points.begin(), t.points.end());
  return all;
}

// Writes the tiles as DIR/tile_00.ply, tile_01.ply, ... (created last first: the folder's order
// is not the names') and returns their paths in name order.
inline std::vector<std::string> write_tiles(const std::string& dir, const std::vector<PointCloud>& tiles) {
  std::filesystem::create_directories(dir);
  std::vector<std::string> paths(tiles.size());
  for (std::size_t k = tiles.size(); k-- > 0;) {
    paths[k] = dir + "/tile_" + (k < 10 ? "0" : "") + std::to_string(k) + ".ply";
    write_ply(paths[k], tiles[k]);
  }
  return paths;
}

}  // namespace lodrefine::fixtures
