// Point cloud input of either format, chosen by the file's content (not its name): PLY
// ('ply' magic line) or LAS ('LASF' signature). Compressed LAZ, city models, JSON and other
// files given as a cloud are refused with a one-line message saying what the file is.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/core/geometry.h"  // bounding_box, for overlap_problem
#include "lodrefine/core/types.h"

namespace lodrefine {

enum class CloudFormat { Ply, Las };

inline constexpr std::uint64_t kDefaultMaxPoints = 20000000;

struct CloudOptions {
  // Classification codes to keep (LAS only; empty: every point). Formats 0–5 carry 5-bit
  // classes (0–31), 6–10 the full byte. A PLY has no classification: a filter is an error.
  std::vector<int> classes;
  // The most points read_cloud holds (a building's crop, not a tile): a LAZ file of a few
  // hundred kilobytes can announce 1e9 points, which would fill the memory. Beyond: InputError.
  std::uint64_t max_points = kDefaultMaxPoints;
};

// The format of a cloud file by its first bytes; throws InputError for anything else.
CloudFormat cloud_format(const std::string& path);

// The number of points the header declares (validated against the file size), before any
// class filter: lets callers refuse clouds too large to hold without reading them.
std::uint64_t cloud_point_count(const std::string& path);

// Streams the points in file order (chunked; memory does not grow with the file).
void stream_cloud(const std::string& path, const CloudOptions& options,
                  const std::function<void(const Vec3&)>& on_point);

// Reads the whole cloud. Throws InputError when its header announces more than
// options.max_points points, before reading them.
PointCloud read_cloud(const std::string& path, const CloudOptions& options = {});

// CRS / tile sanity: one line "cloud x a..b y c..d does not overlap <what> x e..f y g..h: wrong
// CRS or tile?" when the boxes are disjoint in XY (the model grown by `margin` metres); empty
// when they overlap. A cloud in another CRS or of another tile otherwise only shows up as
// "no planes found".
std::string overlap_problem(const Eigen::AlignedBox3d& cloud, const Eigen::AlignedBox3d& model,
                            const std::string& what = "the model", double margin = 3.0);

// "--classes 2,6" as text, for messages ("" without a filter).
std::string classes_text(const std::vector<int>& classes);

}  // namespace lodrefine
