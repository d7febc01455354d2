// Stage 4b: face selection as a binary program in GLPK (paper Sec. 3.4): sigmoid coverage
// cost, PolyFit complexity (sharp edges), and per edge "selected incident faces = 2 x used",
// with the region's outside surface as a constant incident face on boundary edges.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

// What GLPK made of the program (glp_intopt's return code with glp_mip_status).
enum class SolveStatus {
  NotRun,               // nothing solved yet
  NoCandidates,         // an empty program (GLPK aborts on one; never handed to it)
  Optimal,
  Feasible,             // stopped at the gap
  FeasibleTimeLimit,    // a selection, not proven optimal
  Infeasible,
  TimeLimitNoSolution,
  NoDualFeasible,
  SolverFailure,        // any other glp_intopt return code (SelectionResult::glpk_code)
};
// "optimal", "feasible (time limit)", "infeasible", "time limit (no solution)", ...
std::string status_name(SolveStatus status, int glpk_code = 0);

struct SelectionResult {
  bool ok = false;             // a feasible selection satisfying every edge constraint
  std::vector<char> selected;  // per candidate
  SolveStatus status = SolveStatus::NotRun;
  int glpk_code = 0;           // glp_intopt's return code
  std::string status_text() const { return status_name(status, glpk_code); }
  int variables = 0, constraints = 0, nonzeros = 0;
  int fixed = 0;               // candidates fixed before solving
  double objective = 0.0;
  double seconds = 0.0;
};

// `cost[f]`: coverage cost of candidate f (weighted here by lambda_coverage); `outside[e]`: 1
// where the kept surface outside the region continues across edge e (counts as a selected
// face), else 0; `fixed[f]`: -1 free, 0 or 1 to fix candidate f (presolve then removes it).
SelectionResult select_faces(const CandidateSet& cs, const std::vector<double>& cost, const std::vector<int>& outside,
                             const Params& params, const std::vector<int>* fixed = nullptr);

}  // namespace lodrefine
