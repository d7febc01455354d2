#include <gtest/gtest.h>

#include "support/ply_fixtures.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "lodrefine/io/obj.h"
#include "lodrefine/io/ply.h"
#include "lodrefine/io/files.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

// A fresh per-test path under the GoogleTest temp dir.
std::string temp_path(const std::string& name) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(testing::TempDir()) / ("lodrefine_io_" + std::to_string(::getpid())) / info->name();
  fs::create_directories(dir);
  return (dir / name).string();
}

std::string write_bytes(const std::string& name, const std::string& content) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// Expects InputError whose one-line message names the file and contains `fault`.
template <class F>
void expect_input_error(const std::string& path, const std::string& fault, F&& read) {
  try {
    read(path);
    ADD_FAILURE() << "no InputError for " << path << " (expected '" << fault << "')";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(fault), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

void expect_obj_error(const std::string& content, const std::string& fault) {
  expect_input_error(write_bytes("bad.obj", content), fault, [](const std::string& p) { read_obj(p); });
}

void expect_ply_error(const std::string& content, const std::string& fault) {
  expect_input_error(write_bytes("bad.ply", content), fault, [](const std::string& p) { read_ply(p); });
}

const char* kCubeTopObj =
    "# id: should-lose-to-o\n"
    "o building_42\n"
    "v 85123.4567 447987.6543 10.0\n"
    "v 85124.4567 447987.6543 10.0\n"
    "v 85124.4567 447988.6543 10.0\n"
    "v 85123.4567 447988.6543 10.0\n"
    "v 85123.4567 447987.6543 0.0\n"
    "v 85124.4567 447987.6543 0.0\n"
    "g RoofSurface\n"
    "f 1 2 3 4\n"
    "g WallSurface\n"
    "f 5/1 6/2 2/3 1/4\n"
    "g GroundSurface\n"
    "usemtl whatever\n"
    "f -1 -2 -3\n"
    "g something\n"
    "usemtl RoofSurface_mat\n"
    "f 1//1 2//2 6//3\n";


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

TEST(IoObj, GeoreferencedRoundTripKeepsTenthOfMillimetre) {
  Mesh m;
  m.id = "NL.IMBAG.Pand.0363100012345678";
  m.vertices = {{0.0, 0.0, 0.0}, {4.0, 0.0, 0.0}, {4.0, 3.0, 0.0}, {0.0, 3.0, 2.5}};
  m.faces = {{{0, 1, 2}, Semantic::Wall, 0}, {{0, 2, 3}, Semantic::Roof, 1}, {{3, 2, 1, 0}, Semantic::Ground, 2}};
  const Vec3 origin(85123.4567, 447987.6543, 1.2345);
  const std::string path = temp_path("rt.obj");
  write_obj(path, m, origin);
  const Mesh r = read_obj(path);
  ASSERT_EQ(r.vertices.size(), m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    EXPECT_LT((r.vertices[i] - (m.vertices[i] + origin)).cwiseAbs().maxCoeff(), 1e-4) << i;
  EXPECT_NEAR(r.vertices[0].x(), 85123.4567, 1e-6);
  EXPECT_NEAR(r.vertices[0].y(), 447987.6543, 1e-6);
  EXPECT_EQ(r.id, m.id);
  ASSERT_EQ(r.faces.size(), 3u);
  // Grouped Wall, Roof, Ground, so the file order equals the input order here.
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(r.faces[k].v, m.faces[k].v);
    EXPECT_EQ(r.faces[k].sem, m.faces[k].sem);
    EXPECT_EQ(r.faces[k].source, int(k));
  }
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "# lodrefine");
}

TEST(IoObj, GroupsAndMaterialsGiveSemanticsAndIdComesFromO) {
  const Mesh m = read_obj(write_bytes("sem.obj", kCubeTopObj));
  EXPECT_EQ(m.id, "building_42");
  ASSERT_EQ(m.vertices.size(), 6u);
  EXPECT_DOUBLE_EQ(m.vertices[2].y(), 447988.6543);  // double precision, not tinyobjloader's float
  ASSERT_EQ(m.faces.size(), 4u);
  EXPECT_EQ(m.faces[0].sem, Semantic::Roof);
  EXPECT_EQ(m.faces[1].sem, Semantic::Wall);
  EXPECT_EQ(m.faces[1].v, (std::vector<int>{4, 5, 1, 0}));
  EXPECT_EQ(m.faces[2].sem, Semantic::Ground);  // group wins over an unknown material
  EXPECT_EQ(m.faces[2].v, (std::vector<int>{5, 4, 3}));  // negative indices are relative
  EXPECT_EQ(m.faces[3].sem, Semantic::Roof);  // unknown group: the material decides
  EXPECT_EQ(m.faces[3].source, 3);
}

TEST(IoObj, IdFallsBackToCommentThenFileStem) {
  const std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_EQ(read_obj(write_bytes("x.obj", "# id: B-17\n" + body)).id, "B-17");
  EXPECT_EQ(read_obj(write_bytes("house_9.obj", body)).id, "house_9");
}

TEST(IoObj, ShortFacesAreSkippedAndCounted) {
  int skipped = -1;
  const Mesh m = read_obj(write_bytes("short.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\nf 3\nf\n"), &skipped);
  EXPECT_EQ(skipped, 3);  // the bare `f` too
  ASSERT_EQ(m.faces.size(), 1u);
  EXPECT_EQ(m.faces[0].source, 0);
  expect_obj_error("v 0 0 0\nv 1 0 0\nf 1 2\n", "no faces with 3 or more vertices (1 skipped)");
}

TEST(IoObj, GeoreferencedCoordinatesReadBackExactly) {
  // The nearest double to each decimal, bit for bit: 7-digit northings, and values that a
  // digit-by-digit parser (tinyobjloader's own) gets 1-2 ulp wrong.
  const double xs[] = {5779123.4567, 435685.799, 85123.4567, 14.056, 5801234.567, -0.1};
  std::string obj;
  for (double x : xs) {
    char line[96];
    std::snprintf(line, sizeof line, "v %.4f %.4f %.3f\n", x, -x, x);
    obj += line;
  }
  obj += "v 5779123.4567 5779123.4567e0 +5779123.4567\nf 1 2 3\n";
  const Mesh m = read_obj(write_bytes("geo.obj", obj));
  ASSERT_EQ(m.vertices.size(), std::size(xs) + 1);
  for (std::size_t i = 0; i < std::size(xs); ++i) {
    EXPECT_EQ(m.vertices[i].x(), xs[i]) << i;
    EXPECT_EQ(m.vertices[i].y(), -xs[i]) << i;
  }
  EXPECT_EQ(m.vertices.back(), Vec3(5779123.4567, 5779123.4567, 5779123.4567));
}

TEST(IoObj, BlanksPolygonsAndBareStatements) {
  // Any whitespace separates (tabs, \v, \f, a lone \r inside a line); polygons stay polygons; a
  // bare `g` or `usemtl` clears its semantic; `mtllib` files are never opened; the `o` name is
  // kept as written.
  const Mesh m = read_obj(write_bytes("blanks.obj",
                                      "mtllib /no/such/file.mtl\no  bldg\t7 \n"
                                      "v\v0 0 0\nv 4\t0 0\r\nv 4 3\f0\nv 2 4 0\nv 0 3 0\n"
                                      "g\tRoofSurface\nf 1 2\r3 4 5\n"
                                      "usemtl WallSurface\ng\nf 5 4 3\n"
                                      "usemtl\nf 1 2 3\n"));
  EXPECT_EQ(m.id, "bldg\t7");
  ASSERT_EQ(m.vertices.size(), 5u);
  EXPECT_EQ(m.vertices[2], Vec3(4, 3, 0));
  ASSERT_EQ(m.faces.size(), 3u);
  EXPECT_EQ(m.faces[0].v, (std::vector<int>{0, 1, 2, 3, 4}));  // not triangulated
  EXPECT_EQ(m.faces[0].sem, Semantic::Roof);
  EXPECT_EQ(m.faces[1].sem, Semantic::Wall);   // the bare `g` cleared Roof: the material decides
  EXPECT_EQ(m.faces[2].sem, Semantic::Other);  // and the bare `usemtl` cleared that
}

TEST(IoObj, FaceIndicesBeyondTheVerticesNameTheLine) {
  // Forward references are fine as long as the vertex comes; one that never does is refused on
  // the face's line, whatever tinyobjloader would make of it.
  EXPECT_EQ(read_obj(write_bytes("fwd.obj", "f 1 2 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n")).faces[0].v,
            (std::vector<int>{0, 1, 3}));
  const std::string path = write_bytes("far.obj", "f 1 2 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n");
  try {
    read_obj(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": line 1: face index 5 out of range (4 vertices)");
  }
  expect_obj_error("v 0 0 0\nf -1 -2 -3\n", "line 2: face index -2 out of range (1 vertices so far)");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "line 4: bad face vertex '1/1/1/1'");
}

