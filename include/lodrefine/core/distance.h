// Point-to-surface distances of a mesh (CGAL AABB tree on its triangulated faces): the
// never-worse check of the pipeline and every C2M figure of the evaluation use this one measure.
#pragma once
#include <memory>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// The triangulated faces of a mesh, indexed for nearest-point queries. Works in any frame
// (shifts to the mesh's first vertex internally, so georeferenced inputs keep their precision).
// Throws InputError when the mesh has no non-degenerate face.
class MeshDistance {
 public:
  explicit MeshDistance(const Mesh& mesh);
  ~MeshDistance();
  MeshDistance(const MeshDistance&) = delete;
  MeshDistance& operator=(const MeshDistance&) = delete;

  struct Nearest {
    double distance;  // signed when asked for (positive on the outward side), else >= 0
    int face;         // the face of the nearest point
  };
  // When the nearest point lies on an edge or vertex, the sign comes from the angle-weighted
  // pseudonormal of all triangles touching it (found geometrically, so it also works on polygon
  // soups with T-junctions). Where several faces are nearest (within 1e-7 m: an edge, a vertex),
  // the face is the one whose plane lies nearest the point (the ground for a street point beyond
  // a wall's foot; a wall for a point of its plane beyond its end), then the lowest triangle's.
  Nearest nearest(const Vec3& point, bool signed_distance) const;
  // nearest()'s distance alone (faster: no search for tied faces).
  double distance(const Vec3& point, bool signed_distance) const;
  // Unsigned, for many points close together (a scan near the mesh), faster than one nearest()
  // each, with the same answers bit for bit, the face included.
  std::vector<Nearest> nearest_all(const std::vector<Vec3>& points) const;

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

// Signed distance from each point to the nearest point of the mesh surface.
std::vector<double> cloud_to_mesh(const Mesh& mesh, const std::vector<Vec3>& points);
// The same, unsigned.
std::vector<double> unsigned_distances(const Mesh& mesh, const std::vector<Vec3>& points);

// Root mean square of the unsigned distances (0 without points).
double rms_distance(const Mesh& mesh, const std::vector<Vec3>& points);

// Deterministic samples every `spacing` metres on the given faces: a grid in each face's plane
// (cell centres inside the polygon), or the face centroid if no cell centre falls inside.
std::vector<Vec3> sample_faces(const Mesh& mesh, const std::vector<int>& faces, double spacing);

}  // namespace lodrefine
