// LAS and LAZ writer (lodrefine/laz/laz_write.h): the header block (las_header.cpp), the LASzip VLR,
// the chunks (the chunk encoders of laz_pointwise.cpp and laz_layered_write.cpp) and the chunk
// table, coded as read_layout reads it.
#include "lodrefine/laz/laz_write.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

#include "laz_items.h"
#include "lodrefine/base/files.h"
#include "lodrefine/laz/las_header.h"
#include "lodrefine/laz/laz.h"

namespace lodrefine {
namespace {

// The items of a point format, in record order, extra bytes last (the decoder's check_items).
std::vector<laz::Item> items_for(int format, std::uint32_t record_length) {
  using namespace laz;
  std::vector<Item> items;
  const std::uint32_t extra = record_length - las_min_record_length(format);
  if (format >= 6) {
    items.push_back({kPoint14, 30, 3});
    if (format == 7) items.push_back({kRgb14, 6, 3});
    if (format == 8 || format == 10) items.push_back({kRgbNir14, 8, 3});
    if (format == 9 || format == 10) items.push_back({kWavePacket14, 29, 3});
    if (extra > 0) items.push_back({kByte14, std::uint16_t(extra), 3});
  } else {
    items.push_back({kPoint10, 20, 2});
    if (format == 1 || format >= 3) items.push_back({kGpsTime11, 8, 2});
    if (format == 2 || format == 3 || format == 5) items.push_back({kRgb12, 6, 2});
    if (format == 4 || format == 5) items.push_back({kWavePacket13, 29, 1});
    if (extra > 0) items.push_back({kByte, std::uint16_t(extra), 2});
  }
  return items;
}

template <class T>
void put(std::string& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) out += char((std::uint64_t(v) >> (8 * i)) & 0xff);
}

// The "laszip encoded" VLR, header and payload (LASzip 3.4.3's layout).
std::string laszip_vlr(std::uint16_t compressor, std::uint32_t chunk_size, const std::vector<laz::Item>& items) {
  std::string payload;
  put<std::uint16_t>(payload, compressor);
  put<std::uint16_t>(payload, 0);  // coder: arithmetic
  payload += char(3), payload += char(4);
  put<std::uint16_t>(payload, 3);  // LASzip version 3.4 r3
  put<std::uint32_t>(payload, 0);  // options
  put<std::uint32_t>(payload, chunk_size);
  put<std::int64_t>(payload, -1);  // no special EVLRs
  put<std::int64_t>(payload, -1);
  put<std::uint16_t>(payload, std::uint16_t(items.size()));
  for (const laz::Item& it : items) put(payload, it.type), put(payload, it.size), put(payload, it.version);
  std::string vlr;
  put<std::uint16_t>(vlr, 0);
  std::string user = "laszip encoded", description = "lodrefine LAZ encoder";
  user.resize(16, '\0');
  description.resize(32, '\0');
  vlr += user;
  put<std::uint16_t>(vlr, 22204);
  put<std::uint16_t>(vlr, std::uint16_t(payload.size()));
  return vlr + description + payload;
}

// The chunk table after its 8-byte header: each chunk's byte count coded against the previous.
std::vector<unsigned char> chunk_table(const std::vector<std::uint32_t>& bytes) {
  std::vector<unsigned char> out;
  if (bytes.empty()) return out;
  laz::ArithmeticEncoder enc(out);
  laz::IntegerCoder ic(32, 2);
  std::uint32_t prev = 0;
  for (std::uint32_t b : bytes) ic.encode(enc, std::int32_t(prev), std::int32_t(b), 1), prev = b;
  enc.done();
  return out;
}

}  // namespace

// The chunk being coded and the byte counts of those done.
struct LasRecordWriter::Chunks {
  std::vector<laz::Item> items;
  std::unique_ptr<laz::ChunkEncoder> current;
  std::uint32_t in_current = 0;
  std::vector<std::uint32_t> bytes;
};

