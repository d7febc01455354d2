// Cutting one MLS crop per building out of a large tile, in one streaming pass.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/formats/cloud.h"

namespace lodrefine {

struct CropTarget {
  std::string id;
  Vec3 lo, hi;          // expanded bounding box (georeferenced); lo > hi: an empty box, no point
  std::string refused;  // why this building is not cropped (empty: it is)
  PointCloud cloud;     // filled by crop_tile
};

// A model wider than this (m, in x or y) is no building: a stray vertex, or a wrong unit. Its
// crop would hold a whole tile.
constexpr double kMaxBuildingExtent = 5000.0;
// A model taller than this (m, in z) is no building either (the tallest stands 828 m): a stray
// vertex above or below it would set its ground or have a van scan kilometres of wall.
constexpr double kMaxBuildingHeight = 1000.0;

// "spans N km, more than a building can (5 km): a stray vertex?" for a model wider than
// kMaxBuildingExtent in x or y, "rises N km, … (1 km) …" for one taller than kMaxBuildingHeight,
// else empty: crop, a city refine and synth --rescan refuse such a model, each naming it.
std::string building_extent_problem(const Mesh& model);

// The model's bounding box grown by `relative` of its size and `absolute` metres on each side
// (vertically by `absolute` only). Throws InputError "<model id>: spans N km ..." for a model
// wider than kMaxBuildingExtent.
CropTarget crop_target(const Mesh& model, double relative, double absolute);

// Streams the tiles (PLY or LAS/LAZ files, read as one cloud: stream_cloud; `options` filtering
// LAS classes) once and appends each point to every target whose box holds it (2D grids over the
// targets keep this O(points), their memory O(targets)). Returns the number of points read (after
// the class filter); `read` (optional) gets each file's points and bounds (stream_cloud). `on_read`
// (optional) is called with the points read so far, over all files, every 65,536 points (for a
// progress line). Throws InputError naming the file being read when the targets would hold more
// than `max_held` points together.
std::size_t crop_tile(const std::vector<std::string>& tiles, std::vector<CropTarget>& targets,
                      const CloudOptions& options = {}, std::vector<CloudFileRead>* read = nullptr,
                      const std::function<void(std::uint64_t)>& on_read = {}, std::uint64_t max_held = UINT64_MAX);

// The same pass for a whole city tile (or several), with memory bounded by `buffer_points`, not
// by the tiles: each target's points go to `out_paths[i]` (a PLY, written atomically), and points
// held beyond the bound are spilled to per-target temporary files beside them. Only one target's
// crop is in memory at a time when the PLYs are written, so a crop of more than
// options.max_points points (over all tiles) is refused (InputError). Returns the number of
// points read and sets `counts[i]` to each crop's size; `read` as for crop_tile.
std::size_t crop_tile_to_files(const std::vector<std::string>& tiles, const std::vector<CropTarget>& targets,
                               const std::vector<std::string>& out_paths, std::size_t buffer_points,
                               std::vector<std::size_t>& counts, const CloudOptions& options = {},
                               const std::function<void(std::uint64_t)>& on_read = {},
                               std::vector<CloudFileRead>* read = nullptr);

}  // namespace lodrefine
