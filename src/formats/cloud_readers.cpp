// The point-cloud readers' table (see cloud_readers.h).
#include "cloud_readers.h"

#include <algorithm>

#include "lodrefine/formats/las.h"
#include "lodrefine/formats/ply.h"

namespace lodrefine::detail {
namespace {

DeclaredPoints ply_declared(const std::string& path) {
  const std::uint64_t n = ply_vertex_count(path);
  return {n, n};
}
void ply_stream(const std::string& path, const std::vector<int>&, const std::function<void(const Vec3&)>& on_point) {
  stream_ply(path, on_point);
}

// A LAS count is bounded by the file size (checked in the header), a LAZ count only by what its
// chunks decode to, so beyond a few million points the vector grows as points arrive.
DeclaredPoints las_declared(const std::string& path) {
  constexpr std::uint64_t kReserveLimit = std::uint64_t(1) << 22;
  const LasHeader h = read_las_header(path);
  return {h.point_count, h.compressed ? std::min(h.point_count, kReserveLimit) : h.point_count};
}
void las_stream(const std::string& path, const std::vector<int>& classes,
                const std::function<void(const Vec3&)>& on_point) {
  stream_las(path, classes, on_point);
}

}  // namespace

const std::vector<CloudReader>& cloud_readers() {
  static const std::vector<CloudReader> rows = {
      {FileKind::Ply, {"PLY"}, "ply", false, ply_declared, ply_stream},
      {FileKind::Las, {"LAS", "LAZ"}, "LASF", true, las_declared, las_stream},
  };
  return rows;
}

const CloudReader* cloud_reader(FileKind kind) {
  for (const CloudReader& r : cloud_readers())
    if (r.kind == kind) return &r;
  return nullptr;
}

}  // namespace lodrefine::detail
