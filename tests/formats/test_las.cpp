// LAS reading: every point format 0–10 in the versions that define it, written by the test
// itself, read back exactly; class filters; lying and truncated headers. LAZ: tests/laz/test_laz.cpp.
#include <gtest/gtest.h>

#include "support/cli_fixtures.h"
#include "support/io_fixtures.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <tuple>

#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

using fixtures::poke;
using fixtures::temp_path;
using fixtures::write_bytes;

std::string read_bytes(const std::string& path) { return cli_fixtures::slurp(path); }

// Georeferenced points on a millimetre grid (the LAS scale), so they read back exactly.
PointCloud sample_points() {
  PointCloud c;
  for (int i = 0; i < 50; ++i)
    c.points.push_back(Vec3(85123.456 + 0.125 * i, 447987.654 - 0.25 * i, 1.234 + 0.001 * i));
  return c;
}

std::vector<int> sample_classes(std::size_t n, int big) {
  std::vector<int> c;
  for (std::size_t i = 0; i < n; ++i) c.push_back(i % 3 == 0 ? 6 : i % 3 == 1 ? 2 : big);
  return c;
}

LasWriteOptions opts(int minor, int format) {
  LasWriteOptions o;
  o.version_minor = minor;
  o.point_format = format;
  o.offset = Vec3(85000, 447000, 0);
  return o;
}

// A valid LAS file's bytes (version 1.minor, format), for the header-lie tests.
std::string valid_las(int minor = 2, int format = 1) {
  const std::string path = temp_path("valid.las");
  write_las(path, sample_points(), {}, opts(minor, format));
  return read_bytes(path);
}

void expect_error(const std::string& bytes, const std::string& fault) {
  fixtures::expect_bytes_refused("bad.las", bytes, fault, [](const std::string& path) { read_cloud(path); });
}

}  // namespace

TEST(Las, EveryFormatAndVersionReadsBackExactly) {
  const PointCloud pts = sample_points();
  int files = 0;
  for (int minor : {2, 3, 4}) {
    for (int format = 0; format <= 10; ++format) {
      if (format >= 6 && minor < 4) continue;  // formats 6–10 are LAS 1.4
      for (std::uint32_t extra : {0u, 7u}) {   // extra bytes after the format's fields are skipped
        SCOPED_TRACE("LAS 1." + std::to_string(minor) + " format " + std::to_string(format) + " +" +
                     std::to_string(extra));
        LasWriteOptions o = opts(minor, format);
        o.record_length = las_min_record_length(format) + extra;
        const std::string path = temp_path("f.las");
        write_las(path, pts, sample_classes(pts.points.size(), 9), o);
        const LasHeader h = read_las_header(path);
        EXPECT_EQ(h.version_minor, minor);
        EXPECT_EQ(h.point_format, format);
        EXPECT_EQ(h.record_length, o.record_length);
        EXPECT_EQ(h.point_count, pts.points.size());
        EXPECT_EQ(fs::file_size(path), h.point_offset + pts.points.size() * o.record_length);
        EXPECT_EQ(sniff_file(path), FileKind::Las);
        EXPECT_EQ(cloud_point_count(path), pts.points.size());
        const PointCloud back = read_cloud(path);
        ASSERT_EQ(back.points.size(), pts.points.size());
        double worst = 0;
        for (std::size_t i = 0; i < pts.points.size(); ++i)
          worst = std::max(worst, (back.points[i] - pts.points[i]).norm());
        EXPECT_LT(worst, 1e-9);  // integer millimetres · 0.001 + offset, in double
        const PointCloud walls = read_cloud(path, {{6}});
        EXPECT_EQ(walls.points.size(), 17u);  // i % 3 == 0 of 50
        for (std::size_t i = 0; i < walls.points.size(); ++i) EXPECT_EQ(walls.points[i], back.points[3 * i]);
        EXPECT_EQ(read_cloud(path, {{2, 9}}).points.size(), 33u);
        EXPECT_EQ(read_cloud(path, {{3}}).points.size(), 0u);
        ++files;
      }
    }
  }
  EXPECT_EQ(files, 2 * (6 * 3 + 5));
}

TEST(Las, ClassificationWidthFollowsTheFormat) {
  // Class 200: formats 6–10 keep the full byte; 0–5 have 5 bits (200 & 31 = 8), so a file of
  // an old format with a high class matches 8, and bits 5–7 (flags) never leak into the class.
  const PointCloud pts = sample_points();
  const std::string p6 = temp_path("f6.las"), p1 = temp_path("f1.las");
  write_las(p6, pts, sample_classes(pts.points.size(), 200), opts(4, 6));
  EXPECT_EQ(read_cloud(p6, {{200}}).points.size(), 16u);
  EXPECT_EQ(read_cloud(p6, {{8}}).points.size(), 0u);
  write_las(p1, pts, sample_classes(pts.points.size(), 8), opts(2, 1));
  std::string bytes = read_bytes(p1);
  const std::size_t off = 227, rec = 28;
  for (std::size_t i = 0; i < pts.points.size(); ++i)
    bytes[off + i * rec + 15] = char(bytes[off + i * rec + 15] | 0xE0);
  write_bytes("f1.las", bytes);
  EXPECT_EQ(read_cloud(p1, {{8}}).points.size(), 16u);
}

