// Reading LoD2 buildings from CityJSON (1.0, 1.1, 2.0) and CityJSONSeq (.jsonl) files.
//
// Every Building and every BuildingPart that has an LoD 2.x geometry becomes one Mesh (id =
// its CityObject id; parts are NOT merged into their parent). The geometry used is the highest
// LoD 2.x one: Solid -> its exterior shell, MultiSolid/CompositeSolid -> the exterior shell of
// each solid, MultiSurface/CompositeSurface -> all surfaces; a Solid lodrefine wrote with fins
// beside it (CityJsonBuilding::fins_index) -> its shell and, after it, the fins' surfaces. The output is a polygon soup
// in the georeferenced frame (the file's `transform` applied), each face with its own vertices, as an OBJ fan-out
// export of the same building would be; Face::source is the surface's index in the geometry (running over all shells),
// Face::sem comes from the semantics (WallSurface / RoofSurface / GroundSurface, anything else -> Other).
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/base/types.h"

namespace lodrefine {

// The city file formats the city readers take (read_cityjson, read_citygml), as the commands'
// help names them (one list: tests/app/test_help.cpp checks every command that reads one).
inline const std::vector<std::string> kCityFormatNames = {"CityJSON", "CityJSONSeq", "CityGML"};

struct CityJsonBuilding {
  Mesh mesh;                  // polygon soup, georeferenced, mesh.id = CityObject id; its fins last
  std::string type;           // "Building" or "BuildingPart"
  std::string parent;         // first parent id (BuildingPart), empty otherwise
  std::string lod;            // the LoD used, as written in the file ("2", "2.2")
  std::string geometry_type;  // "Solid", "MultiSurface", ...
  int geometry_index = -1;    // position of that geometry in the object's "geometry" array
  // A building lodrefine wrote (a `lodrefine_outcome` attribute) with a MultiSurface of the
  // Solid's LoD right after it: its fins (RefineResult::fins), read back as part of the building.
  int fins_index = -1;        // that MultiSurface's position in "geometry" (geometry_index + 1), or -1
  int fin_faces = 0;          // the last fin_faces of mesh.faces are the fins' (their sources follow the Solid's)
  int skipped_holes = 0;      // inner rings dropped (the surface keeps its outer ring only)
  int skipped_rings = 0;      // outer rings with < 3 distinct vertices, dropped
  int skipped_shells = 0;     // interior shells of solids, dropped
  nlohmann::json attributes;  // CityGML input: the object's attributes (CityJSON input keeps its own JSON)
};

// `b`'s soup without its fins (the last fin_faces faces): the shell its geometry holds, what is
// validated as one solid. Fins are surfaces beside the solid (val3dity too checks a MultiSurface
// apart from a Solid): validated with it, each would be open edges and a component of its own.
Mesh solid_soup(const CityJsonBuilding& b);

struct CityJsonFile {
  std::string format = "CityJSON";  // or "CityGML"
  std::string version;              // "1.0", "1.1", "2.0"
  bool sequence = false;            // read as CityJSONSeq
  std::string crs;                  // metadata.referenceSystem, empty when absent
  Vec3 scale = Vec3::Ones();        // transform (identity when the file has none)
  Vec3 translate = Vec3::Zero();
  std::vector<CityJsonBuilding> buildings;    // in file order (object order within a feature)
  int objects_without_lod2 = 0;               // Building/BuildingPart objects with no LoD 2.x geometry
  std::vector<std::string> ids_without_lod2;  // their ids, in file order (every building by name)
  std::vector<std::string> notes;             // one line per thing worth knowing (holes dropped ...)
};

// Reads a CityJSON file or a CityJSONSeq stream (recognised by its content: a first line that
// is a complete "CityJSON" object followed by "CityJSONFeature" lines). Throws InputError with
// a one-line message "<path>: <fault>" on unreadable or malformed input (bad JSON, wrong type,
// vertex index out of range, boundaries or semantics not shaped as the geometry type says).
// `lod` (e.g. "2.2") picks that LoD instead of the highest 2.x one; objects without it count
// as objects_without_lod2.
CityJsonFile read_cityjson(const std::string& path, const std::string& lod = "");

// Same, from text in memory; `name` is used in error messages.
CityJsonFile parse_cityjson(const std::string& text, const std::string& name = "<cityjson>",
                            const std::string& lod = "");

// Same, from a parsed CityJSON object (not a sequence).
CityJsonFile read_cityjson_document(const nlohmann::ordered_json& doc, const std::string& name,
                                    const std::string& lod = "");

// JSON nesting accepted in a city file: CityJSON needs about ten levels (a MultiSolid's
// boundaries are five deep); deeper nesting would overflow the stack when copied or written.
constexpr int kMaxJsonDepth = 256;

// Parses the JSON text of a CityJSON file or of one CityJSONSeq line. Throws InputError with
// one line "<name>: <fault>" for malformed JSON, numbers beyond the double range (1e400),
// nesting deeper than kMaxJsonDepth, and a CityObjects id that appears twice in one object
// (JSON parsers silently keep one of the two).
nlohmann::ordered_json parse_city_json(std::string_view text, const std::string& name);

// Parses the JSON text of any other untrusted file (a run folder's report, a baseline, gates)
// into plain nlohmann::json (hashed keys: ordered_json's search in order is quadratic in the keys
// of an object), nesting bounded by kMaxJsonDepth; a key given twice keeps the last. Throws
// InputError with one line "<name>: <fault>".
nlohmann::json parse_json(std::string_view text, const std::string& name);

// A value of such a file quoted in an error line: its JSON text (bytes that are no UTF-8 as
// U+FFFD), cut to 40 characters, control characters escaped (escaped_line).
std::string shown_json(const nlohmann::json& value);

// True when `text` is a CityJSONSeq: a first line holding a complete "CityJSON" object, then
// more lines (the CityJSONFeatures).
bool is_cityjson_sequence(const std::string& text);

// Semantic of a CityJSON semantic surface type ("WallSurface" -> Wall, ...; others -> Other).
Semantic semantic_from_cityjson(const std::string& type);

// Adds the ids of a CityJSONSeq feature's "CityObjects" to `seen`; throws InputError "<where>:
// CityObject <id> is in an earlier feature too" for one already there: ids are unique in a
// sequence as in one document (--building and the review page name a building by its id).
void add_feature_ids(const nlohmann::ordered_json& feature, std::unordered_set<std::string>& seen,
                     const std::string& where);

// An LoD as CityJSON writes it, a plain decimal that is the whole string ("2", "2.2", at most 8
// characters); nullopt for anything else ("2.2\0…", "0x2.8p0", "2.", "").
std::optional<double> lod_number(const std::string& text);

}  // namespace lodrefine
