// LAS reader and writer (ASPRS LAS 1.4 R15; 1.0–1.3 are prefixes of the same header); LAZ
// point data goes through our decoder (laz.h). All fields are little-endian and read
// byte-wise, so the code does not depend on the host.
#include "lodrefine/formats/las.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/base/text.h"
#include "lodrefine/laz/laz.h"

namespace lodrefine {
namespace {

// Public header block sizes by version (las_header.h).
using laz::kHeaderSize12;
using laz::kHeaderSize13;
using laz::kHeaderSize14;
constexpr std::uint32_t kVlrHeaderSize = 54;
// Point data format ids with bit 7 (LASzip) or bit 6 (older LASzip) set mark compressed data.
constexpr int kCompressedBits = 0xC0;
// Reading happens in chunks of about this many bytes (whole records).
constexpr std::size_t kChunkBytes = 1 << 20;

using io_text::fail;
using io_text::get_le;
using io_text::open_input;
using io_text::put_le;
using io_text::read_at;

Vec3 get_vec(const unsigned char* p, int stride) {
  return {get_le<double>(p), get_le<double>(p + stride), get_le<double>(p + 2 * stride)};
}

// The LASzip VLR's payload, when one of the VLRs between the header and the point data is
// "laszip encoded" (record 22204): that marks LAZ even when a tool cleared the format bits.
// Walks only as far as the VLRs fit before the point data; a VLR holds at most 64 kB.
std::optional<std::string> laszip_vlr(std::ifstream& in, const LasHeader& h, std::uint32_t vlr_count) {
  std::uint64_t pos = h.header_size;
  for (std::uint32_t i = 0; i < vlr_count && pos + kVlrHeaderSize <= h.point_offset; ++i) {
    unsigned char v[kVlrHeaderSize];
    if (!read_at(in, pos, v, sizeof v)) return std::nullopt;
    const std::uint16_t length = get_le<std::uint16_t>(v + 20);
    if (std::string(reinterpret_cast<const char*>(v + 2), strnlen(reinterpret_cast<const char*>(v + 2), 16)) ==
            "laszip encoded" &&
        get_le<std::uint16_t>(v + 18) == 22204) {
      std::string payload(std::min<std::uint64_t>(length, h.point_offset - pos - kVlrHeaderSize), '\0');
      if (!read_at(in, pos + kVlrHeaderSize, reinterpret_cast<unsigned char*>(payload.data()), payload.size()))
        return std::nullopt;
      return payload;
    }
    pos += kVlrHeaderSize + length;
  }
  return std::nullopt;
}

// A header and, for LAZ, the layout of its compressed data.
struct Parsed {
  LasHeader header;
  std::optional<laz::Layout> laz;
};

Parsed parse_header(const std::string& path, std::ifstream& in, std::uint64_t file_size) {
  if (file_size == 0) fail(path, "empty file");
  unsigned char b[kHeaderSize14] = {};
  const std::size_t got = std::size_t(std::min<std::uint64_t>(file_size, sizeof b));
  if (!read_at(in, 0, b, got)) fail(path, "read error");
  if (got < 4 || std::memcmp(b, "LASF", 4) != 0) fail(path, "not a LAS file (no 'LASF' signature)");
  if (got < kHeaderSize12)
    fail(path, "LAS header truncated (" + std::to_string(file_size) + " of at least " + std::to_string(kHeaderSize12) +
                   " bytes)");
  LasHeader h;
  h.version_major = b[24], h.version_minor = b[25];
  const int format_id = b[104] & ~kCompressedBits;
  if (h.version_major != 1 || h.version_minor > 4)
    fail(path, "unsupported LAS version " + std::to_string(h.version_major) + "." + std::to_string(h.version_minor) +
                   " (1.0–1.4 are read)");
  const std::uint32_t min_header = h.version_minor >= 4   ? kHeaderSize14
                                   : h.version_minor == 3 ? kHeaderSize13
                                                          : kHeaderSize12;
  h.header_size = get_le<std::uint16_t>(b + 94);
  h.point_offset = get_le<std::uint32_t>(b + 96);
  const std::uint32_t vlr_count = get_le<std::uint32_t>(b + 100);
  h.record_length = get_le<std::uint16_t>(b + 105);
  if (h.header_size < min_header)
    fail(path, "header size " + std::to_string(h.header_size) + " is below the " + std::to_string(min_header) +
                   " bytes of LAS 1." + std::to_string(h.version_minor));
  if (h.header_size > file_size)
    fail(path, "header size " + std::to_string(h.header_size) + " exceeds the file size " + std::to_string(file_size) +
                   " (truncated?)");
  if (h.point_offset < h.header_size)
    fail(path, "point data offset " + std::to_string(h.point_offset) + " lies inside the header (" +
                   std::to_string(h.header_size) + " bytes)");
  if (h.point_offset > file_size)
    fail(path, "point data offset " + std::to_string(h.point_offset) + " is beyond the end of the file (" +
                   std::to_string(file_size) + " bytes; truncated?)");
  std::optional<std::string> vlr = laszip_vlr(in, h, vlr_count);
  h.compressed = (b[104] & kCompressedBits) != 0 || vlr.has_value();
  if (h.compressed && !vlr)
    fail(path, "compressed point format bits set but no LASzip VLR (\"laszip encoded\", 22204)");
  if (format_id > 10) fail(path, "unknown point data format " + std::to_string(format_id) + " (0–10 are defined)");
  h.point_format = format_id;
  const std::uint32_t min_record = las_min_record_length(format_id);
  if (h.record_length < min_record)
    fail(path, "point record length " + std::to_string(h.record_length) + " is below the " +
                   std::to_string(min_record) + " bytes of point format " + std::to_string(format_id));

  const std::uint64_t legacy = get_le<std::uint32_t>(b + 107);
  h.point_count = legacy;
  if (h.version_minor >= 4) {
    const std::uint64_t count64 = get_le<std::uint64_t>(b + 247);
    if (legacy != 0 && count64 != 0 && legacy != count64)
      fail(path, "legacy point count " + std::to_string(legacy) + " disagrees with the 64-bit count " +
                     std::to_string(count64));
    if (count64 != 0) h.point_count = count64;
  }
  const std::uint64_t data_bytes = file_size - h.point_offset;
  if (!h.compressed && h.point_count > data_bytes / h.record_length)
    fail(path, "header declares " + std::to_string(h.point_count) + " points of " + std::to_string(h.record_length) +
                   " bytes but the file holds only " + std::to_string(data_bytes) +
                   " bytes of point data (truncated?)");

  h.scale = get_vec(b + 131, 8);
  h.offset = get_vec(b + 155, 8);
  h.max = Vec3(get_le<double>(b + 179), get_le<double>(b + 195), get_le<double>(b + 211));
  h.min = Vec3(get_le<double>(b + 187), get_le<double>(b + 203), get_le<double>(b + 219));
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(h.scale[a]) || h.scale[a] == 0.0)
      fail(path, std::string("scale factor of ") + char('x' + a) + " is zero or not finite");
    if (!std::isfinite(h.offset[a]) || std::abs(h.offset[a]) > kMaxCoordinate)
      fail(path, std::string("offset of ") + char('x' + a) + " is not finite or beyond 1e9 m");
  }
  Parsed parsed{h, std::nullopt};
  if (h.compressed) parsed.laz = laz::read_layout(path, in, file_size, h, *vlr);
  return parsed;
}

}  // namespace

