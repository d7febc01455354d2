// Writing LAS point records as LAZ (LASzip-compressed; our own encoder, src/laz/laz_write.cpp and
// the *_write parts of src/laz/laz_*.cpp, the inverse of the decoder stream_las_records uses) or
// as plain LAS. LAZ is LASzip's chunked format as LASzip writes it: point formats 0–5 with
// compressor 2 (POINT10, GPSTIME11, RGB12 and BYTE items in version 2, WAVEPACKET13 in version
// 1), formats 6–10 with compressor 3 (the layered POINT14, RGB14, RGBNIR14, WAVEPACKET14 and
// BYTE14 in version 3), extra bytes in either, fixed-size chunks and a chunk table at the end.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// What the written header declares.
struct LasRecordFormat {
  int version_minor = 2;            // 2..4 (formats 6–10 need 4)
  int point_format = 0;             // 0–10
  std::uint32_t record_length = 0;  // bytes per record; 0: the format's minimum (more: extra bytes)
  Vec3 scale = Vec3::Constant(0.001), offset = Vec3::Zero();
};

// Collects records (header.record_length bytes each, in the LAS layout, as stream_las_records
// gives them) and writes the file on finish(): the header's point count, counts by return and
// bounding box (from X/Y/Z × scale + offset) computed from the records; for LAZ one LASzip VLR
// ("laszip encoded", 22204), points in chunks of `chunk_size` and the chunk table. Memory: the
// compressed chunks (LAZ; a chunk's records while it is coded) or the records (LAS). The file
// is written atomically (no partial file on an error). Throws std::invalid_argument for a
// format, version or record length it cannot write, std::runtime_error when the file cannot.
class LasRecordWriter {
 public:
  LasRecordWriter(std::string path, const LasRecordFormat& format, bool compressed, std::uint32_t chunk_size = 50000);
  ~LasRecordWriter();
  LasRecordWriter(const LasRecordWriter&) = delete;
  LasRecordWriter& operator=(const LasRecordWriter&) = delete;

  std::uint32_t record_length() const { return record_length_; }
  void add(const unsigned char* record);
  void finish();  // once; add() must not follow

 private:
  struct Chunks;
  void flush_chunk();

  std::string path_;
  LasRecordFormat format_;
  bool compressed_;
  std::uint32_t chunk_size_, record_length_ = 0;
  std::uint64_t count_ = 0;
  std::vector<std::uint64_t> by_return_;
  std::int32_t lo_[3], hi_[3];
  std::string points_;  // LAS: the records; LAZ: the finished chunks
  std::unique_ptr<Chunks> chunks_;
};

}  // namespace lodrefine
