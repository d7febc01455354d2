// Internal to core: a selection of candidates that leaves edges used once or thrice mended into
// the nearest closed one (every edge used 0 or 2 times), by a small program of its own
// (objective.h: mend_cost). The selection's first incumbent (shell_selection), a rebuild's shell
// (shell_rebuild).
#pragma once
#include <vector>

#include "lodrefine/core/params.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/selection.h"

namespace lodrefine::detail {

// A boolean face map of `cs` as 0/1 per candidate (a selection).
std::vector<char> face_flags(const CandidateSet& cs, const CandidateMap<bool>& map);

// What nearest_closed_selection may change and at which cost.
struct MendScope {
  bool whole_last = false;   // at last, every candidate free
  double keep_weight = 1.0;  // a start candidate dropped costs this times its area, one added its area
};
// The nearest selection to `in_start` (0/1 per candidate) that closes (every edge used 0 or 2
// times) and makes none of `excluded` (SelectionProgram::excluded): `in_start` itself when it
// closes and nothing is excluded, else a program over the candidates within 2 edge-rings of the
// edges it uses once or thrice (and of `excluded`), the others fixed, costs mend_cost (the least
// changed area; `scope.keep_weight`); 2 rings more while it has no solution, 3 tries; with
// `scope.whole_last` a 4th with every candidate free. Solved with `prm`'s limits. Empty when
// none is found.
std::vector<char> nearest_closed_selection(CandidateSet& cs, const std::vector<char>& in_start,
                                           const SelectionConfig& prm, const MendScope& scope = {},
                                           const std::vector<LocalSelection>& excluded = {});

}  // namespace lodrefine::detail
