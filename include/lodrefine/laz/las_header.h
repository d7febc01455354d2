// The LAS public header block as the LAZ codec and the LAS reader and writer (formats library,
// las.h) share it: the fields read, the header sizes by version and the point formats' record
// lengths. The formats library's las.h includes it, so its users see LasHeader there.
#pragma once
#include <cstdint>

#include "lodrefine/base/types.h"

namespace lodrefine {

// The public header block fields the reader uses, validated against the file.
struct LasHeader {
  int version_major = 1, version_minor = 2;
  int point_format = 0;             // 0..10
  std::uint32_t record_length = 0;  // bytes per point record (>= the format's minimum; extra bytes are skipped)
  std::uint32_t header_size = 0;
  std::uint64_t point_offset = 0;  // byte offset of the first point record
  std::uint64_t point_count = 0;   // LAS 1.4: the 64-bit count; before: the 32-bit legacy count
  Vec3 scale = Vec3::Ones(), offset = Vec3::Zero();
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // bounding box as declared by the writer
  bool compressed = false;                      // LAZ: point format bit 7 or 6, or a "laszip encoded" VLR
};

// Smallest record length of point data format 0..10 (ASPRS LAS 1.4 R15, Tables 7–17).
std::uint32_t las_min_record_length(int point_format);

namespace laz {
// Public header block sizes by version: 1.0–1.2 end after the bounding box, 1.3 adds the
// waveform data offset, 1.4 the extended VLRs and 64-bit counts.
constexpr std::uint32_t kHeaderSize12 = 227, kHeaderSize13 = 235, kHeaderSize14 = 375;
}  // namespace laz

}  // namespace lodrefine
