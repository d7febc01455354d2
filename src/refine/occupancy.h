// Internal to core: the occupancy grid of a plane's scan points, in the plane's own 2D frame.
// What share of a polygon on a plane its points cover: a candidate's confidence
// (shell_describe), a written face's coverage (provenance). Cells of kOccupancyCell, keyed by (i, j).
#pragma once
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"

namespace lodrefine::detail {

// Occupancy grid cell (m): several MLS points wide, a fraction of a window.
constexpr double kOccupancyCell = 0.25;

// A plane's 2D frame: its basis (Plane::basis) at an origin on it.
struct Frame2 {
  Vec3 o, u, v;
  Vec2 operator()(const Vec3& p) const { return {(p - o).dot(u), (p - o).dot(v)}; }
  Vec3 lifted(const Vec2& q) const { return o + q.x() * u + q.y() * v; }  // back onto the plane
};
// `pl`'s frame with its origin where `centre` projects onto it.
Frame2 frame_of(const Plane& pl, const Vec3& centre);

// The key of grid cell (i, j) (cell i along u covers [i, i + 1) * kOccupancyCell). In unsigned
// arithmetic: shifting a negative index is undefined before C++20.
inline std::int64_t cell_key(long long i, long long j) {
  return std::int64_t((std::uint64_t(i) << 32) ^ std::uint64_t(std::uint32_t(j)));
}

// fn(i, j) for every grid cell of a polygon's bounding box (`poly` in a Frame2's coordinates).
template <class Fn>
void for_box_cells(const std::vector<Vec2>& poly, Fn&& fn) {
  const Eigen::AlignedBox2d box = bounding_box(poly);
  const long long i0 = (long long)std::floor(box.min().x() / kOccupancyCell),
                  i1 = (long long)std::floor(box.max().x() / kOccupancyCell);
  const long long j0 = (long long)std::floor(box.min().y() / kOccupancyCell),
                  j1 = (long long)std::floor(box.max().y() / kOccupancyCell);
  for (long long i = i0; i <= i1; ++i)
    for (long long j = j0; j <= j1; ++j) fn(i, j);
}

// A plane's kOccupancyCell grid cells (in its Frame2) that the scan covers, keyed by cell_key.
using CellSet = std::unordered_set<std::int64_t>;
// Marks the cells of `pts` (in `frame`) and those within 2 cells around each: a facade's windows
// and the gaps between scan lines (up to about a metre) count as scanned.
void mark_scanned(CellSet& cells, const std::vector<Vec3>& pts, const Frame2& frame);
// The share (0..1) of a polygon's cells (by centre; `poly` in the frame's coordinates) in
// `cells`; a polygon holding no cell centre is judged by its centroid's cell (0 or 1). 0 when
// `cells` or `poly` is empty.
double scanned_share(const std::vector<Vec2>& poly, const CellSet& cells);

}  // namespace lodrefine::detail
