#include "lodrefine/city/crop.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/formats/ply.h"

namespace lodrefine {

std::string building_extent_problem(const Mesh& model) {
  const Eigen::AlignedBox3d box = bounding_box(model.vertices);
  if (box.isEmpty()) return "";
  const double width = box.sizes().head<2>().maxCoeff(), height = box.sizes().z();
  if (width > kMaxBuildingExtent)
    return "spans " + std::to_string(long(width / 1000.0)) + " km, more than a building can (" +
           std::to_string(int(kMaxBuildingExtent / 1000.0)) + " km): a stray vertex?";
  if (height > kMaxBuildingHeight)
    return "rises " + std::to_string(long(height / 1000.0)) + " km, more than a building can (" +
           std::to_string(int(kMaxBuildingHeight / 1000.0)) + " km): a stray vertex?";
  return "";
}

CropTarget crop_target(const Mesh& model, double relative, double absolute) {
  CropTarget t;
  t.id = model.id;
  const Eigen::AlignedBox3d box = bounding_box(model.vertices);
  t.lo = box.min();
  t.hi = box.max();
  const Vec3 size = t.hi - t.lo;
  if (const std::string problem = building_extent_problem(model); !problem.empty())
    throw InputError(model.id + ": " + problem + " not cropped");
  const Vec3 grow(relative * size.x() + absolute, relative * size.y() + absolute, absolute);
  t.lo -= grow;
  t.hi += grow;
  return t;
}

namespace {

// Points read between two calls of the progress callback.
constexpr std::size_t kProgressPoints = 1 << 16;
// The targets filed in 2D hash grids, one per level: level L has cells of `cell * 2^L`, and a
// box goes to the lowest level where it spans at most kSpan cells a side. Memory is
// O(targets) whatever the boxes' sizes (one box 1000 km wide among 20 m ones filled billions of
// cells), and a point looks up one cell per level in use.
class TargetGrid {
 public:
  explicit TargetGrid(const std::vector<CropTarget>& targets) {
    std::vector<double> sizes;
    for (const auto& t : targets) sizes.push_back(std::max(t.hi.x() - t.lo.x(), t.hi.y() - t.lo.y()));
    // Cell size: about the median box size, so most boxes touch few cells at level 0.
    std::nth_element(sizes.begin(), sizes.begin() + std::ptrdiff_t(sizes.size() / 2), sizes.end());
    cell_ = sizes.empty() ? 1.0 : std::max(1.0, sizes[sizes.size() / 2]);
    for (std::size_t i = 0; i < targets.size(); ++i) add(targets[i], i);
  }

  template <class Fn>
  void visit(const Vec3& p, Fn&& fn) const {
    for (long long level : levels_) {
      const auto it = cells_.find(key(p.x(), p.y(), level));
      if (it != cells_.end())
        for (std::size_t i : it->second) fn(i);
    }
  }

 private:
  static constexpr long long kSpan = 4;
  double cell_ = 1.0;
  std::vector<long long> levels_;
  std::unordered_map<GridKey, std::vector<std::size_t>, GridKeyHash> cells_;

  GridKey key(double x, double y, long long level) const {
    const double c = std::ldexp(cell_, int(level));
    return {(long long)std::floor(x / c), (long long)std::floor(y / c), level};
  }

  void add(const CropTarget& t, std::size_t i) {
    if (!(t.lo.head<2>().array() <= t.hi.head<2>().array()).all()) return;  // an empty box holds nothing
    long long level = 0;
    GridKey lo = key(t.lo.x(), t.lo.y(), 0), hi = key(t.hi.x(), t.hi.y(), 0);
    while (hi[0] - lo[0] >= kSpan || hi[1] - lo[1] >= kSpan) {
      ++level;
      lo = key(t.lo.x(), t.lo.y(), level);
      hi = key(t.hi.x(), t.hi.y(), level);
    }
    if (std::find(levels_.begin(), levels_.end(), level) == levels_.end()) levels_.push_back(level);
    for (long long x = lo[0]; x <= hi[0]; ++x)
      for (long long y = lo[1]; y <= hi[1]; ++y) cells_[{x, y, level}].push_back(i);
  }
};

// Streams the tiles (PLY or LAS, `options` filtering LAS classes) once and calls on_hit(i, p, file)
// for every target i whose box holds p, `file` the path of the tile being read; the grid keeps
// this O(points). Returns the number of points read; `read` (optional) as for stream_cloud.
std::size_t for_each_hit(const std::vector<std::string>& tiles, const std::vector<CropTarget>& targets,
                         const CloudOptions& options, std::vector<CloudFileRead>* read,
                         const std::function<void(std::size_t, const Vec3&, const std::string&)>& on_hit,
                         const std::function<void(std::uint64_t)>& on_read) {
  if (targets.empty()) return 0;
  const TargetGrid grid(targets);
  std::vector<CloudFileRead> own;  // the files read, when the caller keeps none
  std::vector<CloudFileRead>& files = read ? *read : own;
  std::size_t n = 0;
  stream_cloud(
      tiles, options,
      [&](const Vec3& p) {
        if (++n % kProgressPoints == 0 && on_read) on_read(n);
        grid.visit(p, [&](std::size_t i) {
          const auto& t = targets[i];
          if ((p.array() >= t.lo.array()).all() && (p.array() <= t.hi.array()).all()) on_hit(i, p, files.back().path);
        });
      },
      &files);
  return n;
}

// A limit passed while reading several tiles counts the points of those read before.
std::string before_it(const std::vector<std::string>& tiles) {
  return tiles.size() > 1 ? ", counting the tiles read before it" : "";
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

std::size_t crop_tile(const std::vector<std::string>& tiles, std::vector<CropTarget>& targets,
                      const CloudOptions& options, std::vector<CloudFileRead>* read,
                      const std::function<void(std::uint64_t)>& on_read, std::uint64_t max_held) {
  std::uint64_t held = 0;
  return for_each_hit(
      tiles, targets, options, read,
      [&](std::size_t i, const Vec3& p, const std::string& tile) {
        if (++held > max_held)
          throw InputError(tile + ": the buildings' crop boxes hold more than " + std::to_string(max_held) +
                           " points (--max-crop-points)" + before_it(tiles) + "; refine the district in parts");
        targets[i].cloud.points.push_back(p);
      },
      on_read);
}

std::size_t crop_tile_to_files(const std::vector<std::string>& tiles, const std::vector<CropTarget>& targets,
                               const std::vector<std::string>& out_paths, std::size_t buffer_points,
                               std::vector<std::size_t>& counts, const CloudOptions& options,
                               const std::function<void(std::uint64_t)>& on_read, std::vector<CloudFileRead>* read) {
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
    n = for_each_hit(
        tiles, targets, options, read,
        [&](std::size_t i, const Vec3& p, const std::string& tile) {
          // Each crop is read back whole to be written: bounded as a cloud read whole is.
          if (++counts[i] > options.max_points)
            throw InputError(tile + ": the crop of " + shown_id(targets[i].id) + " holds more than " +
                             std::to_string(options.max_points) + " points (--max-points)" + before_it(tiles));
          held[i].push_back(p);
          if (++in_memory > buffer_points) flush_all();
        },
        on_read);
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