TEST(IoObj, MalformedInputsThrowOneLineInputErrors) {
  expect_input_error(temp_path("missing.obj"), "cannot open", [](const std::string& p) { read_obj(p); });
  expect_input_error(fs::path(temp_path("d")).parent_path().string(), "directory",
                     [](const std::string& p) { read_obj(p); });
  expect_obj_error("", "empty file");
  expect_obj_error("  \n\n", "empty file");
  expect_obj_error("# only a comment\nv 1 2 3\n", "no faces");
  expect_obj_error("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: non-finite");
  expect_obj_error("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n", "line 2: non-finite");
  expect_obj_error("v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: bad number '1e999'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", "bad face vertex");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: face index 4 out of range");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "face index -4 out of range");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "face index 0");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "bad face vertex 'x'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 +-1 2\n", "line 4: bad face vertex '+-1'");  // two signs
  expect_obj_error("v 0 0 0\nv +-1 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: bad number '+-1'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nhello world\nf 1 2 3\n", "line 4: unknown statement 'hello'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1.5 2.", "line 5: vertex with fewer than 3");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1.5 2.0 3.0e", "line 5: bad number");
  expect_obj_error(std::string("v 0 0 0\n\x7f\x45\x4c\x46\x02\x01\x01\0\0\0", 18), "line 2: binary data");
}

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
    put<std::int16_t>(s, -300, be), put<std::int8_t>(s, 5, be), put<std::uint32_t>(s, 900000000u, be);  // beyond int16, within the 1e9 m limit
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
  stream_ply(path, [&](const Vec3& p) { mismatches += n >= r.points.size() || p != r.points[n]; ++n; });
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
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n1 2 3\n4 5\n  \n\n  \n",
                   "data ends after 1 of 2 vertices");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n1 nan 3\n",
                   "non-finite");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n1 2 3abc\n",
                   "bad ASCII value '3abc'");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n1 +-2 3\n",
                   "bad ASCII value '+-2'");
  std::string inf = good;
  const double bad = std::numeric_limits<double>::infinity();
  std::memcpy(&inf[inf.size() - 8], &bad, 8);
  expect_ply_error(inf, "vertex 2 has a non-finite coordinate");
  // A face element before the vertices whose lists run past the end of the file.
  expect_ply_error("ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int vi\n"
                   "element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x03\x01",
                   "data ends inside element 'face'");
}

