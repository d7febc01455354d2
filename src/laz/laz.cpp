// LAZ decoder (laz.h): the LASzip VLR, the item list checked against the point format, the
// chunk table, and the chunk by chunk streaming of records. The decoding itself: laz_coder.h
// (arithmetic decoder and models), laz_items.h (shared field decoders), laz_pointwise.cpp
// (compressor 2) and laz_layered.cpp (compressor 3).
#include "lodrefine/laz/laz.h"

#include <algorithm>
#include <array>
#include <optional>

#include "laz_items.h"
#include "lodrefine/base/text.h"

namespace lodrefine::laz {
namespace {

using io_text::fail;
using io_text::read_at;

// The items a point format needs, in record order (extra bytes come last, as one BYTE item):
// version 2 items for formats 0–5 (compressor 2), version 3 for 6–10 (compressor 3).
std::string check_items(const std::vector<Item>& items, int format, std::uint16_t compressor,
                        std::uint32_t record_length) {
  const bool layered = format >= 6;
  if (compressor != (layered ? 3 : 2))
    return "LASzip compressor " + std::to_string(compressor) + " does not fit point format " + std::to_string(format);
  std::vector<std::uint16_t> want;
  if (layered) {
    want = {kPoint14};
    if (format == 7) want.push_back(kRgb14);
    if (format == 8 || format == 10) want.push_back(kRgbNir14);
    if (format == 9 || format == 10) want.push_back(kWavePacket14);
  } else {
    want = {kPoint10};
    if (format == 1 || format == 3 || format == 4 || format == 5) want.push_back(kGpsTime11);
    if (format == 2 || format == 3 || format == 5) want.push_back(kRgb12);
    if (format == 4 || format == 5) want.push_back(kWavePacket13);
  }
  const std::uint16_t bytes_type = layered ? kByte14 : kByte, version = layered ? 3 : 2;
  std::uint32_t total = 0;
  std::size_t i = 0;
  for (const Item& it : items) {
    const bool expected = i < want.size() ? it.type == want[i] : it.type == bytes_type && i == want.size();
    if (!expected)
      return "LASzip item type " + std::to_string(it.type) + " does not fit point format " + std::to_string(format);
    // WAVEPACKET13 has only version 1 (LASzip writes it beside version-2 items).
    const std::uint16_t item_version = it.type == kWavePacket13 ? 1 : version;
    if (it.version != item_version)
      return "LASzip item version " + std::to_string(it.version) + " (point format " + std::to_string(format) +
             " is read in version " + std::to_string(item_version) + ")";
    static const std::array<std::uint16_t, 15> kSize = {0, 0, 0, 0, 0, 0, 20, 8, 6, 29, 30, 6, 8, 29, 0};
    const std::uint16_t size = it.type == bytes_type ? it.size : kSize[it.type];
    if (it.size != size || size == 0)
      return "LASzip item type " + std::to_string(it.type) + " of " + std::to_string(it.size) + " bytes";
    total += it.size;
    ++i;
  }
  if (i < want.size()) return "LASzip items do not cover point format " + std::to_string(format);
  if (total != record_length)
    return "LASzip items hold " + std::to_string(total) + " bytes per point, the header " +
           std::to_string(record_length);
  return {};
}

// Reads the chunk table one entry at a time: (points, compressed bytes) per chunk.
class ChunkTable {
 public:
  ChunkTable(const std::string& path, std::ifstream& in, std::uint64_t file_size, const Layout& layout)
      : layout_(layout) {
    // An entry takes at most a few bytes; the table never needs more than this many.
    const std::uint64_t start = layout.table_offset + 8;
    const std::uint64_t want =
        std::min<std::uint64_t>(file_size - std::min(file_size, start), 16 * std::uint64_t(layout.chunk_count) + 64);
    bytes_.resize(std::size_t(want));
    if (!read_at(in, start, bytes_.data(), bytes_.size())) fail(path, "read error in the LAZ chunk table");
    reader_.emplace(bytes_.data(), bytes_.data() + bytes_.size());
    dec_.emplace(*reader_);
  }
  // Points and bytes of the next chunk; throws OutOfData on a truncated table.
  std::pair<std::uint32_t, std::uint32_t> next() {
    if (!started_) dec_->init(), started_ = true;
    std::uint32_t count = layout_.chunk_size;
    if (layout_.chunk_size == kVariableChunks)
      count = prev_count_ = std::uint32_t(ic_.decode(*dec_, std::int32_t(prev_count_), 0));
    prev_bytes_ = std::uint32_t(ic_.decode(*dec_, std::int32_t(prev_bytes_), 1));
    return {count, prev_bytes_};
  }

