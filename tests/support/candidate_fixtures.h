// The box [0,a] x [0,b] x [0,c] as the candidate stages see it: its six outward supporting
// planes (x = 0, x = a, y = 0, y = b, z = 0, z = c) and the region around it. Shared by the
// candidate, selection and shell tests.
#pragma once
#include <vector>

#include "lodrefine/refine/candidates.h"

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

// Candidate f's face maps (candidates.h).
inline int plane_of(const CandidateSet& cs, int f) { return cs.supports()[CandidateFace(f)]; }
inline double area_of(const CandidateSet& cs, int f) { return cs.areas()[CandidateFace(f)]; }
inline Vec3 centroid_of(const CandidateSet& cs, int f) { return cs.centroids()[CandidateFace(f)]; }

// A program built by hand: candidate f on plane plane[f] with area area[f], each a polygon of its
// own (a corner per fan it is on, at least 3; the corners are points no other face has), and
// the fans `edges` (the candidates along each, in order; one listed twice is on it twice).
inline CandidateSet hand_built(const std::vector<int>& plane, const std::vector<double>& area,
                               const std::vector<std::vector<int>>& edges) {
  CandidateSet cs;
  auto support = candidate_props::support.add(cs.mesh);
  auto areas = candidate_props::area.add(cs.mesh);
  candidate_props::centroid.add(cs.mesh);
  auto point = candidate_props::point.add(cs.mesh);
  std::vector<std::size_t> uses(plane.size(), 0);
  for (const auto& e : edges)
    for (int f : e) ++uses[std::size_t(f)];
  std::vector<CandidateHalfedge> next_side;  // per candidate: its halfedge for its next fan
  for (std::size_t f = 0; f < plane.size(); ++f) {
    std::vector<CandidateMesh::Vertex_index> loop;
    for (std::size_t k = 0; k < std::max<std::size_t>(3, uses[f]); ++k) {
      const Vec3 x(double(k), double(f), 0.0);
      point[loop.emplace_back(cs.mesh.add_vertex({x.x(), x.y(), x.z()}))] = int(cs.vertices.size());
      cs.vertices.push_back(x);
    }
    const auto face = cs.mesh.add_face(loop);
    support[face] = plane[f];
    areas[face] = area[f];
    next_side.push_back(cs.mesh.halfedge(face));
  }
  for (const auto& e : edges) {
    CandidateEdge ce;
    for (int f : e) {
      ce.push_back(next_side[std::size_t(f)]);
      next_side[std::size_t(f)] = cs.mesh.next(next_side[std::size_t(f)]);
    }
    cs.edges.push_back(ce);
  }
  return cs;
}

inline bool inside_box(const Vec3& p, double a, double b, double c) {
  return p.x() > -1e-9 && p.x() < a + 1e-9 && p.y() > -1e-9 && p.y() < b + 1e-9 && p.z() > -1e-9 && p.z() < c + 1e-9;
}

}  // namespace lodrefine::fixtures
