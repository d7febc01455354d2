// The LAS public header block the LAZ codec and the LAS reader and writer share
// (src/laz/las_header.cpp): the point formats' record lengths and the header block's bytes.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <string>

#include "lodrefine/base/text.h"
#include "lodrefine/laz/las_header.h"
#include "lodrefine/laz/laz.h"

using namespace lodrefine;
using io_text::get_le;

namespace {

template <class T>
T at(const std::string& bytes, std::size_t offset) {
  return get_le<T>(reinterpret_cast<const unsigned char*>(bytes.data()) + offset);
}

laz::HeaderBlock block(int minor, int format, std::uint64_t count) {
  laz::HeaderBlock b;
  b.version_minor = minor;
  b.format_byte = format | 0x80;
  b.record_length = las_min_record_length(format) + 2;
  b.point_offset = 1000;
  b.vlr_count = 1;
  b.count = count;
  b.by_return = {count - 1, 1};
  b.scale = Vec3(0.01, 0.01, 0.001);
  b.offset = Vec3(93000, 436000, 0);
  b.min = Vec3(93001, 436002, -3);
  b.max = Vec3(93101, 436202, 30);
  return b;
}

}  // namespace

TEST(LasHeader, MinimumRecordLengthsOfFormatsZeroToTen) {
  const std::uint32_t want[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  for (int f = 0; f <= 10; ++f) EXPECT_EQ(las_min_record_length(f), want[f]) << "format " << f;
  EXPECT_THROW(las_min_record_length(11), std::invalid_argument);
  EXPECT_THROW(las_min_record_length(-1), std::invalid_argument);
}

TEST(LasHeader, Version12BlockHoldsTheFieldsAtTheirOffsets) {
  const std::string h = laz::las_header_block(block(2, 3, 500));
  ASSERT_EQ(h.size(), std::size_t(laz::kHeaderSize12));
  EXPECT_EQ(h.substr(0, 4), "LASF");
  EXPECT_EQ(int(h[24]), 1);
  EXPECT_EQ(int(h[25]), 2);
  EXPECT_EQ(h.substr(26, 9), "lodrefine");
  EXPECT_EQ(at<std::uint16_t>(h, 94), 227);    // header size
  EXPECT_EQ(at<std::uint32_t>(h, 96), 1000u);  // offset to the point data
  EXPECT_EQ(at<std::uint32_t>(h, 100), 1u);    // VLRs
  EXPECT_EQ(std::uint8_t(h[104]), 0x83);       // format 3, compressed
  EXPECT_EQ(at<std::uint16_t>(h, 105), 36);    // record length
  EXPECT_EQ(at<std::uint32_t>(h, 107), 500u);  // legacy count
  EXPECT_EQ(at<std::uint32_t>(h, 111), 499u);  // first returns
  EXPECT_EQ(at<std::uint32_t>(h, 115), 1u);    // second returns
  EXPECT_EQ(at<double>(h, 131), 0.01);         // x scale
  EXPECT_EQ(at<double>(h, 147), 0.001);        // z scale
  EXPECT_EQ(at<double>(h, 155), 93000.0);      // x offset
  EXPECT_EQ(at<double>(h, 179), 93101.0);      // max x
  EXPECT_EQ(at<double>(h, 187), 93001.0);      // min x
  EXPECT_EQ(at<double>(h, 219), -3.0);         // min z
}

TEST(LasHeader, Version14CountsAre64BitAndFormatsSixToTenLeaveTheLegacyOnesZero) {
  const std::string h = laz::las_header_block(block(4, 6, 5000000000ull));
  ASSERT_EQ(h.size(), std::size_t(laz::kHeaderSize14));
  EXPECT_EQ(at<std::uint16_t>(h, 94), 375);
  EXPECT_EQ(at<std::uint32_t>(h, 107), 0u);  // legacy count
  EXPECT_EQ(at<std::uint32_t>(h, 111), 0u);
  EXPECT_EQ(at<std::uint64_t>(h, 227), 0u);             // waveform data packet record
  EXPECT_EQ(at<std::uint64_t>(h, 235), 0u);             // first EVLR
  EXPECT_EQ(at<std::uint32_t>(h, 243), 0u);             // EVLR count
  EXPECT_EQ(at<std::uint64_t>(h, 247), 5000000000ull);  // the 64-bit count
  EXPECT_EQ(at<std::uint64_t>(h, 255), 4999999999ull);  // first returns
  // Formats 0-5 fill the legacy count when it fits, in 1.4 too; 1.3 has the waveform field.
  EXPECT_EQ(at<std::uint32_t>(laz::las_header_block(block(4, 1, 7)), 107), 7u);
  EXPECT_EQ(at<std::uint32_t>(laz::las_header_block(block(4, 1, 1ull << 33)), 107), 0u);
  EXPECT_EQ(laz::las_header_block(block(3, 1, 7)).size(), std::size_t(laz::kHeaderSize13));
}
