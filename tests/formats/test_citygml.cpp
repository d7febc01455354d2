// CityGML in through libcitygml: the same per-building meshes the CityJSON reader gives, ids
// from gml:id (never the generated ones), semantics from the boundary surfaces, the CRS.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>

#include "lodrefine/formats/citygml.h"
#include "support/hang_guard.h"
#include "support/test_paths.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::path(testing::TempDir()) / ("lodrefine_citygml_" + std::to_string(::getpid())) / info->name();
  fs::create_directories(dir);
  std::ofstream((dir / name).string()) << text;
  return (dir / name).string();
}

std::string pos_list(const std::vector<Vec3>& ring) {
  std::string s;
  for (std::size_t i = 0; i <= ring.size(); ++i) {
    const Vec3& p = ring[i % ring.size()];
    s += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + " ";
  }
  return s;
}

std::string polygon(const std::vector<Vec3>& ring, const std::string& id) {
  return "<gml:Polygon" + (id.empty() ? std::string() : " gml:id=\"" + id + "\"") +
         "><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">" + pos_list(ring) +
         "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>";
}

// The six faces of a box (outward), walls first, then roof, then ground.
std::vector<std::vector<Vec3>> box_faces(const Vec3& o, double w, double d, double h) {
  const Vec3 a = o, b = o + Vec3(w, 0, 0), c = o + Vec3(w, d, 0), e = o + Vec3(0, d, 0), z(0, 0, h);
  return {{a, b, b + z, a + z}, {b, c, c + z, b + z},         {c, e, e + z, c + z},
          {e, a, a + z, e + z}, {a + z, b + z, c + z, e + z}, {a, e, c, b}};
}

const char* kHeader = R"(<?xml version="1.0" encoding="UTF-8"?>
<CityModel xmlns="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0"
 xmlns:gen="http://www.opengis.net/citygml/generics/2.0" xmlns:gml="http://www.opengis.net/gml">
<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3"><gml:lowerCorner>0 0 0</gml:lowerCorner><gml:upperCorner>1 1 1</gml:upperCorner></gml:Envelope></gml:boundedBy>
)";

// Building "thematic": boundedBy Wall/Roof/GroundSurface (polygons with and without ids);
// Building "solid": an lod2Solid only; Building "lod1": lod1Solid only.
std::string sample_citygml() {
  const Vec3 o(512000.125, 5403000.5, 100.0);
  std::string s = kHeader;
  const auto f1 = box_faces(o, 10, 8, 6);
  s += "<cityObjectMember><bldg:Building gml:id=\"thematic\">"
       "<gen:doubleAttribute name=\"height\"><gen:value>6.0</gen:value></gen:doubleAttribute>"
       "<gen:stringAttribute name=\"street\"><gen:value>Hauptstr.</gen:value></gen:stringAttribute>";
  const char* kinds[] = {"WallSurface", "WallSurface", "WallSurface", "WallSurface", "RoofSurface", "GroundSurface"};
  for (int k = 0; k < 6; ++k)
    s += std::string("<bldg:boundedBy><bldg:") + kinds[k] +
         "><bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>" +
         polygon(f1[std::size_t(k)], k % 2 ? "" : "poly" + std::to_string(k)) +
         "</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface></bldg:" + kinds[k] + "></bldg:boundedBy>";
  s += "</bldg:Building></cityObjectMember>";
  const auto f2 = box_faces(o + Vec3(30, 0, 0), 6, 6, 9);
  s += "<cityObjectMember><bldg:Building "
       "gml:id=\"solid\"><bldg:lod2Solid><gml:Solid><gml:exterior><gml:CompositeSurface>";
  for (const auto& f : f2) s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
  s += "</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod2Solid></bldg:Building></cityObjectMember>";
  s += "<cityObjectMember><bldg:Building "
       "gml:id=\"lod1\"><bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface>";
  for (const auto& f : box_faces(o + Vec3(60, 0, 0), 5, 5, 5))
    s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
  s += "</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid></bldg:Building></cityObjectMember>";
  return s + "</CityModel>\n";
}

