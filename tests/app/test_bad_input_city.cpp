// Bad city files given to `lodrefine refine --model` (CityJSON, CityJSONSeq, CityGML): refused
// in one line naming the file, or refined with what they hold kept (issue 15, the attack review
// of 2026-12-03).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "support/bad_input_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

// Issue 15, items 2, 13, 14 through the command line: untrusted city files.
TEST(BadInputSecurity, CityFilesRefusedInOneLineNamingTheFile) {
  const std::string dir = temp_dir("city_refusals");
  write_text(dir + "/c.ply", valid_cloud());
  const std::string xxe =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE CityModel [<!ENTITY e SYSTEM \"file:///etc/passwd\">]>\n"
      "<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\"><gml:name>&e;</gml:name></CityModel>\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"xxe.gml", xxe},
      {"overflow.city.json", R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[[1e400,0,0]]})"},
      {"scale0.city.json",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,0],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})"},
      {"header.city.jsonl",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":"x"},"CityObjects":{},"vertices":[]})"
       "\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{},\"vertices\":[]}\n"},
      {"deep.city.json", R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[],"x":)" +
                             std::string(100000, '[') + std::string(100000, ']') + "}"},
      // A second "CityObjects" replaced the first (its buildings gone without a word).
      {"twice.city.json",
       R"({"type":"CityJSON","version":"2.0","CityObjects":{"A":{"type":"Building"}},"vertices":[],"CityObjects":{}})"},
      // Non-string "version" / "type": a raw json type_error, exit 1, after the crop.
      {"version.city.json", R"({"type":"CityJSON","version":2,"CityObjects":{},"vertices":[]})"},
      {"type.city.json", R"({"type":"CityJSON","version":"1.1","CityObjects":{"A":{"type":5}},"vertices":[]})"},
      {"feature.city.jsonl",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})"
       "\n{\"type\":5,\"CityObjects\":{},\"vertices\":[]}\n"},
      {"seqheader.city.jsonl", "{\"type\":5}\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{},\"vertices\":[]}\n"},
      // 20,000 nested BuildingParts overflowed the CityGML module's stack (a crash, no line).
      {"deep.gml",
       [] {
         std::string s =
             "<?xml version=\"1.0\"?>\n<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\" "
             "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\"><cityObjectMember><bldg:Building>";
         for (int k = 0; k < 20000; ++k) s += "<bldg:consistsOfBuildingPart><bldg:BuildingPart>";
         for (int k = 0; k < 20000; ++k) s += "</bldg:BuildingPart></bldg:consistsOfBuildingPart>";
         return s + "</bldg:Building></cityObjectMember></CityModel>\n";
       }()},
  };
  for (const auto& [name, text] : files) {
    const std::string model = dir + "/" + name;
    write_text(model, text);
    const CliRun r = run_cli("refine --model " + shell_quote(model) + " --cloud " + shell_quote(dir + "/c.ply") +
                                 " --out " + shell_quote(dir + "/out.city.json"),
                             dir);
    EXPECT_EQ(r.exit, 2) << name << ": " << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("lodrefine: error: " + model + ": ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find("root:"), std::string::npos) << r.err;  // nothing of /etc/passwd
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/out.city.json")) << name;
    EXPECT_TRUE(temp_leftovers(dir).empty()) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// Found by an attacker's review (2026-12-03): before its fix each input below crashed, hung,
// wrote outside --out, filled the memory, or was written back as garbage.

// std::regex recursed once per digit of a CityJSON 1.x CRS name: 50,000 digits overflowed the
// stack (SIGSEGV). Such a name is kept as it is.
TEST(BadInputAttack, HugeCrsNameIsKeptNotACrash) {
  const std::string dir = temp_dir("attack_crs");
  const std::string crs = "EPSG:" + std::string(50000, '1');
  json doc = json::parse(box_city({"a"}));
  doc["version"] = "1.1";
  doc["metadata"] = {{"referenceSystem", crs}};
  write_text(dir + "/city.json", doc.dump());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun r = run_cli(
      "refine --quiet --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/out.city.json", dir,
      60);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(json::parse(read_text(dir + "/out.city.json"))["metadata"]["referenceSystem"], crs);
  add_row("CityJSON 1.1, CRS name of 50,000 digits", "refined; the name kept as it is", r.exit);
}

// A transform.scale of 1e-15 wrapped the refined vertices to -9.2e18 (64-bit overflow) and the
// file was written with exit 0.
TEST(BadInputAttack, TransformScaleFinerThanANanometreIsRefused) {
  const std::string dir = temp_dir("attack_scale");
  json doc = json::parse(box_city({"a"}));
  doc["transform"]["scale"] = {1e-15, 1e-15, 1e-15};
  write_text(dir + "/city.json", doc.dump());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun r = run_cli(
      "refine --quiet --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/out.city.json",
      dir);
  expect_one_error_line(r, "transform.scale has a factor below 1e-9 m");
  EXPECT_FALSE(fs::exists(dir + "/out.city.json"));
  add_row("CityJSON transform.scale 1e-15", "refused: the vertices written back would overflow", r.exit);
}