TEST(Las, ScaleAndOffsetInDouble) {
  // 7-digit northings at 0.1 mm: float would lose decimetres, double keeps them.
  PointCloud pts;
  pts.points = {{123456.7891, 5801234.5678, 45.6789}, {123457.0001, 5801235.0002, -3.0003}};
  LasWriteOptions o = opts(4, 7);
  o.scale = Vec3::Constant(0.0001);
  o.offset = Vec3(100000, 5800000, 0);
  const std::string path = temp_path("s.las");
  write_las(path, pts, {}, o);
  const PointCloud back = read_cloud(path);
  ASSERT_EQ(back.points.size(), 2u);
  for (int i = 0; i < 2; ++i) EXPECT_LT((back.points[i] - pts.points[i]).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(Las, PlyAndLasOfOneCloudAgree) {
  const PointCloud pts = sample_points();
  const std::string las = temp_path("c.las"), ply = temp_path("c.ply");
  write_las(las, pts, {}, opts(3, 3));
  write_ply(ply, pts);
  EXPECT_EQ(sniff_file(ply), FileKind::Ply);
  const PointCloud a = read_cloud(las), b = read_cloud(ply);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) EXPECT_LT((a.points[i] - b.points[i]).norm(), 1e-9);
  std::size_t n = 0;
  stream_cloud(las, {}, [&](const Vec3& p) { EXPECT_EQ(p, a.points[n++]); });
  EXPECT_EQ(n, a.points.size());
  try {
    read_cloud(ply, {{2}});
    ADD_FAILURE() << "class filter on a PLY accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs a LAS cloud"), std::string::npos) << e.what();
  }
}

TEST(Las, LyingAndTruncatedHeadersAreOneClearError) {
  const std::string good = valid_las(2, 1);
  const std::string good14 = valid_las(4, 6);
  {
    std::string b = good;
    poke<std::uint32_t>(b, 107, 0xffffffffu);  // 4 billion points in a 1.6 kB file
    expect_error(b, "header declares 4294967295 points of 28 bytes");
  }
  {
    std::string b = good14;
    poke<std::uint64_t>(b, 247, std::uint64_t(1) << 62);
    expect_error(b, "header declares 4611686018427387904 points");
  }
  {
    std::string b = good;
    poke<std::uint32_t>(b, 107, 49);  // 1.4 legacy vs 64-bit count
    expect_error(b.substr(0, b.size() - 100), "points of 28 bytes but the file holds only");
  }
  {
    std::string b = valid_las(4, 1);
    poke<std::uint32_t>(b, 107, 49);
    expect_error(b, "legacy point count 49 disagrees with the 64-bit count 50");
  }
  expect_error(good.substr(0, good.size() - 1), "(truncated?)");
  expect_error(good.substr(0, 100), "LAS header truncated");
  expect_error("LASF", "LAS header truncated");
  // One field of a valid header changed: (file, edit, expected fault).
  const std::vector<std::tuple<const std::string*, std::function<void(std::string&)>, std::string>> lies = {
      {&good, [](std::string& b) { poke<std::uint16_t>(b, 105, 19); },
       "point record length 19 is below the 28 bytes of point format 1"},
      {&good, [](std::string& b) { b[104] = 11; }, "unknown point data format 11"},
      {&good, [](std::string& b) { poke<std::uint32_t>(b, 96, 100); }, "point data offset 100 lies inside the header"},
      {&good, [](std::string& b) { poke<std::uint32_t>(b, 96, 1u << 30); },
       "point data offset 1073741824 is beyond the end of the file"},
      {&good, [](std::string& b) { poke<std::uint16_t>(b, 94, 100); }, "header size 100 is below the 227 bytes"},
      {&good14, [](std::string& b) { poke<std::uint16_t>(b, 94, 227); },
       "header size 227 is below the 375 bytes of LAS 1.4"},
      {&good, [](std::string& b) { b[24] = 2; }, "unsupported LAS version 2.2"},
      {&good, [](std::string& b) { poke<double>(b, 131, 0.0); }, "scale factor of x is zero or not finite"},
      {&good, [](std::string& b) { poke<double>(b, 171, std::numeric_limits<double>::quiet_NaN()); },
       "offset of z is not finite"},
      {&good, [](std::string& b) { poke<double>(b, 139, 1e6); }, "has a coordinate beyond 1e9 m"},  // y = Y · 1e6 m
  };
  for (const auto& [base, edit, fault] : lies) {
    std::string b = *base;
    edit(b);
    expect_error(b, fault);
  }
  {
    std::string b = good;
    poke<std::uint32_t>(b, 107, 0);  // an empty cloud is read as empty, not an error
    EXPECT_EQ(read_cloud(write_bytes("empty.las", b)).points.size(), 0u);
  }
}

