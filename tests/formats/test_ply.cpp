// PLY: ascii and binary clouds, streamed and read whole, written with a scalar.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "lodrefine/formats/ply.h"
#include "support/io_fixtures.h"
#include "support/ply_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
namespace fs = std::filesystem;

namespace {

void expect_ply_error(const std::string& content, const std::string& fault) {
  expect_input_error(write_bytes("bad.ply", content), fault, [](const std::string& p) { read_ply(p); });
}

const std::vector<Vec3> kPoints = {{85123.4567, 447987.6543, 1.25}, {-3.5, 0.0, 7.0}, {1e5, 5.801234567e6, -2.0}};

template <class T>
std::string binary_ply(bool big_endian, const char* type) {
  std::string s = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\ncomment fixture\nelement vertex 3\nproperty " + type + " x\nproperty " + type +
                  " y\nproperty " + type + " z\nend_header\n";
  for (const auto& p : kPoints)
    for (int k = 0; k < 3; ++k) put<T>(s, T(p[k]), big_endian);
  return s;
}

}  // namespace

TEST(IoPly, AsciiWithExtraPropertiesAndElementsBeforeAndAfter) {
  const std::string path = write_bytes("a.ply",
                                       "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\n"
                                       "element camera 1\r\nproperty float fx\r\nproperty list uchar int ids\r\n"
                                       "element vertex 3\r\nproperty uchar red\r\nproperty double z\r\n"
                                       "property float x\r\nproperty list uint8 float32 extra\r\nproperty int y\r\n"
                                       "element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
                                       "500.5 3 1 2 3\r\n"
                                       "255 1.5 10 2 0.5 0.25 -7\r\n"
                                       "0 -2.0 11.25 0 8\r\n"
                                       "1 3e1 12 1 9 9\r\n"
                                       "3 0 1 2\r\n");
  const PointCloud c = read_ply(path);
  ASSERT_EQ(c.points.size(), 3u);
  EXPECT_EQ(c.points[0], Vec3(10, -7, 1.5));
  EXPECT_EQ(c.points[1], Vec3(11.25, 8, -2));
  EXPECT_EQ(c.points[2], Vec3(12, 9, 30));
}

TEST(IoPly, BinaryLittleAndBigEndianFloatAndDouble) {
  for (bool be : {false, true}) {
    const PointCloud d = read_ply(write_bytes("d.ply", binary_ply<double>(be, "double")));
    ASSERT_EQ(d.points.size(), kPoints.size());
    for (std::size_t i = 0; i < kPoints.size(); ++i) EXPECT_EQ(d.points[i], kPoints[i]) << be << " " << i;
    const PointCloud f = read_ply(write_bytes("f.ply", binary_ply<float>(be, "float32")));
    ASSERT_EQ(f.points.size(), kPoints.size());
    for (std::size_t i = 0; i < kPoints.size(); ++i)
      EXPECT_EQ(f.points[i], kPoints[i].cast<float>().cast<double>()) << be << " " << i;
  }
}

