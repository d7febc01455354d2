// Internal to core: what planes.cpp (the shape detection, the only translation unit with CGAL's
// shape detection) and wall_layers.cpp (walls seen twice, relief) share.
#pragma once
#include <vector>

#include "lodrefine/core/planes.h"

namespace lodrefine::detail {

// The scan plane fitted to `inliers` of `all`: least squares (vertical when within
// vertical_snap_deg), facade when within facade_max_tilt_deg of vertical, its rms and hull area.
ScanPlane describe_plane(const std::vector<Vec3>& all, std::vector<int> inliers, const PlaneConfig& prm);

// Each facade, largest first, that two drives saw apart becomes one plane midway between its
// copies (ScanPlane::doubled), holding both; the other planes lose the points it takes.
std::vector<ScanPlane> join_doubled_walls(std::vector<ScanPlane> planes, const std::vector<Vec3>& all,
                                          const PlaneConfig& prm);

}  // namespace lodrefine::detail
