// The laz library's decoder of LASzip-compressed point data (LAZ), written from the LASzip
// format as published (rapidlasso's LAZ specification, with laz-perf as the reference
// implementation it was checked against bit for bit). For the formats library: its LAS reader
// (src/formats/las.cpp) calls it for files whose header or VLRs say "compressed"; other users
// read LAZ through las.h.
//
// Supported: the "laszip encoded" VLR (user id "laszip encoded", record 22204); compressor 2
// (chunked, pointwise) with items POINT10, GPSTIME11, RGB12 and BYTE in version 2 and
// WAVEPACKET13 in version 1, i.e. point formats 0–5 with any extra bytes; compressor 3 (chunked,
// layered: LASzip for LAS 1.4) with POINT14, RGB14, RGBNIR14, WAVEPACKET14 and BYTE14 in version
// 3, i.e. formats 6–10 with extra bytes; chunk tables of fixed and variable chunk sizes. Refused
// with one line naming what is missing: other item versions (LASzip 1.x), the unchunked
// compressor 1. The encoder (laz_write.cpp, the chunk encoders in laz_items.h) writes what this
// decoder reads, on the same models.
#pragma once
#include <array>
#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/laz/las_header.h"

namespace lodrefine::laz {

// One LASzip item: its type (0 BYTE, 6 POINT10, 7 GPSTIME11, 8 RGB12, ...), bytes, version.
struct Item {
  std::uint16_t type = 0, size = 0, version = 0;
};

// The parts of the LAZ VLR and chunk table the decoder needs, checked against the file.
struct Layout {
  std::uint16_t compressor = 0;
  std::uint32_t chunk_size = 0;    // points per chunk; kVariableChunks: sizes in the table
  std::vector<Item> items;         // in record order; their sizes add up to the record length
  std::uint64_t table_offset = 0;  // byte offset of the chunk table header
  std::uint32_t chunk_count = 0;
};
constexpr std::uint32_t kVariableChunks = 0xffffffffu;

// The VLR payload (the bytes after the 54-byte VLR header) as stored in the file.
// Parses it, reads the chunk table and checks everything against `header` and the file: item
// list matching the point format and record length, chunks inside the point data, their
// points adding up to at least the header's count. Throws InputError "<path>: <fault>".
// Memory: O(1) beyond the VLR (the table is decoded twice rather than stored).
Layout read_layout(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& header,
                   const std::string& vlr_payload);

// Decodes the first header.point_count points chunk by chunk (one chunk's compressed bytes in
// memory at a time) and calls on_record with each uncompressed LAS point record
// (header.record_length bytes). Throws InputError on a truncated or corrupt chunk.
void stream_records(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& header,
                    const Layout& layout, const std::function<void(const unsigned char*)>& on_record);

// The fields of a LAS 1.2–1.4 public header block that the writers set (las_header.cpp).
struct HeaderBlock {
  int version_minor = 2;
  int format_byte = 0;  // the point format, with bit 7 set for LAZ
  std::uint32_t record_length = 0, point_offset = 0, vlr_count = 0;
  std::uint64_t count = 0;
  std::array<std::uint64_t, 15> by_return{};
  Vec3 scale, offset, min, max;
};
// The header block's bytes (227, 235 or 375 by version); legacy counts 0 for formats 6–10.
std::string las_header_block(const HeaderBlock& b);

}  // namespace lodrefine::laz
