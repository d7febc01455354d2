// Coverage of a refined building's scan faces: see provenance.h.
#include "lodrefine/refine/provenance.h"

#include <algorithm>

#include "lodrefine/base/geometry.h"
#include "occupancy.h"

namespace lodrefine {

void measure_coverage(Mesh& mesh, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                      const RefineConfig& prm) {
  const double tolerance = prm.plane.ransac_epsilon + prm.selection.merge_distance;
  for (Face& f : mesh.faces) {
    if (f.provenance != Provenance::Scan) continue;
    const std::vector<Vec3> poly = face_points(mesh, f);
    f.coverage = 0.0;
    if (poly.size() < 3) continue;
    const Plane plane = polygon_plane(poly);
    std::vector<Vec3> on;
    for (const ScanPlane& sp : planes) {
      if (unoriented_angle_deg(sp.plane.n, plane.n) > prm.selection.merge_angle_deg) continue;
      for (int i : sp.inliers)
        if (i >= 0 && std::size_t(i) < cloud.points.size() &&
            std::abs(plane.distance(cloud.points[std::size_t(i)])) <= tolerance)
          on.push_back(cloud.points[std::size_t(i)]);
    }
    if (on.empty()) continue;
    const detail::Frame2 frame = detail::frame_of(plane, polygon_centroid(poly));
    detail::CellSet cells;
    detail::mark_scanned(cells, on, frame);
    std::vector<Vec2> flat;
    for (const Vec3& p : poly) flat.push_back(frame(p));
    f.coverage = std::clamp(detail::scanned_share(flat, cells), 0.0, 1.0);
  }
}

void complete_provenance(Mesh& mesh) {
  for (Face& f : mesh.faces)
    if (f.provenance == Provenance::None) f.provenance = Provenance::Model;
}

}  // namespace lodrefine
