// Format dispatch for point clouds: PLY (io) or LAS (las), by content.
#include "lodrefine/io/cloud.h"

#include <algorithm>
#include <cstdio>

#include "lodrefine/io/files.h"
#include "lodrefine/io/las.h"
#include "lodrefine/io/ply.h"

namespace lodrefine {

CloudFormat cloud_format(const std::string& path) {
  const FileKind kind = sniff_file(path);
  if (kind == FileKind::Las) return CloudFormat::Las;
  if (kind == FileKind::Xml || kind == FileKind::Json)
    throw InputError(path + ": not a PLY or LAS point cloud: the file is " + file_kind_text(kind));
  return CloudFormat::Ply;  // the PLY reader reports any other content ("not a PLY file")
}

std::uint64_t cloud_point_count(const std::string& path) {
  return cloud_format(path) == CloudFormat::Las ? read_las_header(path).point_count : ply_vertex_count(path);
}

void stream_cloud(const std::string& path, const CloudOptions& options,
                  const std::function<void(const Vec3&)>& on_point) {
  if (cloud_format(path) == CloudFormat::Las) {
    stream_las(path, options.classes, on_point);
    return;
  }
  if (!options.classes.empty())
    throw InputError(path + ": a PLY cloud has no classification; --classes needs a LAS cloud");
  stream_ply(path, on_point);
}

PointCloud read_cloud(const std::string& path, const CloudOptions& options) {
  // Under read_naming_memory whole: the reservation is most of the memory a cloud takes.
  const std::uint64_t declared = cloud_point_count(path);
  if (declared > options.max_points)
    throw InputError(path + ": " + std::to_string(declared) + " points, more than --max-points " +
                     std::to_string(options.max_points) + "; cut a crop per building first (lodrefine crop)");
  return read_naming_memory(path, [&] {
    PointCloud cloud;
    // A LAS count is bounded by the file size (checked in the header), a LAZ count only by what
    // its chunks decode to, so beyond a few million points the vector grows as points arrive.
    // With a class filter most points may be dropped, so the vector grows too.
    constexpr std::uint64_t kReserveLimit = std::uint64_t(1) << 22;
    if (options.classes.empty()) {
      if (cloud_format(path) == CloudFormat::Las) {
        const LasHeader h = read_las_header(path);
        cloud.points.reserve(h.compressed ? std::min(h.point_count, kReserveLimit) : h.point_count);
      } else {
        cloud.points.reserve(ply_vertex_count(path));
      }
    }
    stream_cloud(path, options, [&](const Vec3& p) { cloud.points.push_back(p); });
    return cloud;
  });
}

std::string overlap_problem(const Eigen::AlignedBox3d& cloud, const Eigen::AlignedBox3d& model, const std::string& what,
                            double margin) {
  if (cloud.isEmpty() || model.isEmpty()) return {};
  const Eigen::AlignedBox2d c(cloud.min().head<2>(), cloud.max().head<2>());
  const Eigen::AlignedBox2d m(model.min().head<2>() - Vec2::Constant(margin),
                              model.max().head<2>() + Vec2::Constant(margin));
  if (c.intersects(m)) return {};
  const auto range = [](const Eigen::AlignedBox3d& b) {
    char s[160];
    std::snprintf(s, sizeof s, "x %.1f..%.1f y %.1f..%.1f", b.min().x(), b.max().x(), b.min().y(), b.max().y());
    return std::string(s);
  };
  return "cloud " + range(cloud) + " does not overlap " + what + " " + range(model) + ": wrong CRS or tile?";
}

std::string classes_text(const std::vector<int>& classes) {
  std::string s;
  for (int c : classes) s += (s.empty() ? "" : ",") + std::to_string(c);
  return s;
}

}  // namespace lodrefine
