// libFuzzer target: bytes -> temporary .json -> read_cityjson (CityJSON or CityJSONSeq, by
// content), then the accepted text parsed and written back as the city refine does.
// Refuses only with a one-line InputError naming the file; an accepted building has faces of
// 3+ in-range vertices with finite coordinates within 1e9 m, and ids are unique; whatever the
// parser accepts can be written (no stack overflow on deep nesting, no throw on bad UTF-8).
#include <cstdint>
#include <set>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/base/files.h"
#include "lodrefine/formats/cityjson.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.city.json");
  fuzz::write_bytes(path, data, size);
  try {
    const CityJsonFile f = read_cityjson(path);
    std::set<std::string> ids;
    for (const auto& b : f.buildings) {
      FUZZ_CHECK(!b.mesh.faces.empty(), "building %s without faces", b.mesh.id.c_str());
      FUZZ_CHECK(f.sequence || ids.insert(b.mesh.id).second, "id %s read twice from one document", b.mesh.id.c_str());
      FUZZ_CHECK(b.fin_faces >= 0 && std::size_t(b.fin_faces) <= b.mesh.faces.size(), "%d fin faces of %zu",
                 b.fin_faces, b.mesh.faces.size());
      FUZZ_CHECK(b.fins_index < 0 ? b.fin_faces == 0 : b.fins_index == b.geometry_index + 1,
                 "fins at %d beside geometry %d", b.fins_index, b.geometry_index);
      for (const auto& face : b.mesh.faces) {
        FUZZ_CHECK(face.v.size() >= 3, "face of %zu vertices", face.v.size());
        for (int v : face.v) {
          FUZZ_CHECK(v >= 0 && std::size_t(v) < b.mesh.vertices.size(), "vertex index out of range");
          const Vec3& p = b.mesh.vertices[std::size_t(v)];
          FUZZ_CHECK(p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate, "vertex beyond 1e9 m accepted");
        }
      }
    }
    if (!f.sequence) {  // the city refine's write: the whole document dumped
      const std::string text(reinterpret_cast<const char*>(data), size);
      const auto doc = parse_city_json(text, path);
      (void)doc.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
    }
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
  }
  return 0;
}