LasRecordWriter::LasRecordWriter(std::string path, const LasRecordFormat& format, bool compressed,
                                 std::uint32_t chunk_size)
    : path_(std::move(path)), format_(format), compressed_(compressed), chunk_size_(chunk_size), by_return_(15) {
  const int f = format.point_format;
  if (f < 0 || f > 10) throw std::invalid_argument("LasRecordWriter: point format 0–10");
  if (format.version_minor < 2 || format.version_minor > 4 || (f >= 6 && format.version_minor < 4))
    throw std::invalid_argument("LasRecordWriter: LAS 1.2–1.4, and 1.4 for point formats 6–10");
  if (compressed && chunk_size == 0) throw std::invalid_argument("LasRecordWriter: chunk size 0");
  record_length_ = std::max(format.record_length, las_min_record_length(f));
  if (record_length_ > 0xffff) throw std::invalid_argument("LasRecordWriter: record length over 65535");
  for (int a = 0; a < 3; ++a)
    lo_[a] = std::numeric_limits<std::int32_t>::max(), hi_[a] = std::numeric_limits<std::int32_t>::min();
  if (compressed) {
    chunks_ = std::make_unique<Chunks>();
    chunks_->items = items_for(f, record_length_);
  }
}

LasRecordWriter::~LasRecordWriter() = default;

void LasRecordWriter::add(const unsigned char* record) {
  for (int a = 0; a < 3; ++a) {
    const auto v = std::int32_t(laz::get_u32(record + 4 * a));
    lo_[a] = std::min(lo_[a], v), hi_[a] = std::max(hi_[a], v);
  }
  const unsigned r = format_.point_format >= 6 ? record[14] & 15 : record[14] & 7;
  if (r >= 1) ++by_return_[r - 1];
  ++count_;
  if (!compressed_) {
    points_.append(reinterpret_cast<const char*>(record), record_length_);
    return;
  }
  Chunks& c = *chunks_;
  if (!c.current)
    c.current = format_.point_format >= 6 ? laz::layered_chunk_encoder(c.items, record_length_)
                                          : laz::pointwise_chunk_encoder(c.items, record_length_);
  c.current->add(record);
  if (++c.in_current == chunk_size_) flush_chunk();
}

void LasRecordWriter::flush_chunk() {
  Chunks& c = *chunks_;
  if (!c.current) return;
  const std::vector<unsigned char> bytes = c.current->finish();
  points_.append(bytes.begin(), bytes.end());
  c.bytes.push_back(std::uint32_t(bytes.size()));
  c.current.reset();
  c.in_current = 0;
}

void LasRecordWriter::finish() {
  const int f = format_.point_format;
  laz::HeaderBlock b;
  b.version_minor = format_.version_minor;
  b.format_byte = f | (compressed_ ? 0x80 : 0);
  b.record_length = record_length_;
  b.count = count_;
  std::copy(by_return_.begin(), by_return_.end(), b.by_return.begin());
  b.scale = format_.scale, b.offset = format_.offset;
  b.min = b.max = Vec3::Zero();
  for (int a = 0; count_ > 0 && a < 3; ++a) {
    b.min[a] = lo_[a] * format_.scale[a] + format_.offset[a];
    b.max[a] = hi_[a] * format_.scale[a] + format_.offset[a];
  }
  std::string vlr;
  if (compressed_) {
    flush_chunk();
    vlr = laszip_vlr(f >= 6 ? 3 : 2, chunk_size_, chunks_->items);
    b.vlr_count = 1;
  }
  const std::size_t header_size = laz::las_header_block(b).size();
  b.point_offset = std::uint32_t(header_size + vlr.size());
  std::string out = laz::las_header_block(b) + vlr;
  if (compressed_) {
    const std::uint64_t table = b.point_offset + 8 + points_.size();
    put<std::uint64_t>(out, table);
    out += points_;
    put<std::uint32_t>(out, 0);  // chunk table version
    put<std::uint32_t>(out, std::uint32_t(chunks_->bytes.size()));
    const std::vector<unsigned char> t = chunk_table(chunks_->bytes);
    out.append(t.begin(), t.end());
  } else {
    out += points_;
  }
  write_file_atomic(path_, out);
}

}  // namespace lodrefine
