// Uses the installed libraries: a 2 x 3 x 4 m box written and read back as OBJ (formats),
// measured (base), checked valid (core), its watertightness (eval). Exit 0 only when every
// figure is as built.
#include <cmath>
#include <cstdio>
#include <string>

#include "lodrefine/base/types.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/version.h"

int main(int argc, char** argv) {
  using namespace lodrefine;
  if (argc != 2) return 2;
  Mesh box;
  box.vertices = {{0, 0, 0}, {2, 0, 0}, {2, 3, 0}, {0, 3, 0}, {0, 0, 4}, {2, 0, 4}, {2, 3, 4}, {0, 3, 4}};
  box.faces = {{{0, 3, 2, 1}, Semantic::Ground}, {{4, 5, 6, 7}, Semantic::Roof}, {{0, 1, 5, 4}, Semantic::Wall},
               {{1, 2, 6, 5}, Semantic::Wall},   {{2, 3, 7, 6}, Semantic::Wall}, {{3, 0, 4, 7}, Semantic::Wall}};
  write_obj(argv[1], box);
  const Mesh back = read_obj(argv[1]);
  const double volume = signed_volume(back.vertices, back.faces);
  const bool valid = validate_mesh(back, 1e-6).valid();
  const bool closed = is_watertight(back);
  std::printf("lodrefine %s: %zu faces, volume %.3f m3, valid %d, watertight %d\n", LODREFINE_VERSION,
              back.faces.size(), volume, int(valid), int(closed));
  return back.faces.size() == 6 && std::abs(volume - 24.0) < 1e-9 && valid && closed ? 0 : 1;
}
