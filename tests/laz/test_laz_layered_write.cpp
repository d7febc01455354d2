// LASzip's layered compressor as the encoder writes a chunk (src/laz/laz_layered_write.cpp,
// internal to laz): the first record raw, the chunk's point count, every layer's byte size, then the
// layers; a layer whose field never changes in the chunk left out (size 0). Records of four
// scanner channels read back as written.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "laz/laz_items.h"
#include "support/io_fixtures.h"
#include "support/laz_fixtures.h"

using namespace lodrefine;

namespace {

using fixtures::peek;
using fixtures::point14;
using fixtures::poke;
using fixtures::write_laz14;

constexpr std::size_t kLayers = 9;  // POINT14: XY and returns, Z, class, flags, intensity, angle, user, source, time

// One chunk of `records` (30 bytes each) as the layered encoder writes it.
std::string chunk_of(const std::vector<std::string>& records) {
  const auto enc = laz::layered_chunk_encoder({{laz::kPoint14, 30, 3}}, 30);
  for (const std::string& r : records) enc->add(reinterpret_cast<const unsigned char*>(r.data()));
  const std::vector<unsigned char> bytes = enc->finish();
  return std::string(bytes.begin(), bytes.end());
}

std::vector<std::uint32_t> layer_sizes(const std::string& chunk) {
  std::vector<std::uint32_t> sizes;
  for (std::size_t i = 0; i < kLayers; ++i) sizes.push_back(peek<std::uint32_t>(chunk, 30 + 4 + 4 * i));
  return sizes;
}

}  // namespace

TEST(LazLayeredWrite, AChunkIsTheFirstRecordTheCountTheSizesAndTheLayers) {
  std::vector<std::string> records;
  for (int k = 0; k < 5; ++k) records.push_back(point14(1000 + 7 * k, 2.0, 0));
  const std::string chunk = chunk_of(records);
  EXPECT_EQ(chunk.substr(0, 30), records[0]);     // the first record raw
  EXPECT_EQ(peek<std::uint32_t>(chunk, 30), 5u);  // the chunk's points, the first among them
  const std::vector<std::uint32_t> sizes = layer_sizes(chunk);
  EXPECT_GT(sizes[0], 0u);                                                             // x changes
  for (std::size_t i = 1; i < kLayers; ++i) EXPECT_EQ(sizes[i], 0u) << "layer " << i;  // nothing else does
  std::size_t total = 30 + 4 + 4 * kLayers;
  for (std::uint32_t s : sizes) total += s;
  EXPECT_EQ(chunk.size(), total);
}

TEST(LazLayeredWrite, ALayerIsWrittenWhenItsFieldChanges) {
  std::vector<std::string> records;
  for (int k = 0; k < 5; ++k) {
    std::string r = point14(1000, 2.0 + k, 0);  // the GPS time changes
    poke<std::int32_t>(r, 8, 50 * k);           // and z
    records.push_back(r);
  }
  const std::vector<std::uint32_t> sizes = layer_sizes(chunk_of(records));
  EXPECT_GT(sizes[1], 0u);  // Z
  EXPECT_GT(sizes[8], 0u);  // GPS time
  for (std::size_t i : {2u, 3u, 4u, 5u, 6u, 7u}) EXPECT_EQ(sizes[i], 0u) << "layer " << i;
}

TEST(LazLayeredWrite, FourChannelsReadBackAsWritten) {
  std::string all;
  for (int k = 0; k < 400; ++k) {
    std::string r = point14(100 * (k % 17) - 800, 10.0 + 0.001 * k, k % 4);
    poke<std::int32_t>(r, 4, 3 * k);
    poke<std::uint16_t>(r, 12, std::uint16_t(40 * (k % 9)));
    r[16] = char(k % 3 == 0 ? 6 : 2);  // class
    all += r;
  }
  const std::string path = write_laz14("channels.laz", 30, all, 128);
  EXPECT_TRUE(fixtures::las_records(path) == all);
}
