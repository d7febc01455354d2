// The box [0,a] x [0,b] x [0,c] as the candidate stages see it: its six outward supporting
// planes, the region around it and its faces as model references (same order as the planes:
// x = 0, x = a, y = 0, y = b, z = 0, z = c). Shared by the candidate, confidence and selection
// tests.
#pragma once
#include <vector>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/confidence.h"

namespace lodrefine::fixtures {

inline std::vector<SupportPlane> box_planes(double a, double b, double c) {
  std::vector<SupportPlane> p;
  p.push_back({Plane(Vec3(-1, 0, 0), 0), Semantic::Wall, false, 0});
  p.push_back({Plane(Vec3(1, 0, 0), -a), Semantic::Wall, false, 1});
  p.push_back({Plane(Vec3(0, -1, 0), 0), Semantic::Wall, false, 2});
  p.push_back({Plane(Vec3(0, 1, 0), -b), Semantic::Wall, false, 3});
  p.push_back({Plane(Vec3(0, 0, -1), 0), Semantic::Ground, false, 4});
  p.push_back({Plane(Vec3(0, 0, 1), -c), Semantic::Roof, false, 5});
  return p;
}

// The pipeline's region around a building's box: 10 % and 1 m beyond it on each side.
inline Region box_region(double a, double b, double c) {
  return Region::around({Vec3(0, 0, 0), Vec3(a, b, c)}, 0.1, 1.0);
}

inline std::vector<ModelReference> box_references(double a, double b, double c) {
  return {{{Vec3(0, 0, 0), Vec3(0, 0, c), Vec3(0, b, c), Vec3(0, b, 0)}},
          {{Vec3(a, 0, 0), Vec3(a, b, 0), Vec3(a, b, c), Vec3(a, 0, c)}},
          {{Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, 0, c), Vec3(0, 0, c)}},
          {{Vec3(0, b, 0), Vec3(0, b, c), Vec3(a, b, c), Vec3(a, b, 0)}},
          {{Vec3(0, 0, 0), Vec3(0, b, 0), Vec3(a, b, 0), Vec3(a, 0, 0)}},
          {{Vec3(0, 0, c), Vec3(a, 0, c), Vec3(a, b, c), Vec3(0, b, c)}}};
}

inline bool inside_box(const Vec3& p, double a, double b, double c) {
  return p.x() > -1e-9 && p.x() < a + 1e-9 && p.y() > -1e-9 && p.y() < b + 1e-9 && p.z() > -1e-9 && p.z() < c + 1e-9;
}

}  // namespace lodrefine::fixtures
