// Small closed test buildings shared by the core and evaluation tests (outward, counter-clockwise
// faces, shared vertices unless made a soup).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine::fixtures {

// Prism over a counter-clockwise footprint between z0 and z1: face 0 ground, 1 roof, then one
// wall per footprint edge (edge i -> i+1 is face 2 + i).
inline Mesh extrusion(const std::vector<Vec2>& footprint, double z0, double z1) {
  Mesh m;
  m.id = "prism";
  const int n = int(footprint.size());
  for (double z : {z0, z1})
    for (const auto& p : footprint) m.vertices.emplace_back(p.x(), p.y(), z);
  Face ground{{}, Semantic::Ground}, roof{{}, Semantic::Roof};
  for (int i = 0; i < n; ++i) ground.v.push_back(n - 1 - i), roof.v.push_back(n + i);
  m.faces = {ground, roof};
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.faces.push_back({{i, j, n + j, n + i}, Semantic::Wall});
  }
  return m;
}

// Axis-aligned box: walls 2 (y = lo), 3 (x = hi), 4 (y = hi), 5 (x = lo).
inline Mesh box(const Vec3& lo, const Vec3& hi) {
  return extrusion({{lo.x(), lo.y()}, {hi.x(), lo.y()}, {hi.x(), hi.y()}, {lo.x(), hi.y()}}, lo.z(), hi.z());
}

// Square pyramid with a needle apex at (0, 0, 10): just above the apex, the normal of any one
// adjacent face gives the wrong sign.
inline Mesh needle() {
  Mesh m;
  m.vertices = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 10}};
  m.faces = {{{0, 3, 2, 1}, Semantic::Ground},
             {{0, 1, 4}, Semantic::Wall},
             {{1, 2, 4}, Semantic::Wall},
             {{2, 3, 4}, Semantic::Wall},
             {{3, 0, 4}, Semantic::Wall}};
  return m;
}

// 10 × 8 m house, eaves at 6 m, ridge at 9 m along x.
inline Mesh gable_house() {
  Mesh m;
  m.vertices = {{0, 0, 0},  {10, 0, 0}, {10, 8, 0}, {0, 8, 0}, {0, 0, 6},
                {10, 0, 6}, {10, 8, 6}, {0, 8, 6},  {0, 4, 9}, {10, 4, 9}};
  m.faces = {{{0, 3, 2, 1}, Semantic::Ground},  {{0, 1, 5, 4}, Semantic::Wall},    {{2, 3, 7, 6}, Semantic::Wall},
             {{1, 2, 6, 9, 5}, Semantic::Wall}, {{3, 0, 4, 8, 7}, Semantic::Wall}, {{4, 5, 9, 8}, Semantic::Roof},
             {{6, 7, 8, 9}, Semantic::Roof}};
  return m;
}

// Every face with its own copies of its vertices, as exported from CityGML.
inline Mesh as_soup(const Mesh& m) {
  Mesh s;
  s.id = m.id;
  for (const Face& f : m.faces) {
    Face g = f;
    g.v.clear();
    for (int v : f.v) {
      g.v.push_back(int(s.vertices.size()));
      s.vertices.push_back(m.vertices[std::size_t(v)]);
    }
    s.faces.push_back(g);
  }
  return s;
}

// Both meshes in one (no vertex shared): a part exported beside another.
inline Mesh merged(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  const int offset = int(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (Face f : b.faces) {
    for (int& v : f.v) v += offset;
    m.faces.push_back(f);
  }
  return m;
}

// The faces of `m` listed in `keep`, in that order, each with its own copies of its vertices (an
// export that lost the others).
inline Mesh only_faces(const Mesh& m, std::initializer_list<int> keep) {
  Mesh out;
  out.id = m.id;
  for (int f : keep) {
    Face face = m.faces[std::size_t(f)];
    for (int& v : face.v) {
      out.vertices.push_back(m.vertices[std::size_t(v)]);
      v = int(out.vertices.size()) - 1;
    }
    out.faces.push_back(face);
  }
  return out;
}

// Largest distance of a vertex of `out` from the nearest vertex of `in` (a kept building is its
// input when this is within the weld tolerance).
inline double largest_vertex_move(const Mesh& out, const Mesh& in) {
  double worst = 0.0;
  for (const auto& p : out.vertices) {
    double best = 1e300;
    for (const auto& q : in.vertices) best = std::min(best, (p - q).squaredNorm());
    worst = std::max(worst, best);
  }
  return std::sqrt(worst);
}

}  // namespace lodrefine::fixtures
