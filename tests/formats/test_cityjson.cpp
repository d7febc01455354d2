// The CityJSON reader (io/cityjson.h) on small inline documents and on the real files, the
// `convert` command built on it, and the quantisation of the CityJSON writer
// (io/cityjson_write.h). The real files are in ../shared/realdata; that test skips when it is
// absent.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "lodrefine/base/files.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/cityjson_write.h"
#include "lodrefine/formats/obj.h"
#include "support/hang_guard.h"
#include "support/realdata.h"
#include "support/test_paths.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

// A unit cube [0,1]^3 (in transformed units) as one Solid shell; faces: ground, roof, 4 walls.
const char* kCubeBoundaries = R"([[[[0,3,2,1]],[[4,5,6,7]],[[0,1,5,4]],[[1,2,6,5]],[[2,3,7,6]],[[3,0,4,7]]]])";
const char* kCubeVertices =
    R"([[0,0,0],[1000,0,0],[1000,1000,0],[0,1000,0],[0,0,1000],[1000,0,1000],[1000,1000,1000],[0,1000,1000]])";

std::string cube_solid(const std::string& lod) {
  return std::string(R"({"type":"Solid","lod":)") + lod + R"(,"boundaries":)" + kCubeBoundaries +
         R"(,"semantics":{"surfaces":[{"type":"GroundSurface"},{"type":"RoofSurface"},{"type":"WallSurface"}],)"
         R"("values":[[0,1,2,2,null,2]]}})";
}

std::string cube_document(const std::string& version, const std::string& objects) {
  return R"({"type":"CityJSON","version":")" + version +
         R"(","transform":{"scale":[0.001,0.001,0.001],"translate":[85000,447000,2]},"CityObjects":{)" + objects +
         R"(},"vertices":)" + kCubeVertices + "}";
}

}  // namespace

TEST(CityJson, ReadsHighestLod2SolidWithTransformAndSemantics) {
  const std::string objects =
      R"("B1":{"type":"Building","children":["B1-0"],"geometry":[{"type":"MultiSurface","lod":"0","boundaries":[[[0,1,2,3]]]}]},)"
      R"("B1-0":{"type":"BuildingPart","parents":["B1"],"geometry":[)" +
      cube_solid("\"1.2\"") + "," + cube_solid("\"2.2\"") + "," + cube_solid("\"2\"") + "]}";
  const CityJsonFile f = parse_cityjson(cube_document("2.0", objects));
  EXPECT_EQ(f.version, "2.0");
  EXPECT_FALSE(f.sequence);
  EXPECT_EQ(f.objects_without_lod2, 1);  // B1 has LoD 0 only
  ASSERT_EQ(f.buildings.size(), 1u);
  const CityJsonBuilding& b = f.buildings[0];
  EXPECT_EQ(b.mesh.id, "B1-0");
  EXPECT_EQ(b.type, "BuildingPart");
  EXPECT_EQ(b.parent, "B1");
  EXPECT_EQ(b.lod, "2.2");
  EXPECT_EQ(b.geometry_type, "Solid");
  ASSERT_EQ(b.mesh.faces.size(), 6u);
  EXPECT_EQ(b.mesh.vertices.size(), 24u);  // polygon soup: every face its own vertices
  const Semantic expect[6] = {Semantic::Ground, Semantic::Roof,  Semantic::Wall,
                              Semantic::Wall,   Semantic::Other, Semantic::Wall};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(b.mesh.faces[i].sem, expect[i]) << i;
    EXPECT_EQ(b.mesh.faces[i].source, i);
  }
  const Vec3 roof0 = b.mesh.vertices[b.mesh.faces[1].v[0]];
  EXPECT_NEAR((roof0 - Vec3(85000, 447000, 3)).norm(), 0.0, 1e-9);
  const Vec3 far = b.mesh.vertices[b.mesh.faces[1].v[2]];
  EXPECT_NEAR((far - Vec3(85001, 447001, 3)).norm(), 0.0, 1e-9);
}