LasHeader read_las_header(const std::string& path) {
  std::uint64_t size = 0;
  std::ifstream in = open_input(path, &size);
  return parse_header(path, in, size).header;
}

std::uint64_t stream_las_records(const std::string& path,
                                 const std::function<void(const LasHeader&, const unsigned char*)>& on_record) {
  std::uint64_t size = 0;
  std::ifstream in = open_input(path, &size);
  const Parsed parsed = parse_header(path, in, size);
  const LasHeader& h = parsed.header;
  if (parsed.laz) {
    laz::stream_records(path, in, size, h, *parsed.laz, [&](const unsigned char* r) { on_record(h, r); });
    return h.point_count;
  }
  const std::size_t per_chunk = std::max<std::size_t>(1, kChunkBytes / h.record_length);
  std::vector<unsigned char> buf(per_chunk * h.record_length);
  in.clear();
  in.seekg(std::streamoff(h.point_offset));
  std::uint64_t done = 0;
  while (done < h.point_count) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(per_chunk, h.point_count - done));
    in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(n * h.record_length));
    if (in.gcount() != std::streamsize(n * h.record_length))
      fail(path, "data ends after " + std::to_string(done + std::uint64_t(in.gcount()) / h.record_length) + " of " +
                     std::to_string(h.point_count) + " points (truncated)");
    for (std::size_t i = 0; i < n; ++i, ++done) on_record(h, buf.data() + i * h.record_length);
  }
  return h.point_count;
}

