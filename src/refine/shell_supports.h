// The supporting planes of a building's arrangement (stage 5, selection: shell_selection.h): the starting
// shell's planes, the scan's facades none of them carries, and the hypothesised walls across the
// steps of a facade line; and the region the arrangement covers. Internal to core: the
// selection's and the rebuild's (which adds its holes' planes: hole_planes.h).
#pragma once
#include <cmath>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/refine/candidates.h"

namespace lodrefine::detail {

// The supporting planes: the starting shell's, then the scan's facades that none of them carries.
struct Supports {
  std::vector<SupportPlane> planes;
  int start_planes = 0;
  std::vector<int> face_plane;            // start face -> supporting plane
  std::vector<std::vector<Vec3>> points;  // per supporting plane: its scan points
  int added = 0;
  int hole_planes = 0;  // planes no face of the start lies on (add_hole_planes)
};

// A plane whose normal is within `max_tilt_deg` of horizontal (PlaneConfig::facade_max_tilt_deg)
// is a wall's: the contradiction and the represented-facade tests apply to walls only.
inline bool near_vertical(const Plane& pl, double max_tilt_deg) {
  return std::abs(pl.n.z()) < std::sin(radians(max_tilt_deg));
}

// The start's planes, one per set of its surfaces within kSurfaceAngleDeg / kSurfaceDistance
// (matching.h), largest first; a surface on none of them goes to the one nearest in angle of
// those its vertices all lie within `planarity_tolerance` (m) of (a sliver).
// A plane's provenance: the scan's when a start face on it is (a moved wall), added when only
// added faces lie on it, else the model's.
void add_start_planes(const Mesh& start, double planarity_tolerance, Supports& s);
// The scan's facade planes near the footprint (within match_distance + bbox_margin, and along the
// facade no farther past the start's ends than the facade's own corner: a facade line running on
// into a neighbour's is the neighbour's there), each on the supporting plane it lies on, else a
// new one; ransac_min_points such points at least.
void add_scan_planes(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& scan,
                     const RefineConfig& prm, Supports& s);
// Hypothesised walls across where a scanned facade's points end inside the footprint.
void add_step_walls(const Mesh& start, const RefineConfig& prm, Supports& s);
// Where the scan-only facades that step from another scanned facade ask for a change: each point
// swept along the normal of the nearest parallel start wall it stands before onto that wall (the
// step, bay or recess between them), sampled every `step` m.
std::vector<Vec3> step_volume_samples(const Mesh& start, const Supports& s, const RefineConfig& prm, double step);
// The region: the start and the scan evidence, in the axes of the start's largest wall (near_vertical
// within `max_tilt_deg`), grown by a margin.
Region building_region(const Mesh& start, const Supports& s, double max_tilt_deg);
// Per supporting plane, the box (region's axes) its candidates need: its start faces and its
// scan points, grown by `margin` (the farthest a wall may move); a plane with neither (a
// hypothesised wall) those of the start and the evidence within `margin` of it. A scanned wall
// spans the region's height (a street scan sees its lower storeys only).
std::vector<Region> plane_reach(const Mesh& start, const Supports& s, const Region& region, double margin);

}  // namespace lodrefine::detail
