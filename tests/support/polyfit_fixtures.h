// The box building of the PolyFit tests (tests/tools/test_polyfit_*.cpp): its truth, a coarse
// model of it with one wall out, and a clean scan, georeferenced as a Dutch tile.
#pragma once
#include <random>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

namespace lodrefine::fixtures {

inline const Vec3 kTileOrigin(85012.0, 446034.0, 2.0);  // georeferenced, as a Dutch tile (EPSG:28992)

// The truth: a 12 × 8 × 6 m box.
inline Mesh truth_box() { return translated(box(Vec3::Zero(), Vec3(12, 8, 6)), kTileOrigin); }

// A clean scan of every face of `m` (5 mm noise, a point every 0.1 m).
inline PointCloud scan_of(const Mesh& m, const std::vector<int>& faces) {
  std::mt19937 rng(7);
  PointCloud cloud;
  for (int f : faces) sample_face(face_points(m, m.faces[std::size_t(f)]), 0.0, 0.1, rng, cloud);
  return cloud;
}
inline PointCloud full_scan(const Mesh& m) { return scan_of(m, {0, 1, 2, 3, 4, 5}); }

// The coarse model: the truth with its wall x = 12 moved 0.4 m out.
inline Mesh coarse_box() { return translated(box(Vec3::Zero(), Vec3(12.4, 8, 6)), kTileOrigin); }

}  // namespace lodrefine::fixtures
