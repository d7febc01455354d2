// The occupancy grid of a plane's scan points (occupancy.h).
#include "occupancy.h"

namespace lodrefine::detail {

Frame2 frame_of(const Plane& pl, const Vec3& centre) {
  const auto [u, v] = pl.basis();
  return {pl.project(centre), u, v};
}

// A point marks its cell and those within kFill cells (occupancy.h): a scanned facade's
// coverage is near 1 and that of a face it does not reach near 0. Each cell holding points is
// filled around once, not once per point.
constexpr int kFill = 2;
void mark_scanned(CellSet& cells, const std::vector<Vec3>& pts, const Frame2& frame) {
  CellSet occupied;
  for (const auto& p : pts) {
    const Vec2 q = frame(p);
    const long long i = (long long)std::floor(q.x() / kOccupancyCell),
                    j = (long long)std::floor(q.y() / kOccupancyCell);
    if (!occupied.insert(cell_key(i, j)).second) continue;
    for (long long di = -kFill; di <= kFill; ++di)
      for (long long dj = -kFill; dj <= kFill; ++dj) cells.insert(cell_key(i + di, j + dj));
  }
}

double scanned_share(const std::vector<Vec2>& poly, const CellSet& cells) {
  if (cells.empty() || poly.empty()) return 0.0;
  long long total = 0, hit = 0;
  for_box_cells(poly, [&](long long i, long long j) {
    if (!point_in_polygon_2d(Vec2((i + 0.5) * kOccupancyCell, (j + 0.5) * kOccupancyCell), poly)) return;
    ++total;
    hit += cells.count(cell_key(i, j));
  });
  if (total > 0) return double(hit) / double(total);
  Vec2 c = Vec2::Zero();
  for (const auto& p : poly) c += p;
  c /= double(poly.size());
  return cells.count(
             cell_key((long long)std::floor(c.x() / kOccupancyCell), (long long)std::floor(c.y() / kOccupancyCell)))
             ? 1.0
             : 0.0;
}

}  // namespace lodrefine::detail