TEST(CityJson, ReadsMultiSurfaceWithHolesKeyholesPinchesAndNoTransform) {
  // CityJSON 1.0 style: numeric lod, no transform (real coordinates). Surfaces: a hole ring plus a
  // repeated vertex and a closing vertex written out; a degenerate ring; a ClosureSurface; a
  // keyhole ring (hole bridged to the outer ring); a figure-8 ring (two loops sharing vertex 1).
  const std::string doc = R"({"type":"CityJSON","version":"1.0","CityObjects":{"X":{"type":"Building","geometry":[
      {"type":"MultiSurface","lod":2,"boundaries":[[[0,1,1,2,3,0],[4,5,6]],[[0,1,0]],[[4,5,6]],
        [[0,1,2,3,0,4,6,5,4]],[[0,1,7,8,1,2,3]]],
       "semantics":{"surfaces":[{"type":"WallSurface"},{"type":"ClosureSurface"}],"values":[0,0,1,0,0]}}]}},
      "vertices":[[0.5,0,0],[10,0,0],[10,0,5],[0,0,5],[2,0,1],[3,0,1],[3,0,2],[20,0,0],[20,0,5]]})";
  const CityJsonFile f = parse_cityjson(doc);
  ASSERT_EQ(f.buildings.size(), 1u);
  const CityJsonBuilding& b = f.buildings[0];
  EXPECT_EQ(b.lod, "2");
  EXPECT_EQ(b.skipped_holes, 2);
  EXPECT_EQ(b.skipped_rings, 1);
  ASSERT_EQ(b.mesh.faces.size(), 5u);
  const int sources[5] = {0, 2, 3, 4, 4};
  const std::size_t sizes[5] = {4, 3, 4, 3, 4};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(b.mesh.faces[i].source, sources[i]) << i;
    EXPECT_EQ(b.mesh.faces[i].v.size(), sizes[i]) << i;
    EXPECT_EQ(b.mesh.faces[i].sem, i == 1 ? Semantic::Other : Semantic::Wall) << i;
  }
  EXPECT_DOUBLE_EQ(b.mesh.vertices[0].x(), 0.5);
  EXPECT_EQ(f.notes.size(), 2u);  // the holes, the degenerate surface
}

TEST(CityJson, ReadsCityJsonSeqWithPerFeatureVertices) {
  const std::string header =
      R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[],)"
      R"("transform":{"scale":[0.01,0.01,0.01],"translate":[100,200,0]},"metadata":{"referenceSystem":"EPSG:7415"}})";
  auto feature = [](const std::string& id) {
    return R"({"type":"CityJSONFeature","id":")" + id + R"(","CityObjects":{")" + id +
           R"(":{"type":"Building","geometry":[)" + cube_solid("\"2.2\"") + R"(]}},"vertices":)" + kCubeVertices + "}";
  };
  const CityJsonFile f = parse_cityjson(header + "\n" + feature("A") + "\r\n\n" + feature("B") + "\n");
  EXPECT_TRUE(f.sequence);
  EXPECT_EQ(f.crs, "EPSG:7415");
  ASSERT_EQ(f.buildings.size(), 2u);
  EXPECT_EQ(f.buildings[1].mesh.id, "B");
  const Vec3 p = f.buildings[1].mesh.vertices[f.buildings[1].mesh.faces[1].v[2]];
  EXPECT_NEAR((p - Vec3(110, 210, 10)).norm(), 0.0, 1e-9);
}

