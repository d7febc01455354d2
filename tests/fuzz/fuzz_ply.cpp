// libFuzzer target: bytes -> temporary .ply -> read_ply and stream_ply. Both must agree:
// refuse with a one-line InputError, or return the same finite points in the same order.
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/formats/ply.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.ply");
  fuzz::write_bytes(path, data, size);

  PointCloud cloud;
  std::string read_error;
  try {
    cloud = read_ply(path);
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
    read_error = e.what();
  }
  for (const auto& p : cloud.points) FUZZ_CHECK(p.allFinite(), "non-finite point accepted");
  // Far more points than bytes would mean the reader invented data.
  FUZZ_CHECK(cloud.points.size() <= size, "%zu points from %zu bytes", cloud.points.size(), size);

  std::size_t n = 0;
  bool same = true;
  std::string stream_error;
  try {
    stream_ply(path, [&](const Vec3& p) {
      FUZZ_CHECK(p.allFinite(), "stream_ply passed a non-finite point");
      if (read_error.empty()) same = same && n < cloud.points.size() && cloud.points[n] == p;
      ++n;
    });
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
    stream_error = e.what();
  }
  FUZZ_CHECK(read_error == stream_error, "read_ply says '%s', stream_ply says '%s'", read_error.c_str(),
             stream_error.c_str());
  if (read_error.empty()) {
    FUZZ_CHECK(same && n == cloud.points.size(), "stream_ply gave %zu points, read_ply %zu", n, cloud.points.size());
  }
  return 0;
}
