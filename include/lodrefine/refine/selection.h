// Stage 5, selection: face selection as a binary program in GLPK (paper Sec. 3.4): the solver driver.
// The costs come built (objective.h); here the columns, per edge "selected incident faces = 2 x
// used" (the region's outside surface a constant incident face on boundary edges), the sharp
// edges' rows, the warm start, the search and its status.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/core/params.h"

namespace lodrefine {

struct CandidateSet;  // candidates.h (its Surface_mesh stays out of the headers that report)

// What GLPK made of the program (glp_intopt's return code with glp_mip_status).
enum class SolveStatus {
  NotRun,        // nothing solved yet
  NoCandidates,  // an empty program (GLPK aborts on one; never handed to it)
  Optimal,
  Feasible,           // stopped at the gap
  FeasibleBudget,     // a selection, not proven optimal: the work budget (mip_work_limit) was spent
  FeasibleTimeLimit,  // the same at the wall-clock ceiling (mip_time_limit; load-dependent)
  Infeasible,
  BudgetNoSolution,
  TimeLimitNoSolution,
  NoDualFeasible,
  SolverFailure,  // any other glp_intopt return code (SelectionResult::glpk_code)
};
// "optimal", "feasible (budget)", "feasible (time limit)", "infeasible", "budget (no solution)",
// "time limit (no solution)", ...
std::string status_name(SolveStatus status, int glpk_code = 0);

// The program's figures (its variables and answer are face maps of the candidate mesh: see
// select_faces).
struct SelectionResult {
  bool ok = false;  // a feasible selection satisfying every edge constraint
  SolveStatus status = SolveStatus::NotRun;
  int glpk_code = 0;  // glp_intopt's return code
  std::string status_text() const { return status_name(status, glpk_code); }
  int variables = 0, constraints = 0, nonzeros = 0;
  int fixed = 0;           // candidates fixed before solving (constants, not columns)
  int forced = 0;          // of those, free in the program but decided by its edge constraints
  double objective = 0.0;  // of the free columns (fixed faces' costs are constants)
  double gap = 0.0;        // relative MIP gap when the search ended (0: proven optimal)
  double work = 0.0;       // the search's work, millions of tableau entries (see mip_work_limit)
  double seconds = 0.0;
  // The starting selection (SelectionProgram::warm): handed to GLPK's heuristic callback, and
  // whether GLPK accepted it as an incumbent (not needed: the search ended before asking).
  bool warm_given = false, warm_feasible = false, warm_asked = false, warm_accepted = false;
  std::string warm_text() const;  // "none", "infeasible", "accepted", "rejected", "not needed"
};

// A selection program over `CandidateSet` (the paper's Sec. 3.4):
// - `cost[f]`: candidate f's objective coefficient, as built (objective.h: candidate_cost,
//   mend_cost), taken unweighted;
// - `outside[e]`: 1 where a kept surface outside the region continues across edge e (counts as a
//   selected face), else 0; empty: none;
// - `fixed[f]`: -1 free, 0 or 1 fixed (folded into the edge constraints as constants); empty:
//   all free;
// - `sharp_cost[e]`: cost of edge e when it is sharp (two selected faces of different planes
//   meet there), as built (objective.h: sharp_edge_cost); empty: uniform_sharp_cost on every
//   edge;
// - `warm[f]`: a starting selection (0/1 per candidate); empty: none. It must agree with
//   `fixed`; if it satisfies every edge constraint it is given to GLPK as the first incumbent
//   (presolve is then off: the callback works on the original columns);
// - `excluded`: local selections never made (a pinch the edge constraints allow: pieces meeting
//   only at a point, or four at one edge): for each, not all of `selected` chosen while none of
//   `unselected` is.
// Faces the edge constraints decide from the fixed ones (an edge with one free face, or two
// fixed selected faces) are fixed too before GLPK sees the program (SelectionResult::forced).
// Some candidates' values: those of `selected` chosen, those of `unselected` not.
struct LocalSelection {
  std::vector<int> selected, unselected;
};
struct SelectionProgram {
  std::vector<double> cost;
  std::vector<int> outside;
  std::vector<int> fixed;
  std::vector<double> sharp_cost;
  std::vector<char> warm;
  std::vector<LocalSelection> excluded;
};
// `config` gives the search's limits (mip_gap, mip_work_limit, mip_time_limit) and, for an empty
// sharp_cost only, lambda_complexity; no other weight is applied here.
// The search ends at config.mip_work_limit (a count of GLPK's work, so the result does not depend
// on the machine's load) or, as a last-resort safety ceiling far above it, at `time_limit`
// (wall-clock s, > 0), explicit so that a caller that solved before passes what is left of
// mip_time_limit. Either way the best selection found, at least a feasible warm start, is taken.
// Writes the program's variables and its answer as face maps of `cs.mesh` (replacing those of an
// earlier solve): candidate_props::variable (int: the candidate's GLPK column, 1-based; 0 when
// fixed) and candidate_props::selected (bool: chosen; all false when the result is not ok).
SelectionResult select_faces(CandidateSet& cs, const SelectionProgram& program, const SelectionConfig& config,
                             double time_limit);
// The same with the whole budget, config.mip_time_limit.
SelectionResult select_faces(CandidateSet& cs, const SelectionProgram& program, const SelectionConfig& config);

// Whether every edge of `cs` is used by 0 or 2 of the `selected` candidates (plus `outside[e]`;
// empty: none): the program's constraint, for checking a starting point or a result.
bool every_edge_used_0_or_2(const CandidateSet& cs, const std::vector<char>& selected,
                            const std::vector<int>& outside = {});

// The same with `cost`, `outside` and optionally `fixed` (see SelectionProgram; no sharp_cost:
// uniform_sharp_cost).
SelectionResult select_faces(CandidateSet& cs, const std::vector<double>& cost, const std::vector<int>& outside,
                             const SelectionConfig& config, const std::vector<int>* fixed = nullptr);

// The face map candidate_props::selected of `cs.mesh` as 0/1 per candidate (all 0 without it).
std::vector<char> selected_faces(const CandidateSet& cs);

}  // namespace lodrefine
