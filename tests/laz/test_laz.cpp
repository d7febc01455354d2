// LAZ reading (src/laz/laz.cpp): the real AHN3 tiles' header, bounds and class histogram; every
// decoded record byte for byte equal to an independent decoder's (the npm package laz-perf,
// LASzip compiled to WASM, run by node); lying VLRs, chunk tables and truncated chunks give one
// line naming the file. Tests needing ../shared, node or laz-perf skip cleanly without them.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/laz/laz_write.h"
#include "support/cli_fixtures.h"
#include "support/io_fixtures.h"
#include "support/laz_fixtures.h"
#include "support/realdata.h"
#include "support/test_paths.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

using fixtures::poke;
using fixtures::temp_path;
using fixtures::write_bytes;

const char* const kAhn3 = "3dfier/example_data/ahn3/ahn3_cropped_1.laz";
const char* const kAhn3Small = "3dfier/example_data/ahn3/ahn3_cropped_2.laz";

using fixtures::expect_laz_refused;
using fixtures::las_records;
using fixtures::peek;

}  // namespace

TEST(Laz, RealAhn3HeaderBoundsAndClassHistogram) {
  REQUIRE_REALDATA(kAhn3);
  const LasHeader h = read_las_header(data_path.string());
  EXPECT_TRUE(h.compressed);
  EXPECT_EQ(h.point_format, 1);
  EXPECT_EQ(h.record_length, 28u);
  EXPECT_EQ(h.point_count, 640510u);
  EXPECT_EQ(cloud_point_count(data_path.string()), 640510u);

  // Expected values from laz-perf's decoding of the same file (node, once).
  std::int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::map<int, std::uint64_t> classes;
  std::uint64_t n = 0, intensity = 0;
  double t0 = 1e300, t1 = -1e300;
  stream_las_records(data_path.string(), [&](const LasHeader&, const unsigned char* r) {
    for (int a = 0; a < 3; ++a) {
      const std::int32_t v = peek<std::int32_t>(r + 4 * a);
      lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
    }
    ++classes[r[15]];
    intensity += peek<std::uint16_t>(r + 12);
    const double t = peek<double>(r + 20);
    t0 = std::min(t0, t), t1 = std::max(t1, t);
    ++n;
  });
  EXPECT_EQ(n, 640510u);
  EXPECT_EQ(lo[0], 84808300);
  EXPECT_EQ(lo[1], 447412800);
  EXPECT_EQ(lo[2], -568);
  EXPECT_EQ(hi[0], 84999999);
  EXPECT_EQ(hi[1], 447641299);
  EXPECT_EQ(hi[2], 19398);
  // The header's box is the points' box (scale 1 mm, offset 0).
  EXPECT_NEAR(h.min.x(), lo[0] * 0.001, 1e-9);
  EXPECT_NEAR(h.max.y(), hi[1] * 0.001, 1e-9);
  EXPECT_NEAR(h.min.z(), lo[2] * 0.001, 1e-9);
  const std::map<int, std::uint64_t> want = {{1, 196137}, {2, 195988}, {6, 246753}, {9, 267}, {26, 1365}};
  EXPECT_EQ(classes, want);
  EXPECT_EQ(intensity, 96620494u);
  EXPECT_DOUBLE_EQ(t0, 228671.75560657517);
  EXPECT_DOUBLE_EQ(t1, 230768.79729183033);

  // The class filter and the double coordinates of the ordinary cloud reader.
  const PointCloud buildings = read_cloud(data_path.string(), {{6}});
  EXPECT_EQ(buildings.points.size(), 246753u);
  const PointCloud all = read_cloud(data_path.string());
  ASSERT_EQ(all.points.size(), 640510u);
  const Eigen::AlignedBox3d box(all.points.front());
  Eigen::AlignedBox3d b = box;
  for (const auto& p : all.points) b.extend(p);
  EXPECT_NEAR(b.min().x(), 84808.300, 1e-9);
  EXPECT_NEAR(b.max().y(), 447641.299, 1e-9);
}

TEST(Laz, DecodedRecordsEqualLazPerfByteForByte) {
  REQUIRE_REALDATA(kAhn3);
  if (const std::string missing = fixtures::lazperf_missing(); !missing.empty()) GTEST_SKIP() << missing;
  for (const char* rel : {kAhn3, kAhn3Small}) {
    const fs::path laz = fixtures::realdata_dir() / rel;
    const std::string dump = temp_path(laz.filename().string() + ".ref");
    const std::string cmd = fixtures::lazperf_command(laz.string(), dump);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const std::string ref = cli_fixtures::slurp(dump), ours = las_records(laz.string());
    ASSERT_EQ(ours.size(), ref.size()) << rel;
    const LasHeader h = read_las_header(laz.string());
    ASSERT_EQ(ours.size(), h.point_count * h.record_length);
    std::size_t first = 0;
    while (first < ours.size() && ours[first] == ref[first]) ++first;
    EXPECT_EQ(first, ours.size()) << rel << ": first difference in point " << first / h.record_length << ", byte "
                                  << first % h.record_length;
  }
}

