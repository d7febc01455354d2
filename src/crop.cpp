#include "lodrefine/crop.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>


namespace lodrefine {

CropTarget crop_target(const Mesh& model, double relative, double absolute) {
  CropTarget t;
  t.id = model.id;
  t.lo = Vec3::Constant(1e300);
  t.hi = Vec3::Constant(-1e300);
  for (const auto& v : model.vertices) {
    t.lo = t.lo.cwiseMin(v);
    t.hi = t.hi.cwiseMax(v);
  }
  const Vec3 size = t.hi - t.lo;
  const Vec3 grow(relative * size.x() + absolute, relative * size.y() + absolute, absolute);
  t.lo -= grow;
  t.hi += grow;
  return t;
}

std::size_t crop_tile(const std::string& tile, std::vector<CropTarget>& targets, const CloudOptions& options,
                      Eigen::AlignedBox3d* bounds) {
  if (targets.empty()) return 0;
  // Grid cell size: about the median box size, so each box touches few cells.
  std::vector<double> sizes;
  for (const auto& t : targets) sizes.push_back(std::max(t.hi.x() - t.lo.x(), t.hi.y() - t.lo.y()));
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  const double cell = std::max(1.0, sizes[sizes.size() / 2]);
  auto key = [cell](double x, double y) {
    return (std::int64_t(std::floor(x / cell)) << 32) ^ (std::int64_t(std::floor(y / cell)) & 0xffffffff);
  };
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  for (int i = 0; i < int(targets.size()); ++i) {
    const auto& t = targets[i];
    for (double x = std::floor(t.lo.x() / cell) * cell; x <= t.hi.x(); x += cell)
      for (double y = std::floor(t.lo.y() / cell) * cell; y <= t.hi.y(); y += cell) grid[key(x + 0.5 * cell, y + 0.5 * cell)].push_back(i);
  }
  std::size_t n = 0;
  stream_cloud(tile, options, [&](const Vec3& p) {
    ++n;
    if (bounds) bounds->extend(p);
    const auto it = grid.find(key(p.x(), p.y()));
    if (it == grid.end()) return;
    for (int i : it->second) {
      auto& t = targets[i];
      if ((p.array() >= t.lo.array()).all() && (p.array() <= t.hi.array()).all()) t.cloud.points.push_back(p);
    }
  });
  return n;
}

}  // namespace lodrefine
