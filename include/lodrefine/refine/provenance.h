// Where each face of a refined or repaired building comes from (Face::provenance: the model's
// plane, the scan's, or added to close the shell; base/types.h) and, for the scan's, how much of
// it the scan covers (Face::coverage). The provenance is carried by the stages themselves (a
// substitution's moved walls, the selection's supporting planes, shell_trace.h); this module
// measures the coverage and fills what no stage set.
#pragma once
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"

namespace lodrefine {

// Sets Face::coverage of every Provenance::Scan face of `mesh` (0..1): the share of its area
// whose 0.25 m cells hold a point of the scan on its plane, each point covering the cells within
// 0.5 m around it (windows and scan-line gaps are scanned wall, as in the selection's coverage
// term). The points: the inliers of `planes` (indices into `cloud`) within selection.merge_angle_deg
// of the face's plane, those within plane.ransac_epsilon + selection.merge_distance (m) of it.
// `mesh`, `cloud` and the planes in one frame. A face no point reaches gets 0 (a corner move).
void measure_coverage(Mesh& mesh, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                      const RefineConfig& prm);

// Every face of `mesh` without a provenance (Provenance::None: as read, no stage touched it)
// becomes the model's; the output of a refined or repaired building says where each face comes
// from.
void complete_provenance(Mesh& mesh);

}  // namespace lodrefine