TEST(IoWrite, MissingDirectoryGivesOneLineErrorAndNoFile) {
  const std::string dir = temp_path("no_such_dir");
  const std::string path = dir + "/model.obj";
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.faces = {{{0, 1, 2}, Semantic::Roof, 0}};
  try {
    write_obj(path, m);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("cannot write " + path + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(IoWrite, AtomicWriteReplacesAndLeavesNoTempOnFailure) {
  const std::string path = temp_path("t.txt");
  write_file_atomic(path, "old");
  write_file_atomic(path, "new content");
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "new content");
  Mesh bad;
  bad.vertices = {{0, 0, 0}};
  bad.faces = {{{0, 1, 2}, Semantic::Wall, 0}};
  EXPECT_THROW(write_obj(path, bad), std::runtime_error);  // the old file survives a failed write
  std::ifstream again(path);
  std::getline(again, s);
  EXPECT_EQ(s, "new content");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(fs::path(path).parent_path())) ++entries;
  EXPECT_EQ(entries, 1u);  // no leftover .tmp.<pid>
}

TEST(IoObj, CoordinatesBeyondAMillionKilometresAreRefused) {
  // Welding and hashing grids would overflow: a broken file, not a building.
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/huge.obj";
  FILE* f = std::fopen(path.c_str(), "w");
  std::fputs("v 1e12 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n", f);
  std::fclose(f);
  try {
    read_obj(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond 1e9 m"), std::string::npos) << e.what();
  }
}