std::uint64_t stream_las(const std::string& path, const std::vector<int>& classes,
                         const std::function<void(const Vec3&)>& on_point) {
  std::bitset<256> keep;
  for (int c : classes) {
    if (c < 0 || c > 255) throw std::invalid_argument("LAS classification out of range 0..255");
    keep.set(std::size_t(c));
  }
  const bool filter = !classes.empty();
  std::uint64_t done = 0, passed = 0;
  stream_las_records(path, [&](const LasHeader& h, const unsigned char* r) {
    // Formats 6–10 hold the class in a byte of its own; 0–5 in the low 5 bits of byte 15.
    const bool extended = h.point_format >= 6;
    const std::uint64_t index = done++;
    if (filter && !keep[extended ? r[16] : (r[15] & 0x1f)]) return;
    const Vec3 p(double(get_le<std::int32_t>(r)) * h.scale.x() + h.offset.x(),
                 double(get_le<std::int32_t>(r + 4)) * h.scale.y() + h.offset.y(),
                 double(get_le<std::int32_t>(r + 8)) * h.scale.z() + h.offset.z());
    if (p.cwiseAbs().maxCoeff() > kMaxCoordinate)
      fail(path, "point " + std::to_string(index) + " has a coordinate beyond 1e9 m");
    on_point(p);
    ++passed;
  });
  return passed;
}

void write_las(const std::string& path, const PointCloud& cloud, const std::vector<int>& classes,
               const LasWriteOptions& o) {
  if (o.version_minor < 2 || o.version_minor > 4) throw std::invalid_argument("write_las: version 1.2–1.4 only");
  const std::uint32_t record = std::max(o.record_length, las_min_record_length(o.point_format));
  if (record > 0xffff) throw std::invalid_argument("write_las: record length over 65535");
  if (!classes.empty() && classes.size() != cloud.points.size())
    throw std::invalid_argument("write_las: one class per point");
  const std::uint32_t header = o.version_minor == 4   ? kHeaderSize14
                               : o.version_minor == 3 ? kHeaderSize13
                                                      : kHeaderSize12;
  const std::uint64_t n = cloud.points.size();
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  if (n > 0) {
    const Eigen::AlignedBox3d box = bounding_box(cloud.points);
    lo = box.min();
    hi = box.max();
  }
  std::array<std::uint64_t, 15> by_return{};
  by_return[0] = n;  // all first returns
  std::string out = laz::las_header_block(
      {o.version_minor, o.point_format, record, header, 0, n, by_return, o.scale, o.offset, lo, hi});
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const std::size_t start = out.size();
    for (int a = 0; a < 3; ++a) {
      const double q = std::round((cloud.points[i][a] - o.offset[a]) / o.scale[a]);
      if (!(std::abs(q) <= 2147483647.0))
        throw std::invalid_argument("write_las: coordinate does not fit scale/offset");
      put_le<std::int32_t>(out, std::int32_t(q));
    }
    out.append(record - 12, '\0');
    out[start + 14] = char(o.point_format >= 6 ? 0x11 : 0x09);  // return 1 of 1
    const int c = classes.empty() ? 1 : classes[i];
    if (o.point_format >= 6) out[start + 16] = char(c & 0xff);
    else out[start + 15] = char(c & 0x1f);
  }
  write_file_atomic(path, out);
}

}  // namespace lodrefine
