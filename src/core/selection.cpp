// Stage 4b: the binary program, driven through GLPK's C API (CGAL's traits only turn presolve
// on; PolyFit-shaped programs need cuts: measured 13 min -> 0.2 s with MIR cuts).
#include "lodrefine/core/selection.h"

#include <glpk.h>

#include "lodrefine/core/candidates.h"

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

std::string SelectionResult::warm_text() const {
  if (!warm_given) return "none";
  if (!warm_feasible) return "infeasible";
  if (warm_accepted) return "accepted";
  return warm_asked ? "rejected" : "not needed";
}

namespace {

// The heuristic callback's state: the starting point (GLPK's 1-based column values) and what
// GLPK made of it; the last relative gap seen.
struct Search {
  std::vector<double> start;  // empty: no warm start
  bool asked = false, accepted = false;
  double gap = 0.0;
};

void on_search(glp_tree* tree, void* info) {
  auto& s = *static_cast<Search*>(info);
  switch (glp_ios_reason(tree)) {
    case GLP_IHEUR:
      if (!s.asked && !s.start.empty()) {
        s.asked = true;
        s.accepted = glp_ios_heur_sol(tree, s.start.data()) == 0;
      }
      break;
    case GLP_IBINGO:
    case GLP_ISELECT: s.gap = glp_ios_mip_gap(tree); break;
    default: break;
  }
}

// Sums repeated columns of a row (GLPK aborts the process on a repeated column: a face listed
// twice on an edge of a degenerate candidate) and drops zero coefficients.
std::vector<std::pair<int, double>> combined(std::vector<std::pair<int, double>> terms) {
  std::sort(terms.begin(), terms.end());
  std::vector<std::pair<int, double>> out;
  for (const auto& t : terms) {
    if (!out.empty() && out.back().first == t.first) out.back().second += t.second;
    else out.push_back(t);
  }
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& t) { return t.second == 0.0; }), out.end());
  return out;
}

// The faces the edge constraints alone decide, given the fixed ones (a reduction GLPK's MIP
// presolver makes, but it is off when a warm start is given, and without it the search over the
// undecided faces is many times slower): an edge with fixed faces summing to c (its outside
// count included) and one free face forces that face to c (0 + x or 1 + x must be 0 or 2); with
// c = 2 every free face is 0. Repeated until nothing changes. Contradictions are left to the
// caller. `fixed` as SelectionProgram::fixed, never empty.
std::vector<int> forced_by_edges(const CandidateSet& cs, std::vector<int> fixed, const std::vector<int>& outside) {
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t e = 0; e < cs.edges.size(); ++e) {
      int constant = outside.empty() ? 0 : outside[e], free = 0;
      for (int f : cs.edges[e].faces) {
        if (fixed[f] < 0) ++free;
        else constant += fixed[f];
      }
      if (free == 0 || constant > 2) continue;
      if (constant == 2 || free == 1) {
        for (int f : cs.edges[e].faces)
          if (fixed[f] < 0) fixed[f] = constant == 2 ? 0 : constant;
        changed = true;
      }
    }
  }
  return fixed;
}

}  // namespace

bool every_edge_used_0_or_2(const CandidateSet& cs, const std::vector<char>& selected,
                            const std::vector<int>& outside) {
  for (std::size_t e = 0; e < cs.edges.size(); ++e) {
    int n = outside.empty() ? 0 : outside[e];
    for (int f : cs.edges[e].faces) n += selected[f];
    if (n != 0 && n != 2) return false;
  }
  return true;
}

