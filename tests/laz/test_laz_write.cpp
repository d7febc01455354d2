// LAZ writing (lodrefine/laz/laz_write.h): for every point format the encoder supports, records
// with varied fields (georeferenced coordinates, returns, classes and flags, scanner channels,
// GPS time sequences, colour, near infrared, extra bytes) go LAS -> LAZ -> our decoder with every
// byte equal; chunk boundaries; the LAZ we write decoded by an independent decoder (the npm
// package laz-perf under node, skipped without it); the real AHN3 tile re-encoded.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/laz/laz_write.h"
#include "support/cli_fixtures.h"
#include "support/io_fixtures.h"
#include "support/laz_fixtures.h"
#include "support/realdata.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

using fixtures::temp_path;

const int kLazFormats[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};

template <class T>
void put(std::string& r, std::size_t at, T v) {
  std::memcpy(&r[at], &v, sizeof v);
}
template <class T>
T get(const std::string& r, std::size_t at) {
  T v;
  std::memcpy(&v, &r[at], sizeof v);
  return v;
}

// Offsets of GPS time, RGB, NIR and the waveform packet in a record of `format` (npos: none).
constexpr std::size_t kNone = std::string::npos;
std::size_t time_at(int f) { return f == 0 || f == 2 ? kNone : f >= 6 ? 22 : 20; }
std::size_t rgb_at(int f) { return f == 2 ? 20 : f == 3 || f == 5 ? 28 : f == 7 || f == 8 || f == 10 ? 30 : kNone; }
std::size_t nir_at(int f) { return f == 8 || f == 10 ? 36 : kNone; }
std::size_t wave_at(int f) { return f == 4 ? 28 : f == 5 ? 34 : f == 9 ? 30 : f == 10 ? 38 : kNone; }

