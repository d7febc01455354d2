// libFuzzer target: the whole refine on tiny inputs. Layout of an input:
//   byte 0-1   OBJ length L (little endian, taken modulo the bytes left + 1)
//   byte 2     flags: bit 0 = tiny-cloud parameters (RANSAC accepts planes of 20 points, so a
//              few hundred bytes of PLY can reach matching, candidates and GLPK)
//   then       L bytes of OBJ, the rest is the PLY.
// Both files are read with the real readers (InputError = refused, fine), then refine_building
// runs with a 1 s GLPK limit. It may refuse the model with InputError; anything else that
// escapes, a sanitizer report or a broken promise of RefineResult is a crash.
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/refine/refine.h"

using namespace lodrefine;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string obj_path = fuzz::temp_file("refine.obj");
  static const std::string ply_path = fuzz::temp_file("refine.ply");
  if (size < 3) return 0;
  const std::size_t rest = size - 3;
  const std::size_t obj_len = (std::size_t(data[0]) | std::size_t(data[1]) << 8) % (rest + 1);
  const bool tiny = data[2] & 1;
  fuzz::write_bytes(obj_path, data + 3, obj_len);
  fuzz::write_bytes(ply_path, data + 3 + obj_len, rest - obj_len);

  Mesh model;
  PointCloud cloud;
  try {
    model = read_obj(obj_path);
    cloud = read_ply(ply_path);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    fuzz::check_message(e.what(), msg.rfind(obj_path, 0) == 0 ? obj_path : ply_path);
    return 0;
  }

  RefineConfig prm;
  prm.selection.mip_time_limit = 1.0;
  if (tiny) {
    prm.plane.ransac_min_points = 20;
    prm.plane.min_plane_area = 0.2;
    prm.plane.normal_neighbors = 6;
    prm.plane.ransac_cluster_epsilon = 1.0;  // seed clouds are sparse (0.5 m spacing)
  }
  RefineResult r;
  try {
    r = refine_building(model, cloud, prm);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    FUZZ_CHECK(msg.find('\n') == std::string::npos, "multi-line InputError from refine: %s", e.what());
    return 0;
  }
  if (std::getenv("FUZZ_VERBOSE"))  // replaying an input by hand: how far did it get?
    std::fprintf(stderr, "model %zu faces, cloud %zu points: %s\n", model.faces.size(), cloud.points.size(),
                 outcome_name(r.outcome));
  FUZZ_CHECK(!r.reason.empty(), "outcome '%s' without a reason", outcome_name(r.outcome));
  FUZZ_CHECK(!r.refined() || r.valid, "refined but not valid");
  FUZZ_CHECK(refine_report(r).value("outcome", std::string()) == outcome_name(r.outcome),
             "report disagrees on the outcome");
  if (r.valid) {
    FUZZ_CHECK(!r.mesh.faces.empty(), "valid result without faces");
    for (const auto& v : r.mesh.vertices) FUZZ_CHECK(v.allFinite(), "non-finite vertex in a valid result");
    for (const auto& f : r.mesh.faces) {
      FUZZ_CHECK(f.v.size() >= 3, "face with %zu vertices in a valid result", f.v.size());
      for (int i : f.v) FUZZ_CHECK(i >= 0 && std::size_t(i) < r.mesh.vertices.size(), "bad index %d", i);
    }
  }
  return 0;
}