std::map<Semantic, int> semantics(const Mesh& m) {
  std::map<Semantic, int> n;
  for (const auto& f : m.faces) ++n[f.sem];
  return n;
}

}  // namespace

TEST(CityGml, BoundarySurfacesSolidsIdsAttributesCrs) {
  const std::string path = write_temp("sample.gml", sample_citygml());
  const CityJsonFile f = read_citygml(path);
  EXPECT_EQ(f.format, "CityGML");
  EXPECT_EQ(f.version, "2.0");
  EXPECT_EQ(f.crs, "https://www.opengis.net/def/crs/EPSG/0/25832");
  ASSERT_EQ(f.buildings.size(), 2u);
  EXPECT_EQ(f.objects_without_lod2, 1);  // "lod1"
  const CityJsonBuilding& t = f.buildings[0];
  EXPECT_EQ(t.mesh.id, "thematic");
  EXPECT_EQ(t.type, "Building");
  ASSERT_EQ(t.mesh.faces.size(), 6u);
  EXPECT_EQ(semantics(t.mesh),
            (std::map<Semantic, int>{{Semantic::Wall, 4}, {Semantic::Roof, 1}, {Semantic::Ground, 1}}));
  EXPECT_EQ(t.attributes.value("height", 0.0), 6.0);
  EXPECT_EQ(t.attributes.value("street", std::string()), "Hauptstr.");
  // Coordinates exact to 0.1 mm (the CityJSON transform of the conversion) at UTM magnitudes.
  double worst = 0;
  const auto faces = box_faces(Vec3(512000.125, 5403000.5, 100.0), 10, 8, 6);
  for (std::size_t k = 0; k < 6; ++k)
    for (std::size_t i = 0; i < 4; ++i)
      worst = std::max(worst, (t.mesh.vertices[std::size_t(t.mesh.faces[k].v[i])] - faces[k][i]).norm());
  EXPECT_LT(worst, 1e-6);
  const CityJsonBuilding& s = f.buildings[1];
  EXPECT_EQ(s.mesh.id, "solid");
  EXPECT_EQ(s.mesh.faces.size(), 6u);
  EXPECT_EQ(semantics(s.mesh), (std::map<Semantic, int>{{Semantic::Other, 6}}));
  // read_city_file picks the reader by content.
  EXPECT_EQ(read_city_file(path).buildings.size(), 2u);
}

TEST(CityGml, CrsNamesBecomeCityJsonUrls) {
  const std::string url = "https://www.opengis.net/def/crs/EPSG/0/";
  const std::vector<std::pair<std::string, std::string>> names = {
      {"urn:ogc:def:crs:EPSG::28992", url + "28992"},
      {"EPSG:25832", url + "25832"},
      {"urn:ogc:def:crs:EPSG:6.12:31467", url + "31467"},
      {"http://www.opengis.net/def/crs/EPSG/0/7415", url + "7415"},
      {"local", "local"}};
  for (const auto& [name, expected] : names) EXPECT_EQ(crs_url(name), expected) << name;
}