// Records like a scan: a random walk in RD New coordinates (mm), pulses of 1–5 returns sharing a
// GPS time, interleaved flight lines (time sequences that jump and come back), classes, flags,
// colour runs and grey, several scanner channels (formats 6–8), constant and varying extra
// bytes. Every `wild`-th record is random bytes: any record must survive. Without `channels`
// every point is on scanner channel 2.
std::string scan_records(int format, std::uint32_t length, std::size_t n, unsigned seed, std::size_t wild = 97,
                         bool channels = true) {
  std::mt19937 rng(seed);
  const auto rnd = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::string all;
  std::string r(length, '\0');
  std::int32_t x = 84900000, y = 447500000, z = 2500;
  double times[3] = {228671.7556, 229000.125, 1.0e9 + 0.5};
  int line = 0, ret = 1, returns = 1;
  std::uint16_t rgb[3] = {1000, 2000, 3000};
  std::uint64_t wave_offset = 60;
  std::uint32_t wave_size = 256;
  const bool layered = format >= 6;
  for (std::size_t i = 0; i < n; ++i) {
    if (wild && i % wild == wild - 1) {
      for (auto& c : r) c = char(rnd(0, 255));
      all += r;
      continue;
    }
    if (ret > returns || ret < 1) {
      returns = rnd(1, layered ? 7 : 5), ret = 1;
      if (rnd(0, 20) == 0) line = rnd(0, 2);  // another flight line's time sequence
      times[line] += rnd(0, 10) == 0 ? rnd(1, 100000) * 1e-3 : 1e-5;
    }
    x += rnd(-300, 300) + (rnd(0, 500) == 0 ? rnd(-20000000, 20000000) : 0);
    y += rnd(-300, 300);
    z = ret == 1 ? z + rnd(-50, 50) : z - rnd(0, 3000);
    put<std::int32_t>(r, 0, x), put<std::int32_t>(r, 4, y), put<std::int32_t>(r, 8, z);
    put<std::uint16_t>(r, 12, std::uint16_t(rnd(0, 3) == 0 ? rnd(0, 65535) : 100 + rnd(0, 40)));
    const int cls = rnd(0, 5) == 0 ? rnd(0, layered ? 255 : 31) : (ret == returns ? 2 : 6);
    if (layered) {
      const int r14 = rnd(0, 200) == 0 ? rnd(0, 15) : ret, n14 = rnd(0, 200) == 0 ? rnd(0, 15) : returns;
      r[14] = char(r14 | n14 << 4);
      const int channel = !channels ? 2 : rnd(0, 30) == 0 ? rnd(0, 3) : int(i / 500) % 2;
      r[15] = char((rnd(0, 10) == 0 ? rnd(0, 15) : 0) | channel << 4 | (line & 1) << 6 | (rnd(0, 50) == 0) << 7);
      r[16] = char(cls);
      r[17] = char(rnd(0, 8) == 0 ? rnd(0, 255) : 7);
      put<std::int16_t>(r, 18, std::int16_t(rnd(0, 4) == 0 ? rnd(-30000, 30000) : -1200 + line * 100));
      put<std::uint16_t>(r, 20, std::uint16_t(line == 2 ? 65535 : 17 + line));
    } else {
      r[14] = char(ret | returns << 3 | (line & 1) << 6 | (rnd(0, 50) == 0) << 7);
      r[15] = char(cls | (rnd(0, 10) == 0 ? rnd(0, 7) << 5 : 0));
      r[16] = char(rnd(0, 3) == 0 ? rnd(-90, 90) : -12 + line);
      r[17] = char(rnd(0, 8) == 0 ? rnd(0, 255) : 7);
      put<std::uint16_t>(r, 18, std::uint16_t(line == 2 ? 65535 : 17 + line));
    }
    if (time_at(format) != kNone) put<double>(r, time_at(format), times[line]);
    if (rgb_at(format) != kNone) {
      if (rnd(0, 5) == 0)
        for (auto& c : rgb) c = std::uint16_t(rnd(0, 7) == 0 ? rnd(0, 65535) : (c + rnd(-300, 300)) & 0xffff);
      const bool grey = rnd(0, 4) == 0;
      for (int k = 0; k < 3; ++k) put<std::uint16_t>(r, rgb_at(format) + 2 * k, grey ? rgb[0] : rgb[k]);
    }
    if (nir_at(format) != kNone) put<std::uint16_t>(r, 36, std::uint16_t(rnd(0, 2) == 0 ? rgb[1] : rnd(0, 65535)));
    if (wave_at(format) != kNone) {
      // Packets one after the other in the waveform file, sometimes repeated or far away.
      const std::size_t w = wave_at(format);
      const int jump = rnd(0, 20);
      r[w] = char(jump == 0 ? rnd(0, 255) : 1);
      wave_offset = jump == 1   ? wave_offset
                    : jump == 2 ? wave_offset + (std::uint64_t(rnd(1, 9)) << 33)
                    : jump == 3 ? wave_offset - std::uint64_t(rnd(0, 1000000))
                                : wave_offset + wave_size;
      wave_size = jump == 4 ? std::uint32_t(rnd(0, 1 << 30)) : wave_size;
      put<std::uint64_t>(r, w + 1, wave_offset);
      put<std::uint32_t>(r, w + 9, wave_size);
      put<float>(r, w + 13, float(rnd(0, 100000)) * 1e-3f);
      for (int k = 0; k < 3; ++k) put<float>(r, w + 17 + 4 * k, float(rnd(-1000, 1000)) * 1e-6f);
    }
    const std::size_t extra = las_min_record_length(format);
    for (std::size_t k = extra; k < length; ++k)
      r[k] = char(k == extra ? 42 : k == extra + 1 ? (i / 10) % 256 : rnd(0, 255));
    all += r;
    ++ret;
  }
  return all;
}

std::string write_records(const std::string& path, const LasRecordFormat& format, bool compressed,
                          const std::string& records, std::uint32_t chunk_size = 50000) {
  LasRecordWriter w(path, format, compressed, chunk_size);
  const auto* p = reinterpret_cast<const unsigned char*>(records.data());
  for (std::size_t at = 0; at < records.size(); at += w.record_length()) w.add(p + at);
  w.finish();
  return path;
}

std::string read_records(const std::string& path) { return fixtures::las_records(path); }

// Index of the first differing record, for messages.
std::size_t first_difference(const std::string& a, const std::string& b, std::uint32_t length) {
  std::size_t i = 0;
  while (i < std::min(a.size(), b.size()) && a[i] == b[i]) ++i;
  return i / length;
}

LasRecordFormat format_of(int f, std::uint32_t extra) {
  LasRecordFormat o;
  o.version_minor = f >= 6 ? 4 : f >= 4 ? 3 : 2;
  o.point_format = f;
  o.record_length = las_min_record_length(f) + extra;
  o.offset = Vec3(0, 0, -10);
  return o;
}

}  // namespace

