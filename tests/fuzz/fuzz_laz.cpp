// libFuzzer target: bytes -> temporary .laz -> read_las_header, stream_las_records and
// read_cloud. LAZ headers, VLRs, chunk tables and chunks are attacker-controlled: each reader
// refuses with a one-line InputError naming the file (the same one for header faults), or
// gives exactly the header's count of records and finite points within 1e9 m. Bounded memory
// and time are checked by libFuzzer's -rss_limit_mb and -timeout.
#include <cstdint>
#include <string>

#include "fuzz_las_common.h"
#include "lodrefine/base/files.h"  // kMaxCoordinate
#include "lodrefine/formats/cloud.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.laz");
  std::string header_error;
  const LasHeader header = fuzz::las_header_of(path, data, size, header_error);

  std::uint64_t records = 0;
  std::string read_error;
  try {
    stream_las_records(path, [&](const LasHeader& h, const unsigned char*) {
      FUZZ_CHECK(h.record_length == header.record_length, "record length changed");
      ++records;
    });
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
    read_error = e.what();
  }
  if (!header_error.empty()) fuzz::check_same_refusal(header_error, read_error);
  if (header_error.empty() && read_error.empty())
    FUZZ_CHECK(records == header.point_count, "%llu records, header %llu", (unsigned long long)records,
               (unsigned long long)header.point_count);

  if (!read_error.empty()) return 0;
  try {
    const PointCloud cloud = read_cloud(path);
    for (const auto& p : cloud.points)
      FUZZ_CHECK(p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate, "bad point accepted");
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);  // a coordinate beyond 1e9 m
  }
  return 0;
}
