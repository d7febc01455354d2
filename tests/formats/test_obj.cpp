// OBJ: reading (tinyobjloader behind our line check) and writing georeferenced polygon soups.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "lodrefine/formats/obj.h"
#include "support/io_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
namespace fs = std::filesystem;

namespace {

void expect_obj_error(const std::string& content, const std::string& fault) {
  expect_input_error(write_bytes("bad.obj", content), fault, [](const std::string& p) { read_obj(p); });
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
  EXPECT_EQ(m.faces[2].sem, Semantic::Ground);           // group wins over an unknown material
  EXPECT_EQ(m.faces[2].v, (std::vector<int>{5, 4, 3}));  // negative indices are relative
  EXPECT_EQ(m.faces[3].sem, Semantic::Roof);             // unknown group: the material decides
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

// A refined building's faces say where they come from: `g WallSurface scan` with the coverage in
// a comment before each scan face; a face without one in the plain group. tinyobjloader (our
// reader) still takes the semantic from the group, and the provenance comes back.
TEST(IoObj, ProvenanceInGroupNamesAndCoverageInComments) {
  Mesh m;
  m.id = "b";
  m.vertices = {{0, 0, 0}, {4, 0, 0}, {4, 0, 3}, {0, 0, 3}, {0, 2, 3}};
  m.faces = {{{0, 1, 2, 3}, Semantic::Wall, 0, Provenance::Scan, 0.857},
             {{3, 2, 4}, Semantic::Roof, 1, Provenance::Model},
             {{0, 3, 4}, Semantic::Wall, 2, Provenance::Added},
             {{1, 4, 2}, Semantic::Wall, 3}};
  const std::string path = temp_path("prov.obj");
  write_obj(path, m);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("g WallSurface\nf 2 5 3\ng WallSurface scan\n# lodrefine_coverage 0.86\nf 1 2 3 4\n"
                      "g WallSurface added\nf 1 4 5\ng RoofSurface model\nf 4 3 5\n"),
            std::string::npos)
      << text;
  const Mesh r = read_obj(path);
  ASSERT_EQ(r.faces.size(), 4u);
  const Provenance expected[] = {Provenance::None, Provenance::Scan, Provenance::Added, Provenance::Model};
  const Semantic sems[] = {Semantic::Wall, Semantic::Wall, Semantic::Wall, Semantic::Roof};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(r.faces[k].provenance, expected[k]) << k;
    EXPECT_EQ(r.faces[k].sem, sems[k]) << k;
  }
}

