// LASzip's layered compressor (compressor 3, point formats 6-10) as the decoder reads it
// (src/laz/laz_layered.cpp): a GPS time layer that only switches sequence ends at once, and the
// BYTE14 models made per extra byte and channel are bounded per chunk.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "lodrefine/formats/las.h"
#include "lodrefine/laz/laz_write.h"
#include "support/cli_fixtures.h"
#include "support/io_fixtures.h"
#include "support/laz_fixtures.h"

using namespace lodrefine;

namespace {

using fixtures::expect_laz_refused;
using fixtures::peek;
using fixtures::point14;
using fixtures::poke;
using fixtures::temp_path;
using fixtures::write_laz14;

}  // namespace

namespace {

// A format-6 LAZ of one chunk whose second point says "GPS time changed" and whose GPS time
// layer is `gps_bytes` of 0xff: every code the time decoder reads is a switch to another time
// sequence. The chunk keeps its size (the table stays valid): 32 random extra bytes a point fill
// it, and their layers give their bytes to the time layer.
std::string gps_switch_loop_laz(std::size_t gps_bytes) {
  constexpr std::size_t kExtra = 32;
  std::mt19937 rng(5);
  std::string all = point14(0, 1.0, 0, kExtra) + point14(100, 2.0, 0, kExtra);
  while (all.size() < (gps_bytes + 4096) / kExtra * (30 + kExtra)) {
    std::string r = point14(100, 2.0, 0, kExtra);
    for (std::size_t i = 30; i < r.size(); ++i) r[i] = char(rng());
    all += r;
  }
  std::string b = cli_fixtures::slurp(write_laz14("gps_source.laz", 30 + kExtra, all));
  const std::size_t chunk = peek<std::uint32_t>(b, 96) + 8;
  const std::size_t sizes = chunk + 30 + kExtra + 4, layers = 9 + kExtra;
  std::vector<std::uint32_t> size(layers);
  for (std::size_t i = 0; i < layers; ++i) size[i] = peek<std::uint32_t>(b, sizes + 4 * i);
  std::size_t rest = 0;
  for (std::size_t i = 1; i < layers; ++i) rest += size[i];
  EXPECT_GE(rest, gps_bytes);
  for (std::size_t i = 1; i < layers; ++i) poke<std::uint32_t>(b, sizes + 4 * i, i == 8 ? std::uint32_t(rest) : 0);
  const std::size_t data = sizes + 4 * layers + size[0];
  std::fill(b.begin() + std::ptrdiff_t(data), b.begin() + std::ptrdiff_t(data + rest), char(0xff));
  return b;
}

}  // namespace

// A time layer that only ever switches sequence consumes no bytes: the decoder ends it after a
// switch to each other sequence, at once, where it used to spin until the layer ran out (12 s for
// 64 KB, minutes for 1 MB).
TEST(Laz, GpsTimeSwitchLoopFailsAtOnce) {
  for (const std::size_t kb : {64, 1024}) {
    SCOPED_TRACE(std::to_string(kb) + " KB of switches");
    const std::string b = gps_switch_loop_laz(kb * 1024);
    const auto t0 = std::chrono::steady_clock::now();
    expect_laz_refused(b, "GPS time switches sequence without end");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  }
}

// BYTE14 models are made per extra byte and channel as a layer first changes, bounded per chunk:
// 4,200 changing extra bytes in four channels (16,800 models, 34 MB) are refused; 1,000 in four
// channels read back as written, changing or not.
TEST(Laz, ExtraByteModelsAreBoundedPerChunk) {
  const auto records = [](std::size_t extra, std::size_t n, bool vary) {
    std::mt19937 rng(9);
    std::string all;
    for (std::size_t k = 0; k < n; ++k) {
      std::string r = point14(std::int32_t(k), 1.0 + double(k), int(k % 4), extra);
      if (vary)
        for (std::size_t i = 30; i < r.size(); ++i) r[i] = char(rng());
      all += r;
    }
    return all;
  };
  expect_laz_refused(cli_fixtures::slurp(write_laz14("models.laz", 30 + 4200, records(4200, 8, true))),
                     "more than 16384 extra-byte models in one chunk");
  for (const bool vary : {true, false}) {
    const std::string want = records(1000, 12, vary);
    EXPECT_TRUE(fixtures::las_records(write_laz14("models_ok.laz", 30 + 1000, want)) == want);
  }
}