TEST(CityGml, BadFilesAreOneClearError) {
  const auto expect = [](const std::string& path, const std::string& fault) {
    try {
      read_citygml(path);
      ADD_FAILURE() << "accepted " << path;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
      EXPECT_NE(msg.find(fault), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  };
  expect(write_temp("v3.gml", "<?xml version=\"1.0\"?><CityModel xmlns=\"http://www.opengis.net/citygml/3.0\"/>"),
         "CityGML 3.0 is not supported");
  expect(write_temp("x.gml", "<?xml version=\"1.0\"?><html/>"), "XML but not CityGML");
  expect(write_temp("j.gml", "{\"type\":\"CityJSON\"}"), "not a CityGML file: the file is JSON");
  std::string cut = sample_citygml();
  expect(write_temp("cut.gml", cut.substr(0, cut.size() / 2)), "CityGML parse error");
}

TEST(CityGml, DenHaagBuildingParts) {
  const fs::path p = fs::path(test_paths::source_dir()) / ".." / "shared/realdata/val3dity/data/gml/DenHaag_1BwBP.gml";
  if (!fs::exists(p)) GTEST_SKIP() << p << " absent";
  const CityJsonFile f = read_citygml(p.string());
  EXPECT_EQ(f.version, "1.0");
  EXPECT_EQ(f.crs, "https://www.opengis.net/def/crs/EPSG/0/28992");
  ASSERT_EQ(f.buildings.size(), 6u);
  EXPECT_EQ(f.objects_without_lod2, 1);  // the Building itself: its geometry is in its parts
  for (std::size_t k = 0; k < 6; ++k) {
    const auto& b = f.buildings[k];
    EXPECT_EQ(b.mesh.id, "GUID_7F91F413-F839-48F6-A36A-E0F2F090C6B0_" + std::to_string(k + 1));
    EXPECT_EQ(b.type, "BuildingPart");
    EXPECT_EQ(b.parent, "GUID_7F91F413-F839-48F6-A36A-E0F2F090C6B0");
    const auto n = semantics(b.mesh);
    EXPECT_GE(n.count(Semantic::Wall) ? n.at(Semantic::Wall) : 0, 4) << b.mesh.id;
    EXPECT_GE(n.count(Semantic::Roof) ? n.at(Semantic::Roof) : 0, 1) << b.mesh.id;
    EXPECT_EQ(n.count(Semantic::Ground) ? n.at(Semantic::Ground) : 0, 1) << b.mesh.id;
    EXPECT_EQ(n.count(Semantic::Other), 0u) << b.mesh.id;
    EXPECT_TRUE(b.attributes.contains("RelativeEavesHeight")) << b.mesh.id;
  }
  EXPECT_DOUBLE_EQ(f.buildings[0].attributes["RelativeEavesHeight"].get<double>(), 6.197);
  EXPECT_EQ(semantics(f.buildings[0].mesh),
            (std::map<Semantic, int>{{Semantic::Wall, 6}, {Semantic::Roof, 2}, {Semantic::Ground, 1}}));
}

// Found by fuzz_citygml (UBSan, signed overflow in the vertex hash): coordinates 1800 km apart
// are 1.8e10 units of 0.1 mm; they must read back, not overflow.
TEST(CityGml, CoordinatesFarApart) {
  std::string s = kHeader;
  s += "<cityObjectMember><bldg:Building gml:id=\"far\"><bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>" +
       polygon({{-9e8, 0, 0}, {9e8, 0, 0}, {9e8, 5e8, 0}}, "") +
       "</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></cityObjectMember></"
       "CityModel>\n";
  const CityJsonFile f = read_citygml(write_temp("far.gml", s));
  ASSERT_EQ(f.buildings.size(), 1u);
  ASSERT_EQ(f.buildings[0].mesh.faces.size(), 1u);
  EXPECT_EQ(f.buildings[0].mesh.vertices[1], Vec3(9e8, 0, 0));
}

namespace {

// One building "b" with a generic string attribute `name` whose XML text is `value`, after a
// prolog `prolog` (between the XML declaration and the root element).
std::string building_with_attribute(const std::string& value, const std::string& prolog = "",
                                    const std::string& root_attributes = "") {
  std::string s = kHeader;
  s.replace(s.find("\n") + 1, 0, prolog);
  s.replace(s.find("xmlns:gml"), 0, root_attributes + " ");
  s += "<cityObjectMember><bldg:Building gml:id=\"b\"><gen:stringAttribute name=\"name\"><gen:value>" + value +
       "</gen:value></gen:stringAttribute><bldg:lod2MultiSurface><gml:MultiSurface>";
  for (const auto& f : box_faces(Vec3(10, 20, 0), 4, 5, 3))
    s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
  return s + "</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></cityObjectMember></CityModel>\n";
}

std::string refusal(const std::string& path) {
  try {
    read_citygml(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

// A TCP socket listening on 127.0.0.1 (port chosen by the system): was anything fetched?
class Listener {
 public:
  Listener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), len) != 0 || ::listen(fd_, 8) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      ADD_FAILURE() << "cannot listen on 127.0.0.1";
    port_ = ntohs(a.sin_port);
  }
  ~Listener() { ::close(fd_); }
  std::string url(const std::string& file) const { return "http://127.0.0.1:" + std::to_string(port_) + "/" + file; }
  bool connected() const {
    const int c = ::accept(fd_, nullptr, nullptr);
    if (c >= 0) ::close(c);
    return c >= 0;
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

}  // namespace

// Issue 15, item 2: an external entity put /etc/passwd into the building's attributes. Every
// document type declaration is refused before libcitygml sees the file, in every spelling
// Xerces would read; a BOM, a comment or an encoding trick does not hide it.
TEST(CityGmlSecurity, EntitiesAndDtdsAreRefusedBeforeParsing) {
  const std::string xxe = "<!DOCTYPE CityModel [<!ENTITY e SYSTEM \"file:///etc/passwd\">]>\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"xxe.gml", building_with_attribute("&e;", xxe)},
      {"bom.gml", "\xEF\xBB\xBF" + building_with_attribute("&e;", xxe)},
      {"comment.gml", building_with_attribute("&e;", "<!-- a note -->\n<?pi x?>\n" + xxe)},
      {"lower.gml", building_with_attribute("x", "<!doctype CityModel>\n")},
      {"space.gml", building_with_attribute("x", "<! DOCTYPE CityModel>\n")},
      {"entity.gml", building_with_attribute("x", "<!ENTITY e \"x\">\n")},
      {"dtd.gml", building_with_attribute("x", "<!DOCTYPE CityModel SYSTEM \"file:///etc/passwd\">\n")},
  };
  for (const auto& [name, text] : cases) {
    const std::string path = write_temp(name, text);
    const std::string msg = refusal(path);
    EXPECT_EQ(msg.rfind(path + ": the XML has a document type or entity declaration", 0), 0u) << name << ": " << msg;
    EXPECT_EQ(msg.find("root:"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // Encodings in which those bytes would read differently are refused as such.
  std::string utf16;
  for (char c : building_with_attribute("x")) utf16 += c, utf16 += '\0';
  EXPECT_NE(refusal(write_temp("utf16.gml", utf16)).find("UTF-16 or UTF-32 is not read"), std::string::npos);
  EXPECT_NE(refusal(write_temp("utf16bom.gml", "\xFF\xFE" + utf16)).find("not a CityGML file (no XML)"),
            std::string::npos);
  std::string ebcdic = building_with_attribute("x");
  ebcdic.replace(ebcdic.find("UTF-8"), 5, "IBM037");
  EXPECT_NE(refusal(write_temp("ebcdic.gml", ebcdic)).find("encoding 'ibm037' is not read"), std::string::npos);
}

// Issue 15, item 2: a billion-laughs file ran for minutes; it is refused at once.
TEST(CityGmlSecurity, BillionLaughsIsRefusedAtOnce) {
  std::string dtd = "<!DOCTYPE CityModel [<!ENTITY l0 \"ha\">";
  for (int k = 1; k < 12; ++k)
    dtd += "<!ENTITY l" + std::to_string(k) + " \"" + [&] {
      std::string r;
      for (int i = 0; i < 10; ++i) r += "&l" + std::to_string(k - 1) + ";";
      return r;
    }() + "\">";
  const std::string path = write_temp("laughs.gml", building_with_attribute("&l11;", dtd + "]>\n"));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_NE(refusal(path).find("document type or entity declaration"), std::string::npos);
  EXPECT_LT(fixtures::seconds_since(t0), fixtures::kHangGuardSeconds);
}

// Issue 15, item 2: nothing is fetched: not an external DTD (refused), not the schemas of
// xsi:schemaLocation, not an XInclude. A socket on 127.0.0.1 sees no connection.
TEST(CityGmlSecurity, NothingIsFetched) {
  const Listener server;
  const std::string dtd = write_temp(
      "dtd.gml", building_with_attribute("x", "<!DOCTYPE CityModel SYSTEM \"" + server.url("a.dtd") + "\">\n"));
  EXPECT_NE(refusal(dtd).find("document type"), std::string::npos);
  const std::string schema = write_temp(
      "schema.gml", building_with_attribute("x<xi:include href=\"" + server.url("inc.xml") + "\"/>", "",
                                            "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
                                            "xmlns:xi=\"http://www.w3.org/2001/XInclude\" xsi:schemaLocation=\""
                                            "http://www.opengis.net/citygml/2.0 " +
                                                server.url("CityGML.xsd") + "\""));
  const CityJsonFile f = read_citygml(schema);
  ASSERT_EQ(f.buildings.size(), 1u);
  EXPECT_EQ(f.buildings[0].mesh.faces.size(), 6u);
  EXPECT_FALSE(server.connected());
}

// Issue 15, item 8: libcitygml kept only the text after the last reference ("& Sons").
TEST(CityGmlSecurity, ReferencesInTextComeThroughWhole) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"Bakery &amp; Sons", "Bakery & Sons"},
      {"caf&#233; 1", "caf\xC3\xA9 1"},
      {"caf\xC3\xA9 2", "caf\xC3\xA9 2"},
      {"&lt;a&gt; &quot;b&quot; &apos;c&apos;", "<a> \"b\" 'c'"},
      {"x&#x26;y&#38;z &#x1F600;", "x&y&z \xF0\x9F\x98\x80"},
      {"a <![CDATA[&amp;]]> b", "a &amp; b"},
      {"a <!-- c --> b", "a  b"},
      {"\n  <![CDATA[x]]>\n", "\n  x\n"},
      {"plain", "plain"}};
  for (const auto& [xml, expected] : cases) {
    const CityJsonFile f = read_citygml(write_temp("text.gml", building_with_attribute(xml)));
    ASSERT_EQ(f.buildings.size(), 1u);
    EXPECT_EQ(f.buildings[0].attributes.value("name", std::string("(none)")), expected) << xml;
  }
  // ISO-8859-1 is transcoded: the same attribute in Latin-1 bytes.
  std::string latin1 = building_with_attribute("caf\xE9 &amp; bar");
  latin1.replace(latin1.find("UTF-8"), 5, "ISO-8859-1");
  const CityJsonFile f = read_citygml(write_temp("latin1.gml", latin1));
  ASSERT_EQ(f.buildings.size(), 1u);
  EXPECT_EQ(f.buildings[0].attributes.value("name", std::string()), "caf\xC3\xA9 & bar");
  // An unknown entity is still an error (no DTD declares it).
  EXPECT_NE(refusal(write_temp("unknown.gml", building_with_attribute("a &nope; b"))).find("CityGML parse error"),
            std::string::npos);
}

// Issue 15, item 5: two buildings with one gml:id, and one without a gml:id beside a real
// "building-1", were one building. Every building keeps a name, the duplicate is noted.
TEST(CityGmlSecurity, EveryBuildingKeepsItsOwnId) {
  std::string s = kHeader;
  int n = 0;
  for (const std::string id : {"dup", "dup", "building-1", "", "dup~2"}) {
    s += "<cityObjectMember><bldg:Building" + (id.empty() ? std::string() : " gml:id=\"" + id + "\"") +
         "><bldg:lod2MultiSurface><gml:MultiSurface>";
    for (const auto& f : box_faces(Vec3(20.0 * n++, 0, 0), 4, 5, 3))
      s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
    s += "</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></cityObjectMember>";
  }
  const CityJsonFile f = read_citygml(write_temp("dup.gml", s + "</CityModel>\n"));
  std::vector<std::string> ids;
  for (const auto& b : f.buildings) ids.push_back(b.mesh.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"dup", "dup~3", "building-1", "building-4", "dup~2"}));
  EXPECT_NEAR(f.buildings[1].mesh.vertices[0].x(), 20.0, 1e-9);  // the second "dup" is the second building
  ASSERT_FALSE(f.notes.empty());
  EXPECT_EQ(f.notes[0], "gml:id \"dup\" is given to more than one building: one is written as \"dup~3\"");
}

// A building nesting 20,000 BuildingParts overflowed the stack in the CityGML module (libcitygml
// and the reader walk nested objects and geometries recursively): the nesting is refused before
// parsing. Real files nest ~15 levels; 40 nested parts (~90 levels) still read.
TEST(CityGmlSecurity, DeepNestingIsRefusedBeforeParsing) {
  auto nested_parts = [](int parts) {
    std::string s = kHeader;
    s += "<cityObjectMember><bldg:Building gml:id=\"b\">";
    for (int k = 0; k < parts; ++k)
      s += "<bldg:consistsOfBuildingPart><bldg:BuildingPart gml:id=\"p" + std::to_string(k) + "\">";
    s += "<bldg:lod2MultiSurface><gml:MultiSurface>";
    for (const auto& f : box_faces(Vec3(10, 20, 0), 4, 5, 3))
      s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
    s += "</gml:MultiSurface></bldg:lod2MultiSurface>";
    for (int k = 0; k < parts; ++k) s += "</bldg:BuildingPart></bldg:consistsOfBuildingPart>";
    return s + "</bldg:Building></cityObjectMember></CityModel>\n";
  };
  const CityJsonFile f = read_citygml(write_temp("forty.gml", nested_parts(40)));
  ASSERT_EQ(f.buildings.size(), 1u);
  EXPECT_EQ(f.buildings[0].mesh.id, "p39");
  EXPECT_EQ(f.buildings[0].mesh.faces.size(), 6u);

  const std::string deep = write_temp("deep.gml", nested_parts(20000));
  EXPECT_EQ(refusal(deep), deep +
                               ": the XML nests elements more than 256 deep: not accepted, CityGML needs a few "
                               "dozen levels");
  // Empty-element tags, processing instructions and comments do not count as levels.
  std::string flat = nested_parts(1);
  std::string many;
  for (int k = 0; k < 1000; ++k) many += "<gen:x/><?pi x?><!-- c -->";
  flat.replace(flat.find("<bldg:lod2MultiSurface>"), 0, many);
  EXPECT_EQ(read_citygml(write_temp("flat.gml", flat)).buildings.size(), 1u);
  // End tags before any start tag bank no levels for a deeper nesting after them.
  std::string stray = nested_parts(200);
  stray.replace(stray.find("<CityModel"), 0, [] {
    std::string s;
    for (int k = 0; k < 1000; ++k) s += "</x>";
    return s;
  }());
  EXPECT_NE(refusal(write_temp("stray.gml", stray)).find("nests elements more than 256 deep"), std::string::npos);
}

// Renaming searched every "<id>~<k>" (and "building-<k>") from the start: one gml:id given to
// 20,000 buildings took 27 s (quadratic), 60,000 minutes. The search resumes where the last
// one for the same name ended; the names are the same as before.
TEST(CityGmlSecurity, ManyBuildingsSharingAnIdAreNamedInLinearTime) {
  constexpr int kMany = 60000;
  std::string s = kHeader;
  auto box_building = [&](const std::string& id, double x) {
    s += "<cityObjectMember><bldg:Building" + (id.empty() ? std::string() : " gml:id=\"" + id + "\"") +
         "><bldg:lod2MultiSurface><gml:MultiSurface>";
    for (const auto& f : box_faces(Vec3(x, 0, 0), 4, 5, 3))
      s += "<gml:surfaceMember>" + polygon(f, "") + "</gml:surfaceMember>";
    s += "</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></cityObjectMember>";
  };
  // Objects without an id before the ids "building-1" ... "building-30000" they must not take.
  for (int k = 0; k < kMany / 2; ++k) s += "<cityObjectMember><bldg:Building/></cityObjectMember>";
  box_building("", 0);
  for (int k = 1; k <= kMany / 2; ++k)
    s += "<cityObjectMember><bldg:Building gml:id=\"building-" + std::to_string(k) + "\"/></cityObjectMember>";
  box_building("dup", 20);
  for (int k = 0; k < kMany; ++k) s += "<cityObjectMember><bldg:Building gml:id=\"dup\"/></cityObjectMember>";
  box_building("dup", 40);
  const std::string path = write_temp("dups.gml", s + "</CityModel>\n");
  const auto t0 = std::chrono::steady_clock::now();
  const CityJsonFile f = read_citygml(path);
  EXPECT_LT(fixtures::seconds_since(t0), fixtures::kHangGuardSeconds);
  std::vector<std::string> ids;
  for (const auto& b : f.buildings) ids.push_back(b.mesh.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"building-" + std::to_string(kMany + 1), "dup",
                                           "dup~" + std::to_string(kMany + 2)}));
}
