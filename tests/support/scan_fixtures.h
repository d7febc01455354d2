// Synthetic MLS points for the stage tests: grids on planar rectangles with range noise, and the
// scan plane of such a grid built directly (without RANSAC).
#pragma once
#include <random>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/planes.h"

namespace lodrefine::fixtures {

// A rectangle origin + s·u + t·v, s in [s0, s1], t in [t0, t1] (u, v orthonormal), sampled every
// `step` metres along both, ends included.
struct Patch {
  Vec3 origin, u, v;
  double s0, s1, t0, t1;
  Vec3 normal() const { return u.cross(v); }
};

// Appends the patch's grid to `cloud`, each point moved by N(0, sigma) along the normal (range
// noise); returns the indices of the new points.
inline std::vector<int> add_grid(PointCloud& cloud, const Patch& p, double step, double sigma = 0.0,
                                 unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<int> idx;
  const int ns = int((p.s1 - p.s0) / step + 1e-6), nt = int((p.t1 - p.t0) / step + 1e-6);
  for (int i = 0; i <= ns; ++i)
    for (int j = 0; j <= nt; ++j) {
      const double n = sigma > 0 ? noise(rng) : 0.0;
      idx.push_back(int(cloud.points.size()));
      cloud.points.push_back(p.origin + (p.s0 + i * step) * p.u + (p.t0 + j * step) * p.v + n * p.normal());
    }
  return idx;
}

// A vertical patch: from `start` along the horizontal unit `along` for `length` m, z from z0 to
// z1. Its normal along × e_z faces right of `along` (-y for a wall running along +x).
inline Patch wall_patch(const Vec3& start, const Vec3& along, double length, double z0, double z1) {
  return {Vec3(start.x(), start.y(), 0.0), along, Vec3::UnitZ(), 0.0, length, z0, z1};
}

// The facade scan plane of the noise-free grid of a vertical patch, as detect_planes would
// describe it (normal = the patch's).
inline ScanPlane grid_scan_plane(PointCloud& cloud, const Patch& p, double step) {
  ScanPlane sp;
  sp.inliers = add_grid(cloud, p, step);
  sp.plane = Plane::through(p.origin, p.normal());
  for (int i : sp.inliers) sp.centroid += cloud.points[i];
  sp.centroid /= double(sp.inliers.size());
  sp.hull_area = (p.s1 - p.s0) * (p.t1 - p.t0);
  sp.facade = true;
  return sp;
}

// Points on a wall face moved `offset` along its normal, every `step` metres, with noise.
inline void sample_face(const std::vector<Vec3>& poly, double offset, double step, std::mt19937& rng, PointCloud& out) {
  const Plane pl = polygon_plane(poly);
  const auto [u, v] = pl.basis();
  std::vector<Vec2> p2;
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
  for (const auto& p : poly) {
    p2.emplace_back(u.dot(p), v.dot(p));
    u0 = std::min(u0, p2.back().x()), u1 = std::max(u1, p2.back().x());
    v0 = std::min(v0, p2.back().y()), v1 = std::max(v1, p2.back().y());
  }
  std::normal_distribution<double> noise(0.0, 0.005);
  const Vec3 base = pl.project(Vec3::Zero());
  for (double a = u0 + step / 2; a < u1; a += step)
    for (double b = v0 + step / 2; b < v1; b += step)
      if (point_in_polygon_2d(Vec2(a, b), p2))
        out.points.push_back(base + a * u + b * v + (offset + noise(rng)) * pl.n);
}

// A terraced street: one facade plane y = 0 running from x = x0 to x1 (the houses' fronts are
// flush, so the scan shows no corner between them), cut at both ends by the tile's edge; the
// houses scanned from 0.2 m to 6.5 m high (1 cm range noise), with the street's ground in front.
inline PointCloud terraced_street_scan(double x0, double x1, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  PointCloud pc;
  for (double x = x0; x <= x1; x += 0.05)
    for (double z = 0.2; z <= 6.5; z += 0.05) pc.points.emplace_back(x, noise(rng), z);
  for (double x = x0; x <= x1; x += 0.1)
    for (double y = -6.0; y < -0.3; y += 0.1) pc.points.emplace_back(x, y, noise(rng));
  return pc;
}

}  // namespace lodrefine::fixtures