TEST(Laz, LyingHeadersAndTruncatedChunksAreOneLine) {
  REQUIRE_REALDATA(kAhn3Small);
  const std::string good = cli_fixtures::slurp(data_path.string());
  const std::uint32_t point_offset = peek<std::uint32_t>(good, 96);
  const std::uint64_t table = peek<std::uint64_t>(good, point_offset);
  const std::size_t vlr = peek<std::uint16_t>(good, 94) + 54;  // the LASzip VLR's payload (its only VLR)
  ASSERT_EQ(good.substr(vlr - 52, 14), "laszip encoded");
  ASSERT_LT(table, good.size());

  const std::vector<std::pair<std::function<void(std::string&)>, std::string>> lies = {
      // point count beyond what the chunks hold (5 chunks of 50,000 points)
      {[](std::string& b) { poke<std::uint32_t>(b, 107, 250001); },
       "header declares 250001 points but the LAZ chunks hold only 250000"},
      {[](std::string& b) { poke<std::uint32_t>(b, 107, 0xffffffffu); }, "header declares 4294967295 points"},
      // chunk table offset outside the file, inside the header, or -1 with a bad tail
      {[&](std::string& b) { poke<std::uint64_t>(b, point_offset, b.size() + 10); }, "LAZ chunk table offset"},
      {[&](std::string& b) { poke<std::uint64_t>(b, point_offset, 12); }, "lies outside the point data"},
      {[&](std::string& b) { poke<std::uint64_t>(b, point_offset, ~std::uint64_t(0)); }, "LAZ chunk table"},
      // absurd chunk counts, a wrong table version
      {[&](std::string& b) { poke<std::uint32_t>(b, table + 4, 0xffffffffu); }, "declares 4294967295 chunks"},
      {[&](std::string& b) { poke<std::uint32_t>(b, table + 4, 0); }, "LAZ chunk table is empty"},
      {[&](std::string& b) { poke<std::uint32_t>(b, table, 7); }, "LAZ chunk table version 7"},
      // the VLR: compressor, chunk size, items, record length, VLR size
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr, 3); }, "LASzip compressor 3 does not fit point format 1"},
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr, 1); }, "LASzip compressor 1 is not supported"},
      {[&](std::string& b) { poke<std::uint32_t>(b, vlr + 12, 0); }, "LASzip chunk size 0"},
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr + 34 + 4, 1); }, "LASzip item version 1"},
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr + 34, 9); }, "LASzip item type 9 does not fit point format 1"},
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr + 34 + 6, 8); }, "does not fit point format 1"},
      {[&](std::string& b) { poke<std::uint16_t>(b, vlr + 32, 60000); }, "item list does not fit"},
      {[](std::string& b) { b[104] = char(0x80); }, "LASzip item type 7 does not fit point format 0"},
      {[](std::string& b) { poke<std::uint16_t>(b, 105, 30); }, "LASzip items hold 28 bytes per point, the header 30"},
  };
  for (const auto& [edit, fault] : lies) {
    std::string b = good;
    edit(b);
    expect_laz_refused(b, fault);
    // read_las_header refuses the same way (the table is checked before any point).
    try {
      read_las_header(write_bytes("bad_header.laz", b));
      ADD_FAILURE() << "header accepted; expected " << fault;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  }
  // Truncated files: the table is at the end, so it goes first; a file cut inside the chunks
  // but given its table back (offset fixed) has chunks that no longer fit before it.
  expect_laz_refused(good.substr(0, good.size() - 10), "LAZ chunk");
  expect_laz_refused(good.substr(0, 2000), "LAZ chunk table offset");
  {
    const std::size_t cut = 300000;
    std::string b = good.substr(0, cut) + good.substr(table);
    poke<std::uint64_t>(b, point_offset, cut);
    expect_laz_refused(b, "does not fit the point data before the chunk table");
  }
  {
    // The header's count cut to the first chunk: exactly its points, the rest is not read.
    // Then that chunk's compressed bytes zeroed: the decoder runs out of data (one line) or
    // decodes other points; it never crashes or hangs.
    std::string b = good;
    poke<std::uint32_t>(b, 107, 50000);
    const std::string first = las_records(write_bytes("first_chunk.laz", b));
    EXPECT_EQ(first, las_records(data_path.string()).substr(0, first.size()));
    EXPECT_EQ(first.size(), 50000u * 28u);
    std::fill(b.begin() + point_offset + 8 + 28, b.begin() + point_offset + 8 + 20000, '\0');
    try {
      las_records(write_bytes("zeroed.laz", b));
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("truncated or corrupt"), std::string::npos) << e.what();
    }
  }
}

namespace {

std::string corpus_dir() { return test_paths::source_dir() + "/tests/fuzz/corpus/fuzz_laz"; }

}  // namespace

