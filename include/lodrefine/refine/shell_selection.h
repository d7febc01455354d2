// Stage 5, selection (candidates, data term, program, traced shell) for the whole building
// (paper Sec. 3.2-3.4): one PolyFit-style candidate arrangement over the building and the scan
// around it, and the GLPK binary selection that decides every face of the output.
//
// Supporting planes: the planes of the starting shell (the substituted or coarse model: roofs,
// ground, unscanned walls, walls already moved onto their scan planes) and every facade plane
// the scan shows in front of or behind the building's footprint that no wall of the shell lies
// on (a recess's back wall and returns, a bay's front and sides, a second facade line). Every
// plane's section of the region is split by every other plane.
//
// Data term per candidate (confidence c in 0..1, the paper's sigmoid coverage cost):
// - on a scanned plane, the share of its area the plane's points cover (an occupancy grid);
// - where the starting shell has a face, 1 (the model's prior: unscanned parts stay), less the
//   share of its area behind or before which the scan shows another parallel facade (the scan
//   saw the facade elsewhere there).
// Complexity: a cost per length of sharp edge (objective.h builds every cost). Constraint:
// every candidate edge is used by 0 or 2 selected faces. Candidates that no scan evidence
// reaches are fixed to the starting shell. The starting shell, as a selection of candidates, is
// GLPK's first incumbent (warm start), or the starting shell with its outdated walls on their
// scan planes (`outdated` below).
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/move_plan.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/substitute.h"
#include "lodrefine/refine/selection.h"

namespace lodrefine {

struct ShellSelectionStats {
  int supporting_planes = 0;        // of the starting shell plus the scan's
  int scan_planes_added = 0;        // facade planes on which no wall of the starting shell lies
  int step_walls = 0;               // hypothesised walls across where a facade's points end (no points)
  int candidates = 0, edges = 0;    // after pruning
  int candidates_pruned = 0;        // fixed out by the starting shell and no evidence: not in the program
  SelectionResult selection;        // status, variables, constraints, gap, seconds, warm start
  int faces_from_selection = 0;     // output faces (each assembled from selected candidates)
  int candidates_changed = 0;       // selected differently from the starting shell
  int neighbourhoods_improved = 0;  // scanned planes' neighbourhoods that improved the warm start
  std::vector<Vec3> evidence;       // the scan points the selection used (its planes', near the footprint)
  double seconds = 0.0;
};

struct ShellSelection {
  bool ok = false;
  std::string reason;  // why not, when !ok
  Mesh mesh;           // closed, 2-manifold, outward, merged coplanar faces; semantics per face
  ShellSelectionStats stats;
};

// Selects the building's faces. `start`: a valid closed shell (local frame); `cloud`: the local
// cloud `planes` were detected in. Faces on the start's planes keep its semantic and source;
// faces on added scan planes are WallSurface (source -1). A selection whose shell does not
// validate is excluded and the program solved again (its changes fixed back, twice at most), as
// is a connected piece of changes leaving ransac_min_points or more of the supporting planes'
// points over 0.5 m inside the shell but not inside `start` (solid where the scan saw through);
// when the program chose the starting shell unchanged but its pieces do not validate, the result
// is `start` itself (ok, with that said in `reason`). A start face whose vertices all lie within
// planarity_tolerance of a larger face's plane, though its own normal is off (a sliver), is a
// piece of that plane. Never throws for geometry; !ok with the reason when the program has no
// solution or no valid shell.
// `outdated` (move_plan.h; its `surfaces` and `scan` only): walls of `start` the scan puts on
// another plane that `start` still has where the model put them (no substitution moved them).
// Its `surfaces` are model_surfaces(start) at their default tolerances, as the matching made them
// (each WallMove::surface indexes them), each WallMove::plane the wall's scan plane. GLPK's first
// incumbent then has each such wall on the supporting plane carrying its scan plane (the wall's
// outline, seen along its normal), the rest closed by the nearest closed selection; `start` stays
// what no evidence reaches is fixed to, what changes are counted from and what a refused change
// goes back to. A wall whose scan plane carries no supporting plane, or a warm start that cannot
// be closed or changes a fixed candidate, leaves the incumbent `start`. Empty (the default):
// `start` is the incumbent.
ShellSelection select_shell(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                            const RefineConfig& params, const MovePlan& outdated = MovePlan{});

}  // namespace lodrefine
