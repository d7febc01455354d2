// CityGML: the file is checked here (kind, xml_guard, version); libcitygml reads it in the module
// lodrefine_citygml.so (src/formats/citygml_module/), loaded only now (citygml_module.h), which turns
// the buildings into a CityJSON document for the CityJSON reader.
#include "lodrefine/formats/citygml.h"

#include <fstream>
#include <regex>
#include <string_view>
#include <unordered_map>

#include "citygml_module.h"
#include "lodrefine/base/files.h"
#include "lodrefine/base/text.h"
#include "xml_guard.h"

namespace lodrefine {
namespace {

// The CityGML version (from the namespace) and the first srsName, from the file's text; searched
// in windows so the regexes never run over a whole large file.
void scan_text(std::string_view text, std::string& version, std::string& srs) {
  static const std::regex ns("http://www\\.opengis\\.net/citygml/([0-9]\\.[0-9])");
  static const std::regex srs_attr("srsName=\"([^\"]{1,200})\"");
  constexpr std::size_t kWindow = 1 << 20, kOverlap = 300;
  for (std::size_t at = 0; at < text.size() && (version.empty() || srs.empty()); at += kWindow - kOverlap) {
    const std::string window(text.substr(at, kWindow));
    std::smatch m;
    if (version.empty() && std::regex_search(window, m, ns)) version = m[1];
    if (srs.empty() && std::regex_search(window, m, srs_attr)) srs = m[1];
  }
}

}  // namespace

std::string crs_url(const std::string& srs_name) {
  // std::regex recurses once per character matched: a name of 50,000 digits overflowed the
  // stack. No CRS name is that long; such a name is kept as it is.
  if (srs_name.size() > kMaxCrsName) return srs_name;
  static const std::regex epsg("EPSG(?::[0-9.]*)?:+([0-9]+)|EPSG/[0-9]+/([0-9]+)", std::regex::icase);
  std::smatch m;
  if (!std::regex_search(srs_name, m, epsg)) return srs_name;
  return "https://www.opengis.net/def/crs/EPSG/0/" + std::string(m[1].matched ? m[1] : m[2]);
}

nlohmann::ordered_json citygml_to_cityjson(const std::string& path, std::string* citygml_version,
                                           std::vector<std::string>* notes) {
  require_regular_file(path);  // a FIFO would block the probe below, /dev/zero be read without end
  const FileKind kind = sniff_file(path);
  if (kind != FileKind::Xml) {
    std::ifstream probe(path);
    if (!probe) throw InputError(path + ": cannot open the file");
    throw InputError(path + ": not a CityGML file" +
                     (kind == FileKind::Other ? std::string(" (no XML)") : ": the file is " + file_kind_text(kind)));
  }
  // Checked before libcitygml sees a byte: no DTD, no entities, an encoding the check can read.
  std::string text = io_xml::safe_citygml_text(io_text::read_whole_file(path), path);
  std::string version, srs;
  scan_text(text, version, srs);
  if (version.empty()) throw InputError(path + ": XML but not CityGML (no CityGML 1.0/2.0 namespace)");
  if (version != "1.0" && version != "2.0")
    throw InputError(path + ": CityGML " + version + " is not supported (libcitygml reads CityGML 1.0 and 2.0)");
  if (citygml_version) *citygml_version = version;

  io_citygml::RenamedIds renamed;
  nlohmann::ordered_json doc;
  io_citygml::to_cityjson(path, text, srs.empty() ? std::string() : crs_url(srs), doc, renamed);
  if (notes)
    for (const auto& [given, written] : renamed)
      notes->push_back("gml:id " + shown_id(given) + " is given to more than one building: one is written as " +
                       shown_id(written));
  return doc;
}

namespace {
CityJsonFile citygml_file(const std::string& path) {
  std::string version;
  std::vector<std::string> notes;
  const auto doc = citygml_to_cityjson(path, &version, &notes);
  CityJsonFile f = read_cityjson_document(doc, path);
  f.notes.insert(f.notes.begin(), notes.begin(), notes.end());
  f.format = "CityGML";
  f.version = version;
  // Attributes travel with each building (CityJSON input keeps them in its own document). Found
  // through an index: ordered_json::find searches the objects in order (quadratic over a file).
  std::unordered_map<std::string_view, const nlohmann::ordered_json*> attributes;
  for (const auto& [id, object] : doc["CityObjects"].get_ref<const nlohmann::ordered_json::object_t&>())
    if (const auto it = object.find("attributes"); it != object.end()) attributes.emplace(id, &*it);
  for (auto& b : f.buildings)
    if (const auto it = attributes.find(b.mesh.id); it != attributes.end()) b.attributes = *it->second;
  return f;
}
}  // namespace

CityJsonFile read_citygml(const std::string& path) {
  return read_naming_memory(path, [&] { return citygml_file(path); });
}

CityJsonFile read_city_file(const std::string& path) {
  return sniff_file(path) == FileKind::Xml ? read_citygml(path) : read_cityjson(path);
}

}  // namespace lodrefine
