// libFuzzer target: bytes -> temporary .obj -> read_obj. InputError is the only accepted way
// to refuse input; any other exception, a sanitizer report or a broken invariant is a crash.
// Accepted meshes must be usable by the pipeline (indices in range, finite coordinates,
// polygons of 3+ vertices) and survive write_obj -> read_obj unchanged in shape; the split
// into solid and fins (read_obj_model) covers every face and survives its own round trip.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/formats/obj.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::temp_file("in.obj");
  static const std::string out = fuzz::temp_file("out.obj");
  fuzz::write_bytes(path, data, size);
  Mesh m;
  int skipped = -1;
  try {
    m = read_obj(path, &skipped);
  } catch (const InputError& e) {
    fuzz::check_message(e.what(), path);
    return 0;
  }
  FUZZ_CHECK(!m.faces.empty(), "accepted a mesh without faces");
  FUZZ_CHECK(skipped >= 0, "skipped_faces not set");
  for (const auto& v : m.vertices) FUZZ_CHECK(v.allFinite(), "non-finite vertex accepted");
  for (const auto& f : m.faces) {
    FUZZ_CHECK(f.v.size() >= 3, "face with %zu vertices", f.v.size());
    for (int i : f.v) FUZZ_CHECK(i >= 0 && std::size_t(i) < m.vertices.size(), "index %d of %zu", i, m.vertices.size());
  }

  // Round trip: what we accept we must be able to write, and read back the same shape.
  try {
    write_obj(out, m);
  } catch (const std::runtime_error& e) {
    FUZZ_CHECK(false, "write_obj failed on an accepted mesh: %s", e.what());
  }
  Mesh back;
  try {
    back = read_obj(out);
  } catch (const InputError& e) {
    FUZZ_CHECK(false, "cannot read back our own OBJ: %s", e.what());
  }
  FUZZ_CHECK(back.faces.size() == m.faces.size(), "round trip: %zu faces, was %zu", back.faces.size(), m.faces.size());
  FUZZ_CHECK(back.vertices.size() == m.vertices.size(), "round trip: %zu vertices, was %zu", back.vertices.size(),
             m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const double err = (back.vertices[i] - m.vertices[i]).lpNorm<Eigen::Infinity>();
    const double mag = m.vertices[i].lpNorm<Eigen::Infinity>();
    FUZZ_CHECK(err <= 1e-6 + 1e-12 * mag, "round trip moved vertex %zu by %g", i, err);
  }

  // The fins group: the split covers every face, and survives write_obj -> read_obj_model.
  ObjModel split;
  try {
    split = read_obj_model(path);
  } catch (const InputError& e) {
    FUZZ_CHECK(false, "read_obj accepted what read_obj_model refuses: %s", e.what());
  }
  FUZZ_CHECK(split.solid.faces.size() + split.fins.faces.size() == m.faces.size(), "split: %zu + %zu faces of %zu",
             split.solid.faces.size(), split.fins.faces.size(), m.faces.size());
  try {
    write_obj(out, split.solid, split.fins);
    const ObjModel again = read_obj_model(out);
    FUZZ_CHECK(
        again.solid.faces.size() == split.solid.faces.size() && again.fins.faces.size() == split.fins.faces.size(),
        "fins round trip: %zu + %zu faces, was %zu + %zu", again.solid.faces.size(), again.fins.faces.size(),
        split.solid.faces.size(), split.fins.faces.size());
  } catch (const std::runtime_error& e) {
    FUZZ_CHECK(false, "fins round trip failed: %s", e.what());
  }
  return 0;
}