// LAS -> LAZ -> records, every format, with and without extra bytes: the same bytes, the same
// header (count, bounds, format), the same points; and the file is smaller than the LAS.
TEST(LazWrite, EveryFormatRoundTripsThroughLasAndLaz) {
  for (const int f : kLazFormats) {
    for (const std::uint32_t extra : {0u, 5u}) {
      SCOPED_TRACE("format " + std::to_string(f) + ", " + std::to_string(extra) + " extra bytes");
      const LasRecordFormat o = format_of(f, extra);
      const std::string want = scan_records(f, o.record_length, 7000, unsigned(f * 10 + extra));
      const std::string las = write_records(temp_path("in.las"), o, false, want);
      ASSERT_TRUE(read_records(las) == want);
      const std::string laz = write_records(temp_path("out.laz"), o, true, read_records(las), 3000);
      const std::string got = read_records(laz);
      ASSERT_EQ(got.size(), want.size());
      EXPECT_TRUE(got == want) << "first difference in record " << first_difference(got, want, o.record_length);

      const LasHeader a = read_las_header(las), b = read_las_header(laz);
      EXPECT_FALSE(a.compressed);
      EXPECT_TRUE(b.compressed);
      EXPECT_EQ(b.point_format, f);
      EXPECT_EQ(b.record_length, o.record_length);
      EXPECT_EQ(b.point_count, 7000u);
      EXPECT_EQ(b.version_minor, o.version_minor);
      EXPECT_EQ(a.min, b.min);
      EXPECT_EQ(a.max, b.max);
      EXPECT_EQ(b.scale, o.scale);
      EXPECT_EQ(b.offset, o.offset);
      EXPECT_EQ(read_cloud(laz).points, read_cloud(las).points);
      EXPECT_LT(fs::file_size(laz), fs::file_size(las) * 3 / 4);
    }
  }
}

// Random bytes in every field (any record is a valid LAS record to the codec): still equal.
TEST(LazWrite, RandomRecordsRoundTrip) {
  for (const int f : kLazFormats) {
    SCOPED_TRACE("format " + std::to_string(f));
    const LasRecordFormat o = format_of(f, 3);
    const std::string want = scan_records(f, o.record_length, 2000, 7u + unsigned(f), 1);
    const std::string got = read_records(write_records(temp_path("random.laz"), o, true, want, 700));
    EXPECT_TRUE(got == want) << "first difference in record " << first_difference(got, want, o.record_length);
  }
}

// Chunk boundaries: 0, 1, chunk size ± 1, exactly one and two chunks, and one point per chunk.
TEST(LazWrite, ChunkBoundaries) {
  for (const int f : kLazFormats) {
    for (const std::size_t n : {0, 1, 2, 99, 100, 101, 200, 201}) {
      for (const std::uint32_t chunk : {100u, 1u}) {
        if (chunk == 1 && n > 101) continue;
        SCOPED_TRACE("format " + std::to_string(f) + ", " + std::to_string(n) + " points, chunks of " +
                     std::to_string(chunk));
        const LasRecordFormat o = format_of(f, 2);
        const std::string want = scan_records(f, o.record_length, n, unsigned(n) + 3u);
        const std::string laz = write_records(temp_path("chunks.laz"), o, true, want, chunk);
        EXPECT_EQ(read_las_header(laz).point_count, n);
        EXPECT_TRUE(read_records(laz) == want);
      }
    }
  }
}