TEST(IoPly, BinaryIntegerCoordinatesExtraPropertiesAndFaceElement) {
  for (bool be : {false, true}) {
    std::string s = std::string("ply\nformat ") + (be ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement face 2\nproperty list uchar int vertex_indices\nproperty ushort flags\n"
                    "element vertex 2\nproperty short x\nproperty char label\nproperty uint y\nproperty int8 z\n"
                    "property double t\nend_header\n";
    put<std::uint8_t>(s, 3, be), put<std::int32_t>(s, 0, be), put<std::int32_t>(s, 1, be), put<std::int32_t>(s, 0, be);
    put<std::uint16_t>(s, 7, be);
    put<std::uint8_t>(s, 0, be), put<std::uint16_t>(s, 9, be);
    put<std::int16_t>(s, -300, be), put<std::int8_t>(s, 5, be),
        put<std::uint32_t>(s, 900000000u, be);  // beyond int16, within the 1e9 m limit
    put<std::int8_t>(s, -5, be), put<double>(s, 1.0, be);
    put<std::int16_t>(s, 12, be), put<std::int8_t>(s, 0, be), put<std::uint32_t>(s, 1, be);
    put<std::int8_t>(s, 127, be), put<double>(s, 2.0, be);
    const PointCloud c = read_ply(write_bytes("i.ply", s));
    ASSERT_EQ(c.points.size(), 2u);
    EXPECT_EQ(c.points[0], Vec3(-300, 9e8, -5)) << be;
    EXPECT_EQ(c.points[1], Vec3(12, 1, 127)) << be;
  }
}

TEST(IoPly, StreamYieldsTheSamePointsAsRead) {
  PointCloud cloud;
  for (int i = 0; i < 100000; ++i) cloud.points.emplace_back(i * 0.001, -i * 0.5, std::sin(i));
  const std::string path = temp_path("s.ply");
  write_ply(path, cloud, Vec3(85000, 447000, 0));
  const PointCloud r = read_ply(path);
  std::size_t n = 0, mismatches = 0;
  stream_ply(path, [&](const Vec3& p) {
    mismatches += n >= r.points.size() || p != r.points[n];
    ++n;
  });
  EXPECT_EQ(n, cloud.points.size());
  EXPECT_EQ(mismatches, 0u);
  ASSERT_EQ(r.points.size(), cloud.points.size());
  EXPECT_LT((r.points[777] - cloud.points[777] - Vec3(85000, 447000, 0)).norm(), 1e-9);
}

TEST(IoPly, WritesOptionalScalar) {
  PointCloud cloud;
  cloud.points = kPoints;
  const std::vector<float> dist = {0.5f, 1.5f, 2.5f};
  const std::string path = temp_path("sc.ply");
  write_ply(path, cloud, Vec3::Zero(), &dist, "distance");
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("property float distance\nend_header\n"), std::string::npos);
  EXPECT_EQ(bytes.size(), bytes.find("end_header\n") + 11 + 3 * 28);
  EXPECT_EQ(read_ply(path).points, kPoints);
  const std::vector<float> wrong = {1.0f};
  EXPECT_THROW(write_ply(temp_path("w.ply"), cloud, Vec3::Zero(), &wrong), std::runtime_error);
  EXPECT_FALSE(fs::exists(temp_path("w.ply")));
}

TEST(IoPly, MalformedInputsThrowOneLineInputErrors) {
  const std::string good = binary_ply<double>(false, "double");
  expect_input_error(temp_path("missing.ply"), "cannot open", [](const std::string& p) { read_ply(p); });
  expect_ply_error("", "empty file");
  expect_ply_error("OFF\n3 1 0\n", "not a PLY file");
  expect_ply_error(std::string("\0\1\2\3junkjunk", 12), "not a PLY file");
  expect_ply_error("ply\n" + std::string(5000, 'x'), "not a PLY file");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "truncated");
  expect_ply_error("ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n", "unknown format");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n1\n",
                   "unknown property type 'float128'");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
                   "no scalar property z");
  expect_ply_error("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n3 0 1 2\n",
                   "no vertex element");
  expect_ply_error(good.substr(0, good.size() - 5), "more data than the file holds");
  std::string lie = good;
  lie.replace(lie.find("vertex 3"), 8, "vertex 99999999999");
  expect_ply_error(lie, "header declares 99999999999 vertex records");
  std::string lie2 = good;
  lie2.replace(lie2.find("vertex 3"), 8, "vertex 4");
  expect_ply_error(lie2, "more data than the file holds");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n1 2 3\n4 5\n  \n\n  \n",
      "data ends after 1 of 2 vertices");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n1 nan 3\n",
      "non-finite");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n1 2 3abc\n",
      "bad ASCII value '3abc'");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n1 +-2 3\n",
      "bad ASCII value '+-2'");
  std::string inf = good;
  const double bad = std::numeric_limits<double>::infinity();
  std::memcpy(&inf[inf.size() - 8], &bad, 8);
  expect_ply_error(inf, "vertex 2 has a non-finite coordinate");
  // A face element before the vertices whose lists run past the end of the file.
  expect_ply_error(
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int vi\n"
      "element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x03\x01",
      "data ends inside element 'face'");
}
