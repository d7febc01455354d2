// The LAS public header block shared by the LAZ codec and the LAS reader and writer
// (las_header.h): the point formats' record lengths, and the header block the writers put first.
#include "lodrefine/laz/las_header.h"

#include <array>
#include <stdexcept>
#include <string>

#include "lodrefine/base/text.h"
#include "lodrefine/laz/laz.h"

namespace lodrefine {

using io_text::put_le;
using laz::kHeaderSize12;
using laz::kHeaderSize13;
using laz::kHeaderSize14;

std::string laz::las_header_block(const laz::HeaderBlock& b) {
  const std::uint32_t header = b.version_minor == 4   ? kHeaderSize14
                               : b.version_minor == 3 ? kHeaderSize13
                                                      : kHeaderSize12;
  std::string out;
  out += "LASF";
  put_le<std::uint16_t>(out, 0);  // file source id
  put_le<std::uint16_t>(out, 0);  // global encoding
  out.append(16, '\0');           // GUID
  out += char(1), out += char(b.version_minor);
  std::string sys = "lodrefine";
  sys.resize(32, '\0');
  out += sys + sys;  // system identifier, generating software
  put_le<std::uint16_t>(out, 1);
  put_le<std::uint16_t>(out, 2026);
  put_le<std::uint16_t>(out, std::uint16_t(header));
  put_le<std::uint32_t>(out, b.point_offset);
  put_le<std::uint32_t>(out, b.vlr_count);
  out += char(b.format_byte);
  put_le<std::uint16_t>(out, std::uint16_t(b.record_length));
  // Formats 6–10 must leave the legacy counts at 0 (LAS 1.4); others fill them when they fit.
  const bool legacy_ok = (b.format_byte & 0x3f) < 6 && b.count <= 0xffffffffu;
  put_le<std::uint32_t>(out, legacy_ok ? std::uint32_t(b.count) : 0);
  for (int i = 0; i < 5; ++i) put_le<std::uint32_t>(out, legacy_ok ? std::uint32_t(b.by_return[i]) : 0);
  for (int a = 0; a < 3; ++a) put_le<double>(out, b.scale[a]);
  for (int a = 0; a < 3; ++a) put_le<double>(out, b.offset[a]);
  for (int a = 0; a < 3; ++a) put_le<double>(out, b.max[a]), put_le<double>(out, b.min[a]);
  if (b.version_minor >= 3) put_le<std::uint64_t>(out, 0);  // waveform data packet record
  if (b.version_minor >= 4) {
    put_le<std::uint64_t>(out, 0);  // first EVLR
    put_le<std::uint32_t>(out, 0);  // EVLR count
    put_le<std::uint64_t>(out, b.count);
    for (std::uint64_t r : b.by_return) put_le<std::uint64_t>(out, r);
  }
  return out;
}

std::uint32_t las_min_record_length(int point_format) {
  static constexpr std::array<std::uint32_t, 11> kLength = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (point_format < 0 || point_format > 10) throw std::invalid_argument("LAS point format out of range");
  return kLength[std::size_t(point_format)];
}

}  // namespace lodrefine
