// libFuzzer target: bytes -> temporary .gml -> read_citygml (libcitygml + the CityJSON reader).
// Refuses only with a one-line InputError naming the file; an accepted building has faces of
// 3+ in-range vertices with finite coordinates, its attributes never hold the content of a
// local file that an external entity could name (the dictionary points entities at it), and
// no two buildings share an id.
#include <cstdint>
#include <set>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/formats/citygml.h"

using namespace lodrefine;

namespace {

// What /tmp/lodrefine_fuzz_secret holds (the dictionary's entities name that file): it must
// never reach a building unless the input itself holds it.
const char* kSecret = "xxe-9f4c2a71";

void write_secret() {
  static const bool written = [] {
    const std::string s = kSecret;
    fuzz::write_bytes("/tmp/lodrefine_fuzz_secret", reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
    return true;
  }();
  (void)written;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.gml");
  write_secret();
  fuzz::write_bytes(path, data, size);
  const bool input_has_secret =
      std::string(reinterpret_cast<const char*>(data), size).find(kSecret) != std::string::npos;
  try {
    const CityJsonFile f = read_citygml(path);
    std::set<std::string> ids;
    for (const auto& b : f.buildings) {
      FUZZ_CHECK(!b.mesh.faces.empty(), "building %s without faces", b.mesh.id.c_str());
      FUZZ_CHECK(ids.insert(b.mesh.id).second, "two buildings with id %s", b.mesh.id.c_str());
      FUZZ_CHECK(input_has_secret ||
                     b.attributes.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).find(kSecret) ==
                         std::string::npos,
                 "a local file's content reached the attributes of %s", b.mesh.id.c_str());
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
