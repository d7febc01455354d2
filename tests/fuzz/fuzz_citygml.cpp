// libFuzzer target: bytes -> temporary .gml -> read_citygml (libcitygml + the CityJSON reader).
// Refuses only with a one-line InputError naming the file; an accepted building has faces of
// 3+ in-range vertices with finite coordinates.
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/io/citygml.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.gml");
  fuzz::write_bytes(path, data, size);
  try {
    const CityJsonFile f = read_citygml(path);
    for (const auto& b : f.buildings) {
      FUZZ_CHECK(!b.mesh.faces.empty(), "building %s without faces", b.mesh.id.c_str());
      FUZZ_CHECK(b.mesh.id.find("genID_") == std::string::npos, "generated id written: %s", b.mesh.id.c_str());
      for (const auto& face : b.mesh.faces) {
        FUZZ_CHECK(face.v.size() >= 3, "face of %zu vertices", face.v.size());
        for (int v : face.v) {
          FUZZ_CHECK(v >= 0 && std::size_t(v) < b.mesh.vertices.size(), "vertex index out of range");
          FUZZ_CHECK(b.mesh.vertices[std::size_t(v)].allFinite(), "non-finite vertex");
        }
      }
    }
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
  }
  return 0;
}