 private:
  const Layout& layout_;
  std::vector<unsigned char> bytes_;
  std::optional<ByteReader> reader_;
  std::optional<ArithmeticDecoder> dec_;
  IntegerCoder ic_{32, 2};
  bool started_ = false;
  std::uint32_t prev_count_ = 0, prev_bytes_ = 0;
};

}  // namespace

Layout read_layout(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& h,
                   const std::string& vlr) {
  const auto* v = reinterpret_cast<const unsigned char*>(vlr.data());
  if (vlr.size() < 34) fail(path, "LASzip VLR of " + std::to_string(vlr.size()) + " bytes (at least 34 needed)");
  Layout L;
  L.compressor = get_u16(v);
  L.chunk_size = get_u32(v + 12);
  const std::uint16_t n_items = get_u16(v + 32);
  if (vlr.size() < 34 + 6 * std::size_t(n_items)) fail(path, "LASzip VLR truncated: its item list does not fit");
  for (std::uint16_t i = 0; i < n_items; ++i)
    L.items.push_back({get_u16(v + 34 + 6 * i), get_u16(v + 36 + 6 * i), get_u16(v + 38 + 6 * i)});
  if (L.compressor != 2 && L.compressor != 3)
    fail(path, "LASzip compressor " + std::to_string(L.compressor) +
                   " is not supported (2, chunked pointwise, and 3, chunked layered, are read)");
  if (const std::string bad = check_items(L.items, h.point_format, L.compressor, h.record_length); !bad.empty())
    fail(path, bad);
  if (L.chunk_size == 0) fail(path, "LASzip chunk size 0");

  unsigned char b[8];
  if (h.point_offset + 8 > file_size || !read_at(in, h.point_offset, b, 8))
    fail(path, "LAZ point data ends before its chunk table offset (truncated?)");
  std::uint64_t table = get_u64(b);
  if (table == ~std::uint64_t(0)) {  // written to a stream: the offset is the file's last 8 bytes
    if (file_size < 8 || !read_at(in, file_size - 8, b, 8)) fail(path, "LAZ chunk table offset missing");
    table = get_u64(b);
  }
  const std::uint64_t first_chunk = h.point_offset + 8;
  if (table < first_chunk || table > file_size || file_size - table < 8)
    fail(path, "LAZ chunk table offset " + std::to_string(table) + " lies outside the point data (file of " +
                   std::to_string(file_size) + " bytes; truncated?)");
  L.table_offset = table;
  if (!read_at(in, table, b, 8)) fail(path, "read error in the LAZ chunk table");
  if (get_u32(b) != 0) fail(path, "LAZ chunk table version " + std::to_string(get_u32(b)) + " (0 expected)");
  L.chunk_count = get_u32(b + 4);
  // Every chunk starts with one raw point, so the point data bounds the number of chunks.
  const std::uint64_t max_chunks = (table - first_chunk) / h.record_length;
  if (L.chunk_count > max_chunks)
    fail(path, "LAZ chunk table declares " + std::to_string(L.chunk_count) + " chunks but " +
                   std::to_string(table - first_chunk) + " bytes of point data hold at most " +
                   std::to_string(max_chunks));
  if (h.point_count > 0 && L.chunk_count == 0) fail(path, "LAZ chunk table is empty but the header declares points");

  // Walk the table: every chunk inside the point data, enough points for the header.
  ChunkTable t(path, in, file_size, L);
  std::uint64_t points = 0, pos = first_chunk;
  try {
    for (std::uint32_t i = 0; i < L.chunk_count && points < h.point_count; ++i) {
      const auto [count, bytes] = t.next();
      if (count == 0) fail(path, "LAZ chunk " + std::to_string(i) + " holds no points");
      if (bytes < h.record_length || bytes > table - pos)
        fail(path, "LAZ chunk " + std::to_string(i) + " of " + std::to_string(bytes) + " bytes at offset " +
                       std::to_string(pos) + " does not fit the point data before the chunk table at " +
                       std::to_string(table));
      points += count;
      pos += bytes;
    }
  } catch (const OutOfData&) {
    fail(path, "LAZ chunk table truncated or corrupt");
  }
  if (points < h.point_count)
    fail(path, "header declares " + std::to_string(h.point_count) + " points but the LAZ chunks hold only " +
                   std::to_string(points) + " (truncated?)");
  return L;
}

void stream_records(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& h,
                    const Layout& L, const std::function<void(const unsigned char*)>& on_record) {
  ChunkTable table(path, in, file_size, L);
  std::vector<unsigned char> chunk, record(h.record_length);
  std::uint64_t pos = h.point_offset + 8, done = 0;
  for (std::uint32_t i = 0; done < h.point_count; ++i) {
    if (i >= L.chunk_count) fail(path, "LAZ chunk table changed while reading (file modified?)");
    std::pair<std::uint32_t, std::uint32_t> entry;
    try {
      entry = table.next();
    } catch (const OutOfData&) {
      fail(path, "LAZ chunk table truncated or corrupt");
    }
    chunk.resize(entry.second);
    if (!read_at(in, pos, chunk.data(), chunk.size())) fail(path, "LAZ chunk " + std::to_string(i) + " truncated");
    pos += entry.second;
    ByteReader reader(chunk.data(), chunk.data() + chunk.size());
    const std::uint64_t n = std::min<std::uint64_t>(entry.first, h.point_count - done);
    try {
      if (L.compressor == 3) decode_layered_chunk(L.items, reader, n, record.data(), done, on_record);
      else decode_pointwise_chunk(L.items, reader, n, record.data(), done, on_record);
    } catch (const OutOfData&) {
      fail(path, "LAZ chunk " + std::to_string(i) + " ends after " + std::to_string(done) + " of " +
                     std::to_string(h.point_count) + " points (truncated or corrupt)");
    } catch (const Corrupt& e) {
      fail(path, "LAZ chunk " + std::to_string(i) + " is corrupt after " + std::to_string(done) + " of " +
                     std::to_string(h.point_count) + " points: " + e.what);
    }
  }
}

}  // namespace lodrefine::laz