SelectionResult select_faces(const CandidateSet& cs, const SelectionProgram& pg, const SelectionConfig& prm,
                             double time_limit) {
  const auto t0 = std::chrono::steady_clock::now();
  SelectionResult res;
  const int nf = int(cs.faces.size()), ne = int(cs.edges.size());
  res.selected.assign(nf, 0);
  const std::vector<int> fixed =
      forced_by_edges(cs, pg.fixed.empty() ? std::vector<int>(nf, -1) : pg.fixed, pg.outside);
  auto fixed_value = [&](int f) { return fixed[f]; };
  auto outside = [&](int e) { return pg.outside.empty() ? 0 : pg.outside[e]; };
  // Column of each free face (1-based), 0 for a fixed one.
  std::vector<int> col(nf, 0);
  int free_faces = 0;
  for (int f = 0; f < nf; ++f) {
    if (fixed_value(f) >= 0) ++res.fixed, res.selected[f] = char(fixed_value(f));
    else col[f] = ++free_faces;
  }
  res.column = col;
  for (int f = 0; f < nf; ++f) res.forced += fixed[f] >= 0 && (pg.fixed.empty() || pg.fixed[f] < 0);
  auto done = [&](SolveStatus status) {
    res.status = status;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return res;
  };
  if (nf == 0) return done(SolveStatus::NoCandidates);  // GLPK aborts on empty column sets

  // The starting point, checked against every edge: GLPK takes a heuristic solution unchecked.
  res.warm_given = !pg.warm.empty();
  if (res.warm_given) {
    res.warm_feasible = every_edge_used_0_or_2(cs, pg.warm, pg.outside);
    for (int f = 0; f < nf; ++f)
      res.warm_feasible = res.warm_feasible && (fixed_value(f) < 0 || fixed_value(f) == pg.warm[f]);
  }

  double total_area = 0.0;
  for (const auto& f : cs.faces) total_area += f.area;
  const double uniform_sharp = ne > 0 ? prm.lambda_complexity * total_area / ne : 0.0;

  glp_term_out(GLP_OFF);
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);
  if (free_faces > 0) glp_add_cols(lp, free_faces);
  for (int f = 0; f < nf; ++f) {
    if (col[f] == 0) continue;
    glp_set_col_kind(lp, col[f], GLP_BV);
    glp_set_obj_coef(lp, col[f], prm.lambda_coverage * pg.cost[f]);
  }
  std::vector<double> start{0.0};  // 1-based like GLPK's columns
  for (int f = 0; f < nf; ++f)
    if (col[f] > 0) start.push_back(res.warm_given ? double(pg.warm[f]) : 0.0);
  auto new_binary = [&](double cost, double value) {
    const int c = glp_add_cols(lp, 1);
    glp_set_col_kind(lp, c, GLP_BV);
    glp_set_obj_coef(lp, c, cost);
    start.push_back(value);
    return c;
  };

  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  auto add_row = [&](const std::vector<std::pair<int, double>>& terms, int type, double lo, double hi) {
    const int r = glp_add_rows(lp, 1);
    glp_set_row_bnds(lp, r, type, lo, hi);
    for (const auto& [c, val] : combined(terms)) {
      ia.push_back(r);
      ja.push_back(c);
      ar.push_back(val);
    }
  };
  bool contradiction = false;  // fixed faces alone leave an edge with 1 or 3+ faces
  for (int e = 0; e < ne; ++e) {
    const auto& edge = cs.edges[e];
    // sum x_free + constant = 2 y
    std::vector<std::pair<int, double>> terms;
    int constant = outside(e), warm_count = outside(e);
    for (int f : edge.faces) {
      if (col[f] > 0) terms.emplace_back(col[f], 1.0);
      else constant += fixed_value(f);
      if (res.warm_given) warm_count += pg.warm[f];
    }
    if (terms.empty()) {
      contradiction = contradiction || (constant != 0 && constant != 2);
    } else {
      terms.emplace_back(new_binary(0.0, warm_count == 2 ? 1.0 : 0.0), -2.0);
      add_row(terms, GLP_FX, -constant, -constant);
    }
    const double sharp = pg.sharp_cost.empty() ? uniform_sharp : pg.sharp_cost[e];
    if (sharp <= 0) continue;
    int s = 0;  // s >= xi + xj - 1 for faces of different planes
    for (std::size_t i = 0; i < edge.faces.size(); ++i)
      for (std::size_t j = i + 1; j < edge.faces.size(); ++j) {
        const int fi = edge.faces[i], fj = edge.faces[j];
        if (cs.faces[fi].plane == cs.faces[fj].plane) continue;
        if (fixed_value(fi) == 0 || fixed_value(fj) == 0) continue;
        if (col[fi] == 0 && col[fj] == 0) continue;  // both fixed in: a constant
        if (s == 0) s = new_binary(sharp, res.warm_given && pg.warm[fi] && pg.warm[fj] ? 1.0 : 0.0);
        else if (res.warm_given && pg.warm[fi] && pg.warm[fj]) start[s] = 1.0;
        std::vector<std::pair<int, double>> t{{s, 1.0}};
        double rhs = -1.0;
        for (int g : {fi, fj}) {
          if (col[g] > 0) t.emplace_back(col[g], -1.0);
          else rhs += 1.0;  // fixed in
        }
        add_row(t, GLP_LO, rhs, 0.0);
      }
  }
  res.variables = glp_get_num_cols(lp);
  res.constraints = glp_get_num_rows(lp);
  res.nonzeros = int(ia.size()) - 1;
  if (contradiction) {
    glp_delete_prob(lp);
    return done(SolveStatus::Infeasible);
  }
  if (res.variables == 0) {  // everything fixed: the fixed selection is the answer
    glp_delete_prob(lp);
    res.ok = true;
    return done(SolveStatus::Optimal);
  }
  glp_load_matrix(lp, int(ia.size()) - 1, ia.data(), ja.data(), ar.data());

  Search search;
  if (res.warm_feasible) search.start = start;
  glp_iocp parm;
  glp_init_iocp(&parm);
  parm.mir_cuts = GLP_ON;
  parm.gmi_cuts = GLP_ON;
  parm.cov_cuts = GLP_ON;
  parm.clq_cuts = GLP_ON;
  parm.mip_gap = prm.mip_gap;
  parm.tm_lim = int(std::min(kMaxTimeLimitMs, std::ceil(time_limit * 1000.0)));
  parm.msg_lev = GLP_MSG_OFF;
  parm.cb_func = on_search;
  parm.cb_info = &search;
  int ret = 0;
  if (search.start.empty()) {
    parm.presolve = GLP_ON;
  } else {
    // The callback sees the original columns only without the MIP presolver, which then needs
    // an optimal basis of the LP relaxation.
    glp_smcp lpp;
    glp_init_smcp(&lpp);
    lpp.msg_lev = GLP_MSG_OFF;
    lpp.presolve = GLP_ON;
    lpp.tm_lim = parm.tm_lim;
    ret = glp_simplex(lp, &lpp);
    parm.presolve = GLP_OFF;
  }
  if (ret == 0) ret = glp_intopt(lp, &parm);
  const int status = glp_mip_status(lp);
  res.status = classify(ret, status);
  res.glpk_code = ret;
  res.warm_asked = search.asked;
  res.warm_accepted = search.accepted;
  res.gap = status == GLP_OPT ? 0.0 : search.gap;
  // A zero return code alone is not success: only a primal feasible MIP point counts.
  res.ok = status == GLP_OPT || status == GLP_FEAS;
  if (res.ok) {
    res.objective = glp_mip_obj_val(lp);
    for (int f = 0; f < nf; ++f)
      if (col[f] > 0) res.selected[f] = glp_mip_col_val(lp, col[f]) > kChosen;
  }
  glp_delete_prob(lp);
  return done(res.status);
}

SelectionResult select_faces(const CandidateSet& cs, const std::vector<double>& cost, const std::vector<int>& outside,
                             const SelectionConfig& prm, const std::vector<int>* fixed) {
  SelectionProgram pg;
  pg.cost = cost;
  pg.outside = outside;
  if (fixed != nullptr) pg.fixed = *fixed;
  return select_faces(cs, pg, prm);
}

SelectionResult select_faces(const CandidateSet& cs, const SelectionProgram& program, const SelectionConfig& config) {
  return select_faces(cs, program, config, config.mip_time_limit);
}

}  // namespace lodrefine
