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

template <class T>
T peek(const std::string& bytes, std::size_t at) {
  T v;
  std::memcpy(&v, &bytes[at], sizeof v);
  return v;
}
template <class T>
T peek(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string records(const std::string& path) { return fixtures::las_records(path); }

void expect_error(const std::string& bytes, const std::string& fault) {
  fixtures::expect_bytes_refused("bad.laz", bytes, fault, records);
}

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
    const std::string ref = cli_fixtures::slurp(dump), ours = records(laz.string());
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
    expect_error(b, fault);
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
  expect_error(good.substr(0, good.size() - 10), "LAZ chunk");
  expect_error(good.substr(0, 2000), "LAZ chunk table offset");
  {
    const std::size_t cut = 300000;
    std::string b = good.substr(0, cut) + good.substr(table);
    poke<std::uint64_t>(b, point_offset, cut);
    expect_error(b, "does not fit the point data before the chunk table");
  }
  {
    // The header's count cut to the first chunk: exactly its points, the rest is not read.
    // Then that chunk's compressed bytes zeroed: the decoder runs out of data (one line) or
    // decodes other points; it never crashes or hangs.
    std::string b = good;
    poke<std::uint32_t>(b, 107, 50000);
    const std::string first = records(write_bytes("first_chunk.laz", b));
    EXPECT_EQ(first, records(data_path.string()).substr(0, first.size()));
    EXPECT_EQ(first.size(), 50000u * 28u);
    std::fill(b.begin() + point_offset + 8 + 28, b.begin() + point_offset + 8 + 20000, '\0');
    try {
      records(write_bytes("zeroed.laz", b));
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
      EXPECT_EQ(records(e.path().string()), "");
      continue;
    }
    const LasHeader t = read_las_header(twin.string());
    EXPECT_EQ(h.point_format, t.point_format) << e.path();
    EXPECT_EQ(h.record_length, t.record_length) << e.path();
    EXPECT_EQ(h.point_count, t.point_count) << e.path();
    EXPECT_GT(h.point_count, 0u) << e.path();
    EXPECT_EQ(records(e.path().string()), records(twin.string())) << e.path();
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
    const std::string want = records(corpus_dir() + "/" + seed);
    const auto check = [&](const std::string& bytes, bool truncated) {
      const std::string path = write_bytes("edit.laz", bytes);
      try {
        const LasHeader h = read_las_header(path);
        const std::string got = records(path);
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
      const std::string ours = records(e.path().string());
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

namespace {

// Format-6 records (30 bytes + `extra`): returns 1 of 1, scanner channel `channel`.
std::string point14(std::int32_t x, double gps, int channel, std::size_t extra = 0) {
  std::string r(30 + extra, '\0');
  poke<std::int32_t>(r, 0, x);
  r[14] = 0x11;
  r[15] = char((channel & 3) << 4);
  r[16] = 2;
  poke<double>(r, 22, gps);
  return r;
}

std::string write_laz(const std::string& name, std::uint32_t record_length, const std::string& records,
                      std::uint32_t chunk = 50000) {
  const std::string path = temp_path(name);
  LasRecordFormat f;
  f.version_minor = 4, f.point_format = 6, f.record_length = record_length;
  LasRecordWriter w(path, f, true, chunk);
  for (std::size_t at = 0; at < records.size(); at += record_length)
    w.add(reinterpret_cast<const unsigned char*>(records.data() + at));
  w.finish();
  return path;
}

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
  std::string b = cli_fixtures::slurp(write_laz("gps_source.laz", 30 + kExtra, all));
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
    expect_error(b, "GPS time switches sequence without end");
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
  expect_error(cli_fixtures::slurp(write_laz("models.laz", 30 + 4200, records(4200, 8, true))),
               "more than 16384 extra-byte models in one chunk");
  for (const bool vary : {true, false}) {
    const std::string want = records(1000, 12, vary);
    EXPECT_TRUE(fixtures::las_records(write_laz("models_ok.laz", 30 + 1000, want)) == want);
  }
}

namespace {

// Resident memory of this process (kB).
long resident_kb() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

// BYTE v2 models are made on a chunk's second point: 40 chunks of one point with 65,000 extra
// bytes each made 65,000 models (130 MB) per chunk, 272 MB peak for 40 points. Read in a child
// whose peak resident memory is measured.
TEST(Laz, OnePointChunksOfManyExtraBytesMakeNoModels) {
  constexpr std::uint32_t kExtra = 65000;
  const std::string path = temp_path("one_point_chunks.laz");
  {
    LasRecordFormat f;
    f.point_format = 0, f.record_length = 20 + kExtra;
    LasRecordWriter w(path, f, true, 1);
    std::string r(20 + kExtra, '\0');
    for (int k = 0; k < 40; ++k) {
      poke<std::int32_t>(r, 0, k);
      r[20 + std::size_t(k)] = char(k);
      w.add(reinterpret_cast<const unsigned char*>(r.data()));
    }
    w.finish();
  }
  const long before = resident_kb();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::size_t n = 0;
    stream_las_records(path, [&](const LasHeader&, const unsigned char*) { ++n; });
    ::_exit(n == 40 ? 0 : 1);
  }
  int status = 0;
  struct rusage usage {};
  ASSERT_EQ(::wait4(child, &status, 0, &usage), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_LT(usage.ru_maxrss - before, 64 * 1024) << "peak " << usage.ru_maxrss << " kB, " << before << " kB before";
}
