// Repair by reconstruction: a model that no weld and orientation make a valid solid is
// closed on its own planes by the same candidate arrangement and selection as a refinement
// (shell_selection.h), its faces the evidence.
#pragma once
#include <string>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

// Repair by reconstruction: the closed shell a polygon soup that is no valid solid (faces crossing,
// missing or doubled, parts touching along an edge) stands for, from the same arrangement and
// selection on the soup's own planes plus those its holes need (a missing party wall: the
// vertical plane through the hole's edge). A candidate is covered when a
// soup face on its plane holds its centroid; the selection is the closed one nearest the cover
// (each change costing its area), searched around the edges the cover leaves open or overused,
// then over every candidate. Output vertices within 3 cm of a soup vertex are put on it. The
// distances both ways are measured on samples every 0.25 m (and near each vertex), wider for a
// soup that would take more than 250,000; time and memory are bounded for any soup within
// size_problem's bounds (validate.h).
struct ShellRebuild {
  bool ok = false;
  std::string reason;    // why not, when !ok
  Mesh mesh;             // closed, 2-manifold, outward; faces on the soup's planes keep semantic and source
  int planes_added = 0;  // planes no soup face lies on (add_hole_planes)
  // m²: the output's area on the soup (within weld_tolerance) and beside it (added: a missing wall,
  // a wall run on to the ground), both from samples.
  double area_kept = 0.0, area_added = 0.0;
  int candidates_changed = 0;  // candidates chosen other than the cover says
  // m: the farthest the soup's faces lie from the output, but for the partitions between parts it
  // joins (inside it, the soup's other faces winding more than 3/4 around them: Jacobson et al.
  // 2013), whose area is area_dropped.
  double input_to_output = 0.0;
  double area_dropped = 0.0;     // m²
  double area_uncovered = 0.0;   // m²: of the soup farther than weld_tolerance from the output (not dropped)
  double sampling = 0.0;         // m: the spacing of the samples these areas and distances come from
  double area_fins = 0.0;        // m²: of that, with outside on both sides (winding below 1/4): a fin
  double output_to_input = 0.0;  // m: the farthest the output lies from the soup (an added wall's middle)
  double corner_to_input = 0.0;  // m: the farthest an output vertex lies from the soup (an invented corner)
  // The soup's fins: pieces of its faces with its outside on both sides, outside `mesh` (no
  // solid holds them), as read and oriented like their faces, to be written beside the shell;
  // area_carried (m²) is the soup's area on them. The output is `mesh` and `fins` together.
  Mesh fins;
  double area_carried = 0.0;
};

// `soup`: the welded faces (welded_soup, repair.h), local frame; Face::source says which input
// face each is. Not ok when its planes bound no valid shell, when it has no ground face (the
// walls' foot would be invented: a roof alone is no building), or when its arrangement would
// exceed 10,000 candidates. Never throws for geometry.
ShellRebuild rebuild_shell(const Mesh& soup, const RefineConfig& params);

}  // namespace lodrefine
