// Not in the pipeline (kept for its tests; stage 4 over one wall): one outdated wall replaced
// through the paper's method. A region around the
// old and the new wall; the scan plane and every kept surface reaching into it as supporting
// planes; their PolyFit-style candidate faces, scored by confidence and coverage; GLPK selects
// the faces that close the shell with the kept model outside the region.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/core/geometry.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/selection.h"
#include "lodrefine/core/types.h"

namespace lodrefine {

struct WallReplacement {
  std::vector<int> surfaces;  // model surfaces replaced by the scan plane
  Plane plane;                // the scan plane, oriented like the wall (outward)
  std::vector<Vec3> points;   // its inliers
};

// What the arrangement built, as far as it got (for the report).
struct ArrangementStats {
  std::optional<int> supporting_planes, candidates, edges;
  std::optional<SelectionResult> selection;  // the program's figures (`selected` cleared)
  bool fixing_dropped = false;  // the fixed candidates contradicted each other: solved free
  std::optional<int> selected;  // candidate faces taken into the shell
  std::optional<double> seconds;  // on success
};

struct ArrangementResult {
  bool ok = false;
  std::string reason;  // why not, when !ok
  Mesh mesh;           // the closed shell with the wall replaced
  ArrangementStats stats;
};

// Replaces `rep.surfaces` (indices into `surfaces` = model_surfaces(mesh)) by `rep.plane`. The
// model is first snapped onto its own planes (the arrangement needs it to agree with them
// exactly); a result that changes the roof away from the moved wall is refused.
ArrangementResult arrange_wall(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                               const WallReplacement& rep, const Params& params);

}  // namespace lodrefine