// What the writer refuses: unknown formats, versions that cannot hold the format, chunks of 0.
TEST(LazWrite, RefusesFormatsItCannotWrite) {
  const std::string path = temp_path("x.laz");
  for (const int f : {11, -1}) {
    LasRecordFormat o;
    o.version_minor = 4;
    o.point_format = f;
    EXPECT_THROW(LasRecordWriter(path, o, true), std::invalid_argument) << f;
  }
  LasRecordFormat o = format_of(6, 0);
  o.version_minor = 2;
  EXPECT_THROW(LasRecordWriter(path, o, false), std::invalid_argument);
  EXPECT_THROW(LasRecordWriter(path, format_of(1, 0), true, 0), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

// The independent decoder: laz-perf (LASzip as WASM, npm) decodes the LAZ we write, every format
// it reads (not the waveform formats 4, 5, 9, 10) with extra bytes, several chunks and scanner channels, to the records
// we encoded. Format 8 on one channel: where a chunk returns to an earlier channel, LASzip's RGBNIR14 reader predicts
// the infrared from the previous channel but keeps it in the current one (our decoder and encoder do the same), while
// laz-perf keeps it in the previous one; the two disagree there.
TEST(LazWrite, LazPerfDecodesWhatWeWrite) {
  if (const std::string missing = fixtures::lazperf_missing(); !missing.empty()) GTEST_SKIP() << missing;
  for (const int f : kLazFormats) {
    if (wave_at(f) != kNone) continue;  // laz-perf reads no waveform packets
    for (const std::uint32_t extra : {0u, 4u}) {
      SCOPED_TRACE("format " + std::to_string(f) + ", " + std::to_string(extra) + " extra bytes");
      const LasRecordFormat o = format_of(f, extra);
      const std::string want = scan_records(f, o.record_length, 5001, 100u + unsigned(f), 0, f != 8);
      const std::string laz = write_records(temp_path("ours.laz"), o, true, want, 1000);
      const std::string dump = temp_path("ours.ref");
      const std::string cmd = fixtures::lazperf_command(laz, dump);
      ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
      const std::string ref = cli_fixtures::slurp(dump);
      ASSERT_EQ(ref.size(), want.size());
      EXPECT_TRUE(ref == want) << "first difference in record " << first_difference(ref, want, o.record_length);
    }
  }
}

// The real AHN3 tile (LASzip-written, format 1): decode -> encode -> decode gives the same
// records; and our compressed chunks and chunk table are LASzip's byte for byte (only the
// header and VLR texts differ).
TEST(LazWrite, RealAhn3ReEncodesToTheSamePoints) {
  REQUIRE_REALDATA("3dfier/example_data/ahn3/ahn3_cropped_1.laz");
  const LasHeader h = read_las_header(data_path.string());
  LasRecordFormat o;
  o.version_minor = h.version_minor;
  o.point_format = h.point_format;
  o.record_length = h.record_length;
  o.scale = h.scale;
  o.offset = h.offset;
  const std::string want = read_records(data_path.string());
  ASSERT_EQ(want.size(), 640510u * 28u);
  const std::string laz = write_records(temp_path("ahn3.laz"), o, true, want);
  EXPECT_TRUE(read_records(laz) == want);
  const LasHeader b = read_las_header(laz);
  EXPECT_EQ(b.point_count, h.point_count);
  EXPECT_EQ(b.min, h.min);
  EXPECT_EQ(b.max, h.max);
  // The point data: from the chunk table offset at its start to the end of the file.
  const auto point_data = [](const std::string& file) {
    const auto offset = get<std::uint32_t>(file, 96);
    return file.substr(offset + 8);
  };
  EXPECT_TRUE(point_data(cli_fixtures::slurp(laz)) == point_data(cli_fixtures::slurp(data_path.string())));
}

// Waveform LAZ is checked as the other formats: the WAVEPACKET13 item in version 1 only, the
// packet item present, a truncated chunk one line.
TEST(LazWrite, WaveformItemsAreChecked) {
  const LasRecordFormat o = format_of(4, 0);
  const std::string good =
      cli_fixtures::slurp(write_records(temp_path("f4.laz"), o, true, scan_records(4, o.record_length, 500, 9u), 200));
  const std::size_t items = get<std::uint16_t>(good, 94) + 54 + 34;
  ASSERT_EQ(get<std::uint16_t>(good, items + 12), 9);  // POINT10, GPSTIME11, WAVEPACKET13
  const auto refused = [](std::string bytes, const std::string& fault) {
    fixtures::expect_bytes_refused("bad.laz", bytes, fault, read_records);
  };
  std::string b = good;
  fixtures::poke<std::uint16_t>(b, items + 12 + 4, 2);
  refused(b, "LASzip item version 2 (point format 4 is read in version 1)");
  b = good;
  fixtures::poke<std::uint16_t>(b, items + 12, 0);  // the packet item made extra bytes
  refused(b, "LASzip item type 0 does not fit point format 4");
  const auto table = get<std::uint64_t>(good, get<std::uint32_t>(good, 96));
  b = good.substr(0, std::size_t(table) - 300) + good.substr(std::size_t(table));
  fixtures::poke<std::uint64_t>(b, get<std::uint32_t>(good, 96), table - 300);
  refused(b, "does not fit the point data before the chunk table");
}
