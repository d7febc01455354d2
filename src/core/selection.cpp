// Stage 4b: the binary program, driven through GLPK's C API (CGAL's traits only turn presolve
// on; PolyFit-shaped programs need cuts: measured 13 min -> 0.2 s with MIR cuts).
#include "lodrefine/core/selection.h"

#include <glpk.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace lodrefine {
namespace {

// GLPK returns binary columns as 0 or 1 up to its integrality tolerance: above this is chosen.
constexpr double kChosen = 0.5;
// glp_iocp::tm_lim is an int of milliseconds: longer limits are cut to this (~23 days).
constexpr double kMaxTimeLimitMs = 2.0e9;

SolveStatus classify(int ret, int status) {
  if (status == GLP_OPT) return SolveStatus::Optimal;
  if (status == GLP_FEAS) return ret == GLP_ETMLIM ? SolveStatus::FeasibleTimeLimit : SolveStatus::Feasible;
  if (status == GLP_NOFEAS || ret == GLP_ENOPFS) return SolveStatus::Infeasible;
  if (ret == GLP_ETMLIM) return SolveStatus::TimeLimitNoSolution;
  if (ret == GLP_ENODFS) return SolveStatus::NoDualFeasible;
  return SolveStatus::SolverFailure;
}

}  // namespace

std::string status_name(SolveStatus status, int glpk_code) {
  switch (status) {
    case SolveStatus::NotRun: return "not run";
    case SolveStatus::NoCandidates: return "no candidates";
    case SolveStatus::Optimal: return "optimal";
    case SolveStatus::Feasible: return "feasible";
    case SolveStatus::FeasibleTimeLimit: return "feasible (time limit)";
    case SolveStatus::Infeasible: return "infeasible";
    case SolveStatus::TimeLimitNoSolution: return "time limit (no solution)";
    case SolveStatus::NoDualFeasible: return "no dual feasible solution";
    case SolveStatus::SolverFailure: break;
  }
  return "solver failure (glp_intopt " + std::to_string(glpk_code) + ")";
}

SelectionResult select_faces(const CandidateSet& cs, const std::vector<double>& cost, const std::vector<int>& outside,
                             const Params& prm, const std::vector<int>* fixed) {
  const auto t0 = std::chrono::steady_clock::now();
  SelectionResult res;
  const int nf = int(cs.faces.size()), ne = int(cs.edges.size());
  res.selected.assign(nf, 0);
  if (nf == 0) {  // GLPK aborts on empty column sets
    res.status = SolveStatus::NoCandidates;
    return res;
  }

  glp_term_out(GLP_OFF);
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);

  // Columns: x_f (faces), y_e (edge used), s_e (sharp edge, only where non-coplanar faces meet).
  double total_area = 0.0;
  for (const auto& f : cs.faces) total_area += f.area;
  const double sharp_cost = ne > 0 ? prm.lambda_complexity * total_area / ne : 0.0;
  glp_add_cols(lp, nf + ne);
  for (int f = 0; f < nf; ++f) {
    glp_set_col_kind(lp, f + 1, GLP_BV);
    glp_set_obj_coef(lp, f + 1, prm.lambda_coverage * cost[f]);
    if (fixed != nullptr && (*fixed)[f] >= 0) {
      glp_set_col_bnds(lp, f + 1, GLP_FX, (*fixed)[f], (*fixed)[f]);
      ++res.fixed;
    }
  }
  for (int e = 0; e < ne; ++e) glp_set_col_kind(lp, nf + e + 1, GLP_BV);

  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  auto add_row = [&](std::vector<std::pair<int, double>> terms, int type, double lo, double hi) {
    const int r = glp_add_rows(lp, 1);
    glp_set_row_bnds(lp, r, type, lo, hi);
    // GLPK aborts the process on a repeated column in a row (a face listed twice on an edge
    // of a degenerate candidate): sum such coefficients.
    std::sort(terms.begin(), terms.end());
    for (std::size_t i = 1; i < terms.size(); ++i)
      if (terms[i].first == terms[i - 1].first) {
        terms[i].second += terms[i - 1].second;
        terms[i - 1].second = 0.0;
      }
    for (const auto& [col, val] : terms) {
      if (val == 0.0) continue;
      ia.push_back(r);
      ja.push_back(col);
      ar.push_back(val);
    }
  };
  for (int e = 0; e < ne; ++e) {
    const auto& edge = cs.edges[e];
    const int y = nf + e + 1;
    std::vector<std::pair<int, double>> terms;
    for (int f : edge.faces) terms.emplace_back(f + 1, 1.0);
    terms.emplace_back(y, -2.0);
    add_row(terms, GLP_FX, -outside[e], -outside[e]);  // sum x + outside = 2 y
    if (sharp_cost <= 0) continue;
    int s = 0;
    for (std::size_t i = 0; i < edge.faces.size(); ++i)
      for (std::size_t j = i + 1; j < edge.faces.size(); ++j) {
        const int fi = edge.faces[i], fj = edge.faces[j];
        if (cs.faces[fi].plane == cs.faces[fj].plane) continue;
        if (s == 0) {
          s = glp_add_cols(lp, 1);
          glp_set_col_kind(lp, s, GLP_BV);
          glp_set_obj_coef(lp, s, sharp_cost);
        }
        add_row({{s, 1.0}, {fi + 1, -1.0}, {fj + 1, -1.0}}, GLP_LO, -1.0, 0.0);  // s >= xi + xj - 1
      }
  }
  glp_load_matrix(lp, int(ia.size()) - 1, ia.data(), ja.data(), ar.data());
  res.variables = glp_get_num_cols(lp);
  res.constraints = glp_get_num_rows(lp);
  res.nonzeros = int(ia.size()) - 1;

  glp_iocp parm;
  glp_init_iocp(&parm);
  parm.presolve = GLP_ON;
  parm.mir_cuts = GLP_ON;
  parm.gmi_cuts = GLP_ON;
  parm.cov_cuts = GLP_ON;
  parm.clq_cuts = GLP_ON;
  parm.mip_gap = prm.mip_gap;
  parm.tm_lim = int(std::min(kMaxTimeLimitMs, std::ceil(prm.mip_time_limit * 1000.0)));
  parm.msg_lev = GLP_MSG_OFF;
  const int ret = glp_intopt(lp, &parm);
  const int status = glp_mip_status(lp);
  res.status = classify(ret, status);
  res.glpk_code = ret;
  // A zero return code alone is not success: only a primal feasible MIP point counts.
  res.ok = status == GLP_OPT || status == GLP_FEAS;
  if (res.ok) {
    res.objective = glp_mip_obj_val(lp);
    for (int f = 0; f < nf; ++f) res.selected[f] = glp_mip_col_val(lp, f + 1) > kChosen;
  }
  glp_delete_prob(lp);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace lodrefine