// tests/fuzz/regressions/fuzz_obj/writer_huge_coordinate.obj: read_obj accepts any finite
// coordinate, so write_obj must print any finite coordinate readably.
TEST(BadInputRegression, ObjWriterRoundTripsHugeCoordinates) {
  // The writer prints any finite double readably; the reader refuses such a file in one line.
  const std::string path = temp_path("h.obj");
  Mesh m;
  m.id = "huge";
  m.vertices = {{1e60, 0, 0}, {0, 1, 0}, {0, 0, -1.7e308}};
  Face f;
  f.v = {0, 1, 2};
  m.faces = {f};
  write_obj(path, m);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (unsigned char c : text) EXPECT_TRUE(c == '\n' || (c >= 32 && c < 127)) << "byte " << int(c);
  EXPECT_GT(text.size(), 309u);  // -1.7e308 printed in full (309 digits)
  try {
    read_obj(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond 1e9 m"), std::string::npos) << e.what();
  }
}

// A repaired building's fins follow the solid's faces in their own group (`g fins <semantic>`):
// read_obj_model tells them apart, read_obj reads the building whole (a soup, as refine reads
// it), with each fin's semantic. Before, the fins were written among the solid's faces.
TEST(IoObj, FinsAreWrittenAfterTheSolidInTheirOwnGroup) {
  Mesh solid;
  solid.id = "house";
  solid.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  solid.faces = {{{0, 2, 1}, Semantic::Ground, 0},
                 {{0, 1, 3}, Semantic::Wall, 1},
                 {{1, 2, 3}, Semantic::Roof, 2},
                 {{2, 0, 3}, Semantic::Wall, 3}};
  Mesh fins;
  fins.vertices = {{0, 0, 1}, {0, 1, 0}, {0, 1, 2}, {0, 0, 2}};
  fins.faces = {{{0, 1, 2, 3}, Semantic::Wall, 4}};
  const std::string path = temp_path("fins.obj");
  write_obj(path, solid, fins);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t group = text.find("g fins WallSurface\nf 5 6 7 8\n");
  ASSERT_NE(group, std::string::npos) << text;
  EXPECT_EQ(text.find("\nf ", group + 20), std::string::npos) << "a solid face after the fins:\n" << text;
  const ObjModel m = read_obj_model(path);
  EXPECT_EQ(m.solid.id, "house");
  EXPECT_EQ(m.fins.id, "house");
  ASSERT_EQ(m.solid.faces.size(), 4u);
  EXPECT_EQ(m.solid.vertices.size(), 4u);
  ASSERT_EQ(m.fins.faces.size(), 1u);
  EXPECT_EQ(m.fins.faces[0].sem, Semantic::Wall);
  ASSERT_EQ(m.fins.vertices.size(), 4u);
  EXPECT_EQ(m.fins.vertices[2], Vec3(0, 1, 2));
  const Mesh all = read_obj(path);
  ASSERT_EQ(all.faces.size(), 5u);
  EXPECT_EQ(all.faces.back().sem, Semantic::Wall);
}

// A refined building's fins say where they come from as its solid's faces do: `g fins
// WallSurface model` after the solid's `g WallSurface scan` (the merge of the fins group and the
// provenance words), both read back.
TEST(IoObj, FinsCarryTheirProvenanceInTheirGroup) {
  Mesh solid;
  solid.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  solid.faces = {{{0, 2, 1}, Semantic::Ground, 0, Provenance::Model},
                 {{0, 1, 3}, Semantic::Wall, 1, Provenance::Scan, 0.5},
                 {{1, 2, 3}, Semantic::Roof, 2, Provenance::Model},
                 {{2, 0, 3}, Semantic::Wall, 3, Provenance::Added}};
  Mesh fins;
  fins.vertices = {{0, 0, 1}, {0, 1, 0}, {0, 1, 2}, {0, 0, 2}};
  fins.faces = {{{0, 1, 2, 3}, Semantic::Wall, 4, Provenance::Model}};
  const std::string path = temp_path("fins_provenance.obj");
  write_obj(path, solid, fins);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t scan = text.find("g WallSurface scan\n# lodrefine_coverage 0.50\nf 1 2 4\n"),
                    fin = text.find("g fins WallSurface model\nf 5 6 7 8\n");
  ASSERT_NE(scan, std::string::npos) << text;
  ASSERT_NE(fin, std::string::npos) << text;
  EXPECT_LT(scan, fin);
  const ObjModel m = read_obj_model(path);
  ASSERT_EQ(m.fins.faces.size(), 1u);
  EXPECT_EQ(m.fins.faces[0].provenance, Provenance::Model);
  ASSERT_EQ(m.solid.faces.size(), 4u);
  int scanned = 0;
  for (const Face& f : m.solid.faces) scanned += f.provenance == Provenance::Scan;
  EXPECT_EQ(scanned, 1);
}

// A foreign OBJ's groups: only a group named exactly `fins` (any name of its `g` line) holds
// fins; `finsbury` or `Fins` do not.
TEST(IoObj, OnlyAGroupNamedFinsHoldsFins) {
  const std::string path = write_bytes("foreign.obj",
                                       "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                       "g finsbury\nf 1 2 3\ng Fins\nf 1 2 3\n"
                                       "g RoofSurface fins\nf 1 2 3\ng fins\nf 1 3 2\ng\nf 1 2 3\n");
  const ObjModel m = read_obj_model(path);
  ASSERT_EQ(m.solid.faces.size(), 3u);
  ASSERT_EQ(m.fins.faces.size(), 2u);
  EXPECT_EQ(m.fins.faces[0].sem, Semantic::Roof);
  EXPECT_EQ(m.fins.faces[1].sem, Semantic::Other);
  EXPECT_EQ(m.fins.faces[1].source, 3);  // the face's index in the file
  // A file of fins only has no solid; what needs one says so (eval, below).
  const ObjModel only = read_obj_model(write_bytes("only.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\ng fins\nf 1 2 3\n"));
  EXPECT_TRUE(only.solid.faces.empty());
  EXPECT_TRUE(only.solid.vertices.empty());
  EXPECT_EQ(only.fins.faces.size(), 1u);
}