TEST(CityJson, RejectsMalformedInputWithOneLineMessages) {
  const std::string ok_solid = cube_solid("\"2\"");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"{not json", "not valid JSON"},
      {R"({"type":"FeatureCollection"})", "not a CityJSON file"},
      {R"({"type":"CityJSON","CityObjects":{}})", "no \"vertices\""},
      {R"({"type":"CityJSON","vertices":[]})", "no \"CityObjects\""},
      {cube_document("2.0",
                     R"("A":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[[[[0,1,99]]]]}]})"),
       "vertex index 99 is out of range"},
      {cube_document("2.0",
                     R"("A":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[[0,1,2]]}]})"),
       "not nested"},
      {cube_document("2.0", R"("A":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":)" +
                                std::string(kCubeBoundaries) +
                                R"(,"semantics":{"surfaces":[{"type":"RoofSurface"}],"values":[[0,0,0,0,0,3]]}}]})"),
       "semantics value 3"},
      {cube_document("2.0", R"("A":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":)" +
                                std::string(kCubeBoundaries) +
                                R"(,"semantics":{"surfaces":[{"type":"RoofSurface"}],"values":[[0,0]]}}]})"),
       "semantics values do not match"},
      {cube_document("2.0", R"("A":{"type":"Building","geometry":[{"type":"Solid","lod":"two","boundaries":[]}]})"),
       "lod"},
      {R"({"type":"CityJSON","transform":{"scale":[1,1]},"CityObjects":{},"vertices":[]})", "transform.scale"},
      {R"({"type":"CityJSON","CityObjects":{},"vertices":[[1,2]]})", "vertex 0"},
      {R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[]})"
       "\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{},\"vertices\":[]}\n{\"type\":\"CityJSON\"}\n",
       "line 3: expected a CityJSONFeature"},
      {cube_document(
           "2.0", R"("A":{"type":"Building","geometry":[)" + ok_solid + R"(]},"B":{"type":"Building","geometry":{}})"),
       "object \"B\": \"geometry\" is not an array"},
  };
  for (const auto& [text, expect] : bad) {
    try {
      parse_cityjson(text, "bad.json");
      ADD_FAILURE() << "accepted: " << text.substr(0, 200);
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("bad.json: ", 0), 0u) << msg;
      EXPECT_NE(msg.find(expect), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  EXPECT_THROW(read_cityjson("/nonexistent/file.city.json"), InputError);
}

// `lodrefine convert` writes one OBJ per building that reads back as the same soup.
TEST(CityJson, ConvertCommandWritesOneObjPerBuilding) {
  const fs::path dir = fs::temp_directory_path() / ("lodrefine_convert_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string objects = std::string(R"("B/1":{"type":"Building","geometry":[)") + cube_solid("\"2\"") +
                              R"(]},"B2":{"type":"Building","geometry":[)" + cube_solid("\"2.2\"") + "]}";
  write_file_atomic((dir / "in.city.json").string(), cube_document("1.1", objects));
  const std::string cmd = test_paths::lodrefine_binary() + " convert --cityjson '" + (dir / "in.city.json").string() +
                          "' --out-dir '" + (dir / "out").string() + "'";
  ASSERT_EQ(std::system((cmd + " > /dev/null").c_str()), 0) << cmd;
  const Mesh m = read_obj((dir / "out" / (safe_name("B/1") + ".obj")).string());  // B_1--<hash>.obj
  EXPECT_EQ(m.id, "B/1");
  ASSERT_EQ(m.faces.size(), 6u);
  const Mesh expect = parse_cityjson(cube_document("1.1", objects)).buildings[0].mesh;
  std::map<Semantic, int> got, want;
  for (std::size_t f = 0; f < 6; ++f) {
    EXPECT_EQ(m.faces[f].v.size(), 4u);
    ++got[m.faces[f].sem];
    ++want[expect.faces[f].sem];
  }
  EXPECT_EQ(got, want);
  Vec3 lo = Vec3::Constant(1e300);
  for (const auto& v : m.vertices) lo = lo.cwiseMin(v);
  EXPECT_NEAR((lo - Vec3(85000, 447000, 2)).norm(), 0.0, 1e-6);
  EXPECT_TRUE(fs::exists(dir / "out" / "B2.obj"));
  // An id that is not in the file is an input error (exit code 2).
  EXPECT_EQ(WEXITSTATUS(std::system((cmd + " --id nope 2> /dev/null").c_str())), 2);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// Fins read back (a building lodrefine wrote: its Solid, then a MultiSurface of its LoD).

namespace {

// The cube with a fin on its wall x = 0 standing 1 m above the roof: vertices 8 and 9.
const char* kFinMultiSurface = R"({"type":"MultiSurface","lod":"2.2","boundaries":[[[4,7,9,8]]],)"
                               R"("semantics":{"surfaces":[{"type":"WallSurface"}],"values":[0]}})";

std::string fin_document(const std::string& objects) {
  std::string doc = cube_document("2.0", objects);
  const std::size_t end = doc.rfind("]]");
  return doc.substr(0, end) + "],[0,0,2000],[0,1000,2000]]}";
}

std::string building(const std::string& id, bool ours, const std::vector<std::string>& geometries) {
  std::string g;
  for (const auto& x : geometries) g += (g.empty() ? "" : ",") + x;
  return "\"" + id + "\":{\"type\":\"Building\"," + (ours ? R"("attributes":{"lodrefine_outcome":"repaired"},)" : "") +
         "\"geometry\":[" + g + "]}";
}

}  // namespace

// Only a building lodrefine wrote has fins to read back, and only the MultiSurface of its
// Solid's LoD right after the Solid: crafted and foreign layouts read as before.
TEST(CityJson, ReadsOurFinsWithTheirSolidOnly) {
  const std::string solid = cube_solid("\"2.2\""), fins = kFinMultiSurface;
  const std::string objects =
      building("ours", true, {solid, fins}) + "," + building("foreign", false, {solid, fins}) + "," +
      building("other_lod", true, {solid, std::string(fins).replace(fins.find("2.2"), 3, "2")}) + "," +
      building("fins_alone", true, {fins}) + "," + building("twice", true, {solid, fins, fins}) + "," +
      building("fins_first", true, {fins, solid});
  const CityJsonFile f = parse_cityjson(fin_document(objects));
  std::map<std::string, const CityJsonBuilding*> by_id;
  for (const auto& b : f.buildings) by_id[b.mesh.id] = &b;
  ASSERT_EQ(by_id.size(), 6u);
  const CityJsonBuilding& ours = *by_id.at("ours");
  ASSERT_EQ(ours.mesh.faces.size(), 7u);
  EXPECT_EQ(ours.fin_faces, 1);
  EXPECT_EQ(ours.fins_index, 1);
  EXPECT_EQ(ours.mesh.faces.back().sem, Semantic::Wall);
  EXPECT_EQ(ours.mesh.faces.back().source, 6);  // after the Solid's six
  EXPECT_NEAR(ours.mesh.vertices[std::size_t(ours.mesh.faces.back().v[2])].z(), 4.0, 1e-9);
  for (const char* id : {"foreign", "other_lod", "fins_alone", "fins_first"}) {
    SCOPED_TRACE(id);
    EXPECT_EQ(by_id.at(id)->fin_faces, 0);
    EXPECT_EQ(by_id.at(id)->fins_index, -1);
  }
  EXPECT_EQ(by_id.at("foreign")->mesh.faces.size(), 6u);
  EXPECT_EQ(by_id.at("other_lod")->mesh.faces.size(), 6u);
  EXPECT_EQ(by_id.at("fins_alone")->mesh.faces.size(), 1u);  // a MultiSurface alone is the model
  EXPECT_EQ(by_id.at("fins_first")->geometry_type, "MultiSurface");
  EXPECT_EQ(by_id.at("twice")->fin_faces, 1);  // the second is another geometry, left alone
}

// `convert` keeps the fins: after the solid's faces, in the OBJ's fins group (before, it wrote
// the Solid alone and dropped them without a word).
TEST(CityJson, ConvertKeepsTheFinsInTheirGroup) {
  const fs::path dir = fs::temp_directory_path() / ("lodrefine_convert_fins_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_file_atomic((dir / "in.city.json").string(),
                    fin_document(building("ours", true, {cube_solid("\"2.2\""), kFinMultiSurface})));
  const std::string cmd = test_paths::lodrefine_binary() + " convert --cityjson '" + (dir / "in.city.json").string() +
                          "' --out-dir '" + (dir / "out").string() + "' > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const ObjModel m = read_obj_model((dir / "out" / "ours.obj").string());
  EXPECT_EQ(m.solid.faces.size(), 6u);
  ASSERT_EQ(m.fins.faces.size(), 1u);
  EXPECT_EQ(m.fins.faces[0].sem, Semantic::Wall);
  EXPECT_EQ(m.fins.vertices.size(), 4u);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// Real files.

TEST(CityJson, ReadsTheRealFiles) {
  REQUIRE_REALDATA("val3dity/data");
  const CityJsonFile rotterdam = read_cityjson((data_path / "rotterdam/3-20-DELFSHAVEN.city.json").string());
  EXPECT_EQ(rotterdam.version, "2.0");
  EXPECT_EQ(rotterdam.buildings.size(), 853u);
  // metadata.geographicalExtent of the file
  const Vec3 lo(90409.32, 435440.44, 0.0), hi(91453.879, 436089.946, 41.158);
  int walls = 0, roofs = 0, grounds = 0;
  for (const auto& b : rotterdam.buildings) {
    EXPECT_EQ(b.geometry_type, "MultiSurface");
    for (const auto& v : b.mesh.vertices)
      ASSERT_TRUE((v.array() >= lo.array() - 1e-6).all() && (v.array() <= hi.array() + 1e-6).all()) << b.mesh.id;
    for (const auto& f : b.mesh.faces) {
      walls += f.sem == Semantic::Wall;
      roofs += f.sem == Semantic::Roof;
      grounds += f.sem == Semantic::Ground;
    }
  }
  EXPECT_GT(walls, 5 * 853);
  EXPECT_GE(roofs, 853);
  EXPECT_GE(grounds, 853);

  const CityJsonFile bag = read_cityjson((data_path / "cityjsonseq/3dbag_b2.city.jsonl").string());
  EXPECT_TRUE(bag.sequence);
  ASSERT_EQ(bag.buildings.size(), 2u);  // the two BuildingParts; their Buildings have LoD 0 only
  EXPECT_EQ(bag.buildings[0].mesh.id, "NL.IMBAG.Pand.0503100000031927-0");
  EXPECT_EQ(bag.buildings[0].lod, "2.2");
  EXPECT_NEAR(bag.buildings[0].mesh.vertices[0].x(), 85006.254, 1e-3);

  const CityJsonFile dh = read_cityjson((data_path / "test_cjseq/denhaag_random_5.city.jsonl").string());
  EXPECT_EQ(dh.version, "1.1");
  EXPECT_EQ(dh.buildings.size(), 14u);  // 12 parts + 2 buildings without parts
  for (const auto& b : dh.buildings) EXPECT_EQ(b.geometry_type, "Solid");

  const CityJsonFile lods = read_cityjson((data_path / "test_cityjson/several_lods_valid.json").string());
  ASSERT_EQ(lods.buildings.size(), 1u);
  EXPECT_EQ(lods.buildings[0].lod, "2.2");
}

// ---------------------------------------------------------------------------------------
// Writer: CityJSON's integer vertices.

TEST(CityJsonWrite, QuantiseRoundsToTheNearestStep) {
  CityJsonTransform t;  // millimetres
  t.translate = Vec3(85000.0, 447000.0, 0.0);
  EXPECT_EQ(t.quantise({85001.2344, 447000.0006, 12.3454}), (std::array<long long, 3>{1234, 1, 12345}));
  EXPECT_EQ(t.quantise({84999.9996, 446999.9994, -0.0004}), (std::array<long long, 3>{0, -1, 0}));
  // At the CityGML resolution, georeferenced coordinates come back within half a step.
  t.scale = Vec3::Constant(kCityGmlResolution);
  for (const Vec3& p : {Vec3(85123.45678, 447987.65432, 3.21098), Vec3(93512.00004, 436001.99996, -4.5)}) {
    const auto q = t.quantise(p);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(double(q[k]) * t.scale[k] + t.translate[k], p[k], 0.5 * kCityGmlResolution + 1e-9);
  }
}

namespace {

std::string refusal_of(const std::string& text, const std::string& name = "bad.json") {
  try {
    parse_cityjson(text, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

// Issue 15, items 10, 13, 14: what the JSON parser took silently or with a raw message.
TEST(CityJsonSecurity, DeepNestingOverflowsAndDuplicatesAreOneLine) {
  const std::string ok = R"("A":{"type":"Building","geometry":[)" + cube_solid("\"2\"") + "]";
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::vector<std::pair<std::string, std::string>> bad = {
      // 100k-deep attribute: the writer's recursion overflowed the stack.
      {cube_document("2.0", ok + R"(,"attributes":{"x":)" + deep + "}}"),
       "bad.json: JSON nested deeper than 256 levels"},
      {cube_document("2.0", ok + "}").replace(1, 0, R"("deep":)" + deep + ","),
       "bad.json: JSON nested deeper than 256"},
      // 1e400: out_of_range.406, raw and without the file name.
      {cube_document("2.0", ok + R"(,"attributes":{"x":1e400}})"),
       "bad.json: not valid JSON: number overflow parsing '1e400'"},
      // A zero scale collapses every vertex.
      {R"({"type":"CityJSON","transform":{"scale":[0.001,0.001,0],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})",
       "bad.json: transform.scale has a zero or negative factor"},
      // 2e15 m without a transform was written back as -9223372036854775808.
      {R"({"type":"CityJSON","version":"1.1","CityObjects":{},"vertices":[[2e15,0,0]]})",
       "bad.json: vertex 0 is beyond 1e9 m from the origin"},
      // A duplicate CityObjects key kept one of the two buildings.
      {cube_document("2.0", ok + "}," + ok + "}"), "bad.json: CityObjects id \"A\" appears twice"},
  };
  for (const auto& [text, expect] : bad) {
    const std::string msg = refusal_of(text);
    EXPECT_EQ(msg.rfind(expect, 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // A CityJSONSeq line names its line; keys repeated elsewhere (attributes) are JSON's business.
  const std::string seq =
      R"({"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})"
      "\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{\"A\":{\"type\":\"Building\",\"attributes\":{\"x\":" +
      deep + "}}},\"vertices\":[]}\n";
  EXPECT_EQ(refusal_of(seq).rfind("bad.json: line 2: JSON nested deeper than 256 levels", 0), 0u) << refusal_of(seq);
  EXPECT_EQ(parse_cityjson(cube_document("2.0", ok + R"(,"attributes":{"k":1,"k":2}})")).buildings.size(), 1u);
}

// A key given twice where the reader looks (the root, transform, an object, a geometry): JSON
// keeps the last one, so one of two "CityObjects" (and its buildings) vanished without a word,
// and other readers may keep the first. Wrong types of "version" and "type" were a raw
// type_error (exit 1, no file name) from the city writer, after the whole crop.
TEST(CityJsonSecurity, KeysGivenTwiceAndNonStringTypesAreOneLine) {
  const std::string ok = R"("A":{"type":"Building","geometry":[)" + cube_solid("\"2\"") + "]}";
  const std::string doc = cube_document("2.0", ok);
  const std::string tail = doc.substr(0, doc.size() - 1);  // without the closing brace
  const std::vector<std::pair<std::string, std::string>> bad = {
      {tail + R"(,"CityObjects":{}})", "bad.json: key \"CityObjects\" appears twice in one object"},
      {tail + R"(,"vertices":[]})", "bad.json: key \"vertices\" appears twice in one object"},
      {cube_document("2.0", ok).replace(doc.find(R"("scale")"), 0, R"("scale":[1,1,1],)"),
       "bad.json: key \"scale\" appears twice in one object"},
      {cube_document("2.0", R"("A":{"type":"Building","type":"Bridge","geometry":[)" + cube_solid("\"2\"") + "]}"),
       "bad.json: key \"type\" appears twice in one object"},
      {cube_document("2.0", R"("A":{"type":"Building","geometry":[)" +
                                cube_solid("\"2\"").replace(1, 0, R"("boundaries":[],)") + "]}"),
       "bad.json: key \"boundaries\" appears twice in one object"},
      {cube_document("2.0", ok + R"(,"B":{"type":5})"), "bad.json: object \"B\": \"type\" is not a string"},
      {R"({"type":"CityJSON","version":2,"CityObjects":{},"vertices":[]})", "bad.json: \"version\" is not a string"},
      // 2^63 was shown as -9223372036854775808.
      {cube_document("2.0", ok).replace(doc.find("[[[[0,"), 6, "[[[[9223372036854775808,"),
       "bad.json: object \"A\": vertex index 9223372036854775808 is out of range"},
  };
  for (const auto& [text, expect] : bad) {
    const std::string msg = refusal_of(text);
    EXPECT_EQ(msg.rfind(expect, 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // Free-form data keeps JSON's rule (the last one counts): attributes, metadata, addresses.
  const std::string free_form =
      cube_document("2.0", R"("A":{"type":"Building","attributes":{"k":1,"k":{"n":1,"n":2}},"address":[{"a":1,"a":2}],)"
                           R"("geometry":[)" +
                               cube_solid("\"2\"") + "]}");
  EXPECT_EQ(
      parse_cityjson(free_form.substr(0, free_form.size() - 1) + R"(,"metadata":{"t":1,"t":2}})").buildings.size(), 1u);
}

// Issue 15, item 12: a ring pinched at one vertex 6000 times took minutes (cubic split).
TEST(CityJsonSecurity, RingPinchedThousandsOfTimesSplitsInLinearTime) {
  const int petals = 6000;
  std::string vertices = "[[0,0,0]", ring = "[";
  for (int k = 0; k < petals; ++k) {
    const double a = 2 * 3.14159265358979 * k / petals, b = 2 * 3.14159265358979 * (k + 0.5) / petals;
    vertices += ",[" + std::to_string(100 * std::cos(a)) + "," + std::to_string(100 * std::sin(a)) + ",0],[" +
                std::to_string(100 * std::cos(b)) + "," + std::to_string(100 * std::sin(b)) + ",0]";
    ring += (k ? ",0," : "0,") + std::to_string(2 * k + 1) + "," + std::to_string(2 * k + 2);
  }
  const std::string doc = R"({"type":"CityJSON","version":"2.0","CityObjects":{"P":{"type":"Building","geometry":[)"
                          R"({"type":"MultiSurface","lod":"2","boundaries":[[)" +
                          ring + R"(]]]}]}},"vertices":)" + vertices + "]}";
  const auto t0 = std::chrono::steady_clock::now();
  const CityJsonFile f = parse_cityjson(doc);
  EXPECT_LT(fixtures::seconds_since(t0), fixtures::kHangGuardSeconds);
  ASSERT_EQ(f.buildings.size(), 1u);
  ASSERT_EQ(f.buildings[0].mesh.faces.size(), std::size_t(petals));  // one triangle per petal
  EXPECT_EQ(f.buildings[0].mesh.faces[1].v.size(), 3u);
  EXPECT_EQ(f.buildings[0].mesh.vertices[std::size_t(f.buildings[0].mesh.faces[1].v[0])], Vec3::Zero());
}