// The fuzz seeds (tests/fuzz/make_corpus.py: LASzip's chunk table coding, one point per chunk,
// fixed and variable chunk sizes, formats 0–3 and 6–8 with extra bytes) read as their LAS twins.
// laz-perf decodes them to the same records (checked when they were made).
TEST(Laz, CorpusSeedsReadAsTheirLasTwins) {
  std::size_t pairs = 0;
  for (const auto& e : fs::directory_iterator(corpus_dir())) {
    if (e.path().extension() != ".laz") continue;
    fs::path twin = e.path();
    twin.replace_extension(".las");
    const LasHeader h = read_las_header(e.path().string());
    EXPECT_TRUE(h.compressed) << e.path();
    if (!fs::exists(twin)) {
      EXPECT_EQ(h.point_count, 0u) << e.path();
      EXPECT_EQ(las_records(e.path().string()), "");
      continue;
    }
    const LasHeader t = read_las_header(twin.string());
    EXPECT_EQ(h.point_format, t.point_format) << e.path();
    EXPECT_EQ(h.record_length, t.record_length) << e.path();
    EXPECT_EQ(h.point_count, t.point_count) << e.path();
    EXPECT_GT(h.point_count, 0u) << e.path();
    EXPECT_EQ(las_records(e.path().string()), las_records(twin.string())) << e.path();
    const PointCloud a = read_cloud(e.path().string(), {{6}}), b = read_cloud(twin.string(), {{6}});
    EXPECT_EQ(a.points, b.points) << e.path();
    ++pairs;
  }
  EXPECT_EQ(pairs, 7u);
}

// Every prefix and every single-byte change of a small LAZ: one line naming the file, or records
// of the declared count (a prefix missing only the coder's final padding: the same records).
// Never a crash or a hang.
TEST(Laz, EveryTruncationAndByteFlipIsOneLineOrTheSamePoints) {
  for (const char* seed : {"v12_f1_extra.laz", "v14_f8_extra.laz"}) {
    const std::string good = cli_fixtures::slurp(corpus_dir() + "/" + seed);
    ASSERT_FALSE(good.empty()) << seed;
    const std::string want = las_records(corpus_dir() + "/" + seed);
    const auto check = [&](const std::string& bytes, bool truncated) {
      const std::string path = write_bytes("edit.laz", bytes);
      try {
        const LasHeader h = read_las_header(path);
        const std::string got = las_records(path);
        if (truncated) {
          EXPECT_EQ(got, want) << seed << ": truncated at " << bytes.size();
        }
        EXPECT_EQ(got.size(), h.point_count * h.record_length);
      } catch (const InputError& e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      }
    };
    for (std::size_t n = 0; n < good.size(); ++n) check(good.substr(0, n), true);
    for (std::size_t i = 0; i < good.size(); ++i) {
      std::string b = good;
      b[i] = char(b[i] ^ 0x5a);
      check(b, false);
    }
    EXPECT_FALSE(want.empty());
  }
}

// More files, e.g. the LAZ samples of other projects, checked against laz-perf when
// LODREFINE_LAZ_SAMPLES names a folder of them (see the README): every file laz-perf decodes
// is decoded to the same bytes; files it cannot decode, we refuse with one line.
TEST(Laz, SampleFolderEqualsLazPerf) {
  const char* dir = std::getenv("LODREFINE_LAZ_SAMPLES");
  if (!dir) GTEST_SKIP() << "LODREFINE_LAZ_SAMPLES not set";
  if (const std::string missing = fixtures::lazperf_missing(); !missing.empty()) GTEST_SKIP() << missing;
  std::size_t same = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".laz") continue;
    const std::string dump = temp_path("sample.ref");
    fs::remove(dump);
    const std::string cmd = fixtures::lazperf_command(e.path().string(), dump) + " 2>/dev/null";
    const bool reference = std::system(cmd.c_str()) == 0 && fs::exists(dump) && fs::file_size(dump) > 0;
    try {
      const std::string ours = las_records(e.path().string());
      if (reference) {
        EXPECT_EQ(ours, cli_fixtures::slurp(dump)) << e.path();
        ++same;
      }
    } catch (const InputError& ex) {
      EXPECT_FALSE(reference) << e.path() << ": laz-perf decodes it, we refuse: " << ex.what();
    }
  }
  EXPECT_GT(same, 0u);
}

// A LAZ count is bounded by its chunk table, not by the file size: a 4-billion-point header over
// 6 chunks declared as huge is refused when the data runs out, having reserved little.
TEST(Laz, HugeDeclaredCountsAllocateLittle) {
  std::string b = cli_fixtures::slurp(corpus_dir() + "/v12_f0.laz");
  ASSERT_EQ(b.substr(227 + 2, 14), "laszip encoded");
  poke<std::uint32_t>(b, 227 + 54 + 12, 0xfffffff0u);  // the VLR's chunk size
  poke<std::uint32_t>(b, 107, 0xffffff00u);
  const std::string path = write_bytes("huge.laz", b);
  EXPECT_EQ(read_las_header(path).point_count, 0xffffff00u);
  EXPECT_THROW(read_cloud(path), InputError);  // beyond the default --max-points, before decoding
  CloudOptions unbounded;                      // the decoder itself, without that limit
  unbounded.max_points = std::numeric_limits<std::uint64_t>::max();
  try {
    read_cloud(path, unbounded);
    ADD_FAILURE() << "4 billion points from 500 bytes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated or corrupt"), std::string::npos) << e.what();
  }
}
