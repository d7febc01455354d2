#include "lodrefine/io/crop.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <unordered_map>

#include "lodrefine/core/geometry.h"
#include "lodrefine/io/files.h"
#include "lodrefine/io/ply.h"

namespace lodrefine {

CropTarget crop_target(const Mesh& model, double relative, double absolute) {
  CropTarget t;
  t.id = model.id;
  const Eigen::AlignedBox3d box = bounding_box(model.vertices);
  t.lo = box.min();
  t.hi = box.max();
  const Vec3 size = t.hi - t.lo;
  const Vec3 grow(relative * size.x() + absolute, relative * size.y() + absolute, absolute);
  t.lo -= grow;
  t.hi += grow;
  return t;
}

namespace {

// Points read between two calls of the progress callback.
constexpr std::size_t kProgressPoints = 1 << 16;

// Streams the tile (PLY or LAS, `options` filtering LAS classes) once and calls on_hit(i, p)
// for every target i whose box holds p; a 2D grid over the targets keeps this O(points).
// Returns the number of points read; `bounds` (optional) gets their bounding box.
std::size_t for_each_hit(const std::string& tile, const std::vector<CropTarget>& targets, const CloudOptions& options,
                         Eigen::AlignedBox3d* bounds, const std::function<void(std::size_t, const Vec3&)>& on_hit,
                         const std::function<void(std::uint64_t)>& on_read) {
  if (targets.empty()) return 0;
  // Grid cell size: about the median box size, so each box touches few cells.
  std::vector<double> sizes;
  for (const auto& t : targets) sizes.push_back(std::max(t.hi.x() - t.lo.x(), t.hi.y() - t.lo.y()));
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  const double cell = std::max(1.0, sizes[sizes.size() / 2]);
  auto key = [cell](double x, double y) {
    return (std::int64_t(std::floor(x / cell)) << 32) ^ (std::int64_t(std::floor(y / cell)) & 0xffffffff);
  };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const auto& t = targets[i];
    for (double x = std::floor(t.lo.x() / cell) * cell; x <= t.hi.x(); x += cell)
      for (double y = std::floor(t.lo.y() / cell) * cell; y <= t.hi.y(); y += cell) grid[key(x + 0.5 * cell, y + 0.5 * cell)].push_back(i);
  }
  std::size_t n = 0;
  stream_cloud(tile, options, [&](const Vec3& p) {
    if (++n % kProgressPoints == 0 && on_read) on_read(n);
    if (bounds) bounds->extend(p);
    const auto it = grid.find(key(p.x(), p.y()));
    if (it == grid.end()) return;
    for (std::size_t i : it->second) {
      const auto& t = targets[i];
      if ((p.array() >= t.lo.array()).all() && (p.array() <= t.hi.array()).all()) on_hit(i, p);
    }
  });
  return n;
}

// Appends points to a spill file (raw doubles), created exclusively beside `out_path` on the
// first spill (`path` empty until then) and reopened without following links after that.
void spill(const std::string& out_path, std::string& path, const std::vector<Vec3>& points) {
  const int fd = path.empty() ? create_temp_file(std::filesystem::path(out_path).parent_path().string(), out_path, path)
                              : ::open(path.c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(fd < 0 ? nullptr : ::fdopen(fd, "ab"), std::fclose);
  if (fd >= 0 && !f) ::close(fd);
  const std::size_t bytes = points.size() * sizeof(Vec3);
  if (!f || std::fwrite(points.data(), 1, bytes, f.get()) != bytes || std::fflush(f.get()) != 0)
    throw InputError("cannot write " + path + ": " + std::strerror(errno));
}

std::vector<Vec3> unspill(const std::string& path) {
  std::vector<Vec3> points(!path.empty() ? std::filesystem::file_size(path) / sizeof(Vec3) : 0);
  if (points.empty()) return points;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), std::fclose);
  if (!f || std::fread(points.data(), sizeof(Vec3), points.size(), f.get()) != points.size())
    throw InputError("cannot read back " + path);
  return points;
}

}  // namespace

std::size_t crop_tile(const std::string& tile, std::vector<CropTarget>& targets, const CloudOptions& options,
                      Eigen::AlignedBox3d* bounds, const std::function<void(std::uint64_t)>& on_read) {
  return for_each_hit(
      tile, targets, options, bounds, [&](std::size_t i, const Vec3& p) { targets[i].cloud.points.push_back(p); },
      on_read);
}

std::size_t crop_tile_to_files(const std::string& tile, const std::vector<CropTarget>& targets,
                               const std::vector<std::string>& out_paths, std::size_t buffer_points,
                               std::vector<std::size_t>& counts, const CloudOptions& options,
                               const std::function<void(std::uint64_t)>& on_read) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "spill files hold Vec3 as three doubles");
  std::vector<std::vector<Vec3>> held(targets.size());
  std::vector<std::string> spills(targets.size());  // created on a target's first spill
  counts.assign(targets.size(), 0);
  std::size_t in_memory = 0;
  auto flush_all = [&] {
    for (std::size_t i = 0; i < held.size(); ++i)
      if (!held[i].empty()) spill(out_paths[i], spills[i], held[i]), std::vector<Vec3>().swap(held[i]);
    in_memory = 0;
  };
  std::size_t n = 0;
  try {
    n = for_each_hit(tile, targets, options, nullptr, [&](std::size_t i, const Vec3& p) {
      held[i].push_back(p);
      ++counts[i];
      if (++in_memory > buffer_points) flush_all();
    }, on_read);
    for (std::size_t i = 0; i < targets.size(); ++i) {
      PointCloud cloud;
      cloud.points = unspill(spills[i]);
      cloud.points.insert(cloud.points.end(), held[i].begin(), held[i].end());
      std::vector<Vec3>().swap(held[i]);
      write_ply(out_paths[i], cloud);
      if (!spills[i].empty()) std::filesystem::remove(spills[i]);
    }
  } catch (...) {
    for (const auto& s : spills)
      if (!s.empty()) ::unlink(s.c_str());
    throw;
  }
  return n;
}

}  // namespace lodrefine
