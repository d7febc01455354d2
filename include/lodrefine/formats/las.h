// Reading ASPRS LAS point clouds: versions 1.0–1.4, point data record formats 0–10,
// uncompressed, and LASzip-compressed LAZ of point formats 0–10 (our own decoder, src/laz/laz.cpp:
// Debian ships no LAS library, no PDAL, LASlib, liblas, LASzip or laz-perf). A small reader of
// the public header block and the point records; other LAZ is refused with one line.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/laz/las_header.h"

namespace lodrefine {

// LasHeader and las_min_record_length: las_header.h (the laz library's, which the decoder shares).

// Reads and checks the header: 'LASF' signature, version 1.0–1.4, header size, point data
// offset and record length within the file, point format 0–10, record length at least the
// format's minimum, the point count times the record length within the file, finite non-zero
// scales and finite offsets. For LAZ (point format bit 7 or 6, or a "laszip encoded" VLR;
// point_format is then the format without those bits) instead of the count check: a LASzip VLR
// the decoder supports, a chunk table inside the file whose chunks hold at least the declared
// points. Throws InputError "<path>: <fault>" (one line); allocates no more than the header, a
// VLR (64 kB) and a bounded slice of the chunk table.
LasHeader read_las_header(const std::string& path);

// Streams the raw point records in file order: header.record_length bytes each, in the LAS
// layout (LAZ decompressed chunk by chunk, so memory stays bounded). Returns the count.
std::uint64_t stream_las_records(const std::string& path,
                                 const std::function<void(const LasHeader&, const unsigned char*)>& on_record);

// Streams the points (x = X·scale + offset, in double) in file order, reading the file in
// chunks (LAZ: one compressed chunk at a time). `classes` (empty: every point) keeps only points whose classification
// is listed: formats 0–5 carry a 5-bit class (bits 0–4 of byte 15), formats 6–10 a full byte (byte 16). Returns the
// number of points passed on. Rejects coordinates beyond 1e9 m (kMaxCoordinate).
std::uint64_t stream_las(const std::string& path, const std::vector<int>& classes,
                         const std::function<void(const Vec3&)>& on_point);

// Writes an uncompressed LAS file (for tests and tools): `version_minor` 2..4, `point_format`
// 0..10, `record_length` 0 = the format's minimum (more: zero padding as extra bytes), one
// classification per point (or none: class 1), scale 1 mm and the given offset.
struct LasWriteOptions {
  int version_minor = 2;
  int point_format = 0;
  std::uint32_t record_length = 0;
  Vec3 scale = Vec3::Constant(0.001);
  Vec3 offset = Vec3::Zero();
};
void write_las(const std::string& path, const PointCloud& cloud, const std::vector<int>& classes,
               const LasWriteOptions& options);

}  // namespace lodrefine