TEST(Las, CompressedBitsWithoutALaszipVlrAreOneClearError) {
  for (int bit : {0x80, 0x40}) {
    std::string b = valid_las(2, 1);
    b[104] = char(b[104] | bit);
    expect_error(b, "compressed point format bits set but no LASzip VLR");
  }
}

TEST(Las, OtherFilesGivenAsACloudSayWhatTheyAre) {
  const auto check = [](const std::string& content, const std::string& fault) {
    const std::string path = write_bytes("x.dat", content);
    try {
      read_cloud(path);
      ADD_FAILURE() << "accepted: " << content.substr(0, 20);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  };
  check("<?xml version=\"1.0\"?>\n<CityModel/>", "not a PLY or LAS point cloud: the file is XML (a CityGML model?)");
  check("{\"type\": \"CityJSON\"}", "the file is JSON (a CityJSON model?)");
  check("o b\nv 0 0 0\n", "not a PLY file");
  check("\x01\x02garbage", "not a PLY file");
}

using cli_fixtures::Cli;
using cli_fixtures::run_cli;

TEST(Las, RefineCropAndEvalTakeLasWithClasses) {
  SynthOptions so;
  so.target_points = 6000;
  const SynthBuilding b = make_building(BuildingType::Gable, 3, so);
  const std::string dir = fs::path(temp_path("x")).parent_path().string();
  write_obj(dir + "/m.obj", b.coarse);
  write_ply(dir + "/c.ply", b.cloud);
  // The LAS holds the building's points as class 1 and as many far-away noise points of class 7.
  PointCloud mixed = b.cloud;
  std::vector<int> classes(b.cloud.points.size(), 1);
  for (std::size_t i = 0; i < b.cloud.points.size(); ++i) {
    mixed.points.push_back(b.cloud.points[i] + Vec3(0.3 * double(i % 7), -0.2 * double(i % 5), 0.5));
    classes.push_back(7);
  }
  LasWriteOptions lo;
  lo.version_minor = 4, lo.point_format = 6, lo.scale = Vec3::Constant(1e-4);
  lo.offset = (b.coarse.vertices[0] / 1000).array().floor() * 1000;
  write_las(dir + "/c.las", mixed, classes, lo);

  const Cli ply =
      run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/c.ply --out " + dir + "/r_ply.obj", dir);
  const Cli las = run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/c.las --classes 1 --out " + dir +
                              "/r_las.obj --report " + dir + "/r.json",
                          dir);
  ASSERT_EQ(ply.exit, 0) << ply.err;
  ASSERT_EQ(las.exit, 0) << las.err;
  // Same points (to 0.1 mm) give the same refined building.
  const Mesh a = read_obj(dir + "/r_ply.obj"), c = read_obj(dir + "/r_las.obj");
  ASSERT_EQ(a.vertices.size(), c.vertices.size());
  ASSERT_EQ(a.faces.size(), c.faces.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_LT((a.vertices[i] - c.vertices[i]).norm(), 2e-3);

  const Cli none =
      run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/c.las --classes 2,3 --out " + dir + "/n.obj", dir);
  EXPECT_EQ(none.exit, 2);
  EXPECT_NE(none.err.find("the cloud has no points of classes 2,3 (of " + std::to_string(mixed.points.size()) + ")"),
            std::string::npos)
      << none.err;

  fs::create_directories(dir + "/models");
  write_obj(dir + "/models/" + b.id + ".obj", b.coarse);
  const Cli crop =
      run_cli("crop --tile " + dir + "/c.las --classes 1 --models " + dir + "/models --out " + dir + "/run", dir);
  ASSERT_EQ(crop.exit, 0) << crop.err;
  EXPECT_NE(crop.out.find(std::to_string(b.cloud.points.size()) + " tile points"), std::string::npos) << crop.out;
  const PointCloud cut = read_cloud(dir + "/run/" + b.id + "/cloud.ply");
  EXPECT_GT(double(cut.points.size()), 0.8 * double(b.cloud.points.size()));
  EXPECT_LE(cut.points.size(), b.cloud.points.size());

  const Cli eval = run_cli("eval --original " + dir + "/m.obj --refined " + dir + "/r_las.obj --cloud " + dir +
                               "/c.las --classes 1 --json " + dir + "/e.json",
                           dir);
  ASSERT_EQ(eval.exit, 0) << eval.err;
  const std::string ej = read_bytes(dir + "/e.json");
  EXPECT_NE(ej.find("rmse"), std::string::npos);
}
