// libFuzzer target: bytes -> temporary .las -> read_las_header, read_cloud and stream_cloud
// with a class filter. Each refuses with a one-line InputError naming the file, or returns
// finite points within 1e9 m; the header's count bounds the points (no invented data), and
// the filtered stream is the unfiltered one minus the dropped points, in the same order.
#include <cstdint>
#include <string>

#include "fuzz_las_common.h"
#include "lodrefine/base/files.h"  // kMaxCoordinate
#include "lodrefine/formats/cloud.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.las");
  std::string header_error;
  const LasHeader header = fuzz::las_header_of(path, data, size, header_error);
  if (header_error.empty()) {
    FUZZ_CHECK(header.record_length >= las_min_record_length(header.point_format), "short record accepted");
    FUZZ_CHECK(header.compressed || header.point_offset + header.point_count * header.record_length <= size,
               "%llu points of %u bytes from offset %llu exceed %zu bytes", (unsigned long long)header.point_count,
               header.record_length, (unsigned long long)header.point_offset, size);
  }

  PointCloud cloud;
  std::string read_error;
  try {
    cloud = read_cloud(path);
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
    read_error = e.what();
  }
  for (const auto& p : cloud.points)
    FUZZ_CHECK(p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate, "bad point accepted");
  if (!header_error.empty() && size >= 4 && std::string(reinterpret_cast<const char*>(data), 4) == "LASF")
    fuzz::check_same_refusal(header_error, read_error);
  if (header_error.empty() && read_error.empty())
    FUZZ_CHECK(cloud.points.size() == header.point_count, "%zu points, header %llu", cloud.points.size(),
               (unsigned long long)header.point_count);

  if (!header_error.empty() || !read_error.empty()) return 0;
  std::size_t n = 0, kept = 0;
  std::string stream_error;
  try {
    stream_cloud(path, {{2, 6, 200}}, [&](const Vec3& p) {
      while (n < cloud.points.size() && !(cloud.points[n] == p)) ++n;  // dropped points are skipped
      FUZZ_CHECK(n < cloud.points.size(), "filtered stream gave a point not in the cloud (or out of order)");
      ++n, ++kept;
    });
  } catch (const InputError& e) {
    stream_error = e.what();
  }
  FUZZ_CHECK(stream_error.empty(), "filtered stream failed where the full read passed: %s", stream_error.c_str());
  FUZZ_CHECK(kept <= cloud.points.size(), "filter kept more than all");
  return 0;
}
