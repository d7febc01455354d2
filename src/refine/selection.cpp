// Stage 5, selection: the binary program, driven through GLPK's C API (CGAL's traits only turn presolve
// on; PolyFit-shaped programs need cuts: measured 13 min -> 0.2 s with MIR cuts).
#include "lodrefine/refine/selection.h"

#include <glpk.h>

#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/objective.h"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>

namespace lodrefine {
namespace {

// GLPK returns binary columns as 0 or 1 up to its integrality tolerance: above this is chosen.
constexpr double kChosen = 0.5;
// glp_iocp::tm_lim is an int of milliseconds: longer limits are cut to this (~23 days).
constexpr double kMaxTimeLimitMs = 2.0e9;

// glp_intopt's and glp_simplex's return code: the work budget (GLP_ESTOP from our callback,
// GLP_EITLIM from the relaxation's iteration limit) or the wall-clock ceiling.
bool at_budget(int ret) { return ret == GLP_ESTOP || ret == GLP_EITLIM; }

SolveStatus classify(int ret, int status) {
  if (status == GLP_OPT) return SolveStatus::Optimal;
  if (status == GLP_FEAS) {
    if (at_budget(ret)) return SolveStatus::FeasibleBudget;
    return ret == GLP_ETMLIM ? SolveStatus::FeasibleTimeLimit : SolveStatus::Feasible;
  }
  if (status == GLP_NOFEAS || ret == GLP_ENOPFS) return SolveStatus::Infeasible;
  if (at_budget(ret)) return SolveStatus::BudgetNoSolution;
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
    case SolveStatus::FeasibleBudget: return "feasible (budget)";
    case SolveStatus::FeasibleTimeLimit: return "feasible (time limit)";
    case SolveStatus::Infeasible: return "infeasible";
    case SolveStatus::BudgetNoSolution: return "budget (no solution)";
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

// The search's work, counted in tableau entries: each simplex iteration (of the relaxation and
// of every node's LP) one row and one column (rows + columns), each round of cuts at the root the
// whole tableau (rows x columns: its generators scan it; measured 3-5 ns of CPU per entry on the
// real dev tile's 1,300-5,700 column programs). A count of what GLPK did, not of seconds, so a
// search that reaches it ends at the same point on any machine load.
double tableau_size(glp_prob* lp) { return double(glp_get_num_rows(lp)) * double(glp_get_num_cols(lp)); }
double iteration_size(glp_prob* lp) { return double(glp_get_num_rows(lp)) + double(glp_get_num_cols(lp)); }

// Until the search holds a solution, it may spend this many budgets to find one (no warm start,
// or GLPK refused it): a building is then kept only when none is found even so. With one budget
// an upper storey's move is lost (Refine.AnUpperStoreyOverALedgeIsMovedWhereItsSubstitutionFolds)
// and the jobs' selections end elsewhere (CityFile.JobsWriteTheSameBytesWhenSelectionsEndAtTheBudget);
// ten let hopeless programs of the 2,000-building bench run 15 s. Without a warm start the count
// under-reads GLPK's time about 5x (presolved program, cut rows): such a search may take ~5 s.
constexpr double kFirstSolutionBudgets = 4.0;

// The callback's state: the starting point (GLPK's 1-based column values) and what GLPK made of
// it; the last relative gap seen; the work done, the simplex iterations counted in it and the
// budget.
struct Search {
  std::vector<double> start;  // empty: no warm start
  bool asked = false, accepted = false;
  double gap = 0.0;
  double work = 0.0, budget = 0.0;
  int iterations = 0;  // glp_get_it_cnt when work was last brought up to date
};

// Brings the work up to date with the iterations GLPK made since, and tells whether the search
// has spent its budget (checked before each node's LP solve and before a round of cuts).
bool budget_spent(glp_tree* tree, Search& s, int reason) {
  glp_prob* lp = glp_ios_get_prob(tree);
  const int it = glp_get_it_cnt(lp);
  s.work += double(it >= s.iterations ? it - s.iterations : it) * iteration_size(lp);
  s.iterations = it;
  const bool solved = glp_ios_mip_gap(tree) < DBL_MAX;  // an incumbent exists
  const double budget = solved ? s.budget : kFirstSolutionBudgets * s.budget;
  if (reason == GLP_ICUTGEN) {
    if (s.work + tableau_size(lp) > budget) return true;
    s.work += tableau_size(lp);
    return false;
  }
  return reason == GLP_IPREPRO && s.work > budget;
}

void on_search(glp_tree* tree, void* info) {
  auto& s = *static_cast<Search*>(info);
  const int reason = glp_ios_reason(tree);
  if (budget_spent(tree, s, reason)) {
    glp_ios_terminate(tree);
    return;
  }
  switch (reason) {
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

}  // namespace

bool every_edge_used_0_or_2(const CandidateSet& cs, const std::vector<char>& selected,
                            const std::vector<int>& outside) {
  for (std::size_t e = 0; e < cs.edges.size(); ++e) {
    int n = outside.empty() ? 0 : outside[e];
    for (auto h : cs.edges[e]) n += selected[cs.face(h)];
    if (n != 0 && n != 2) return false;
  }
  return true;
}

namespace {

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
      for (auto h : cs.edges[e]) {
        const int f = cs.face(h);
        if (fixed[f] < 0) ++free;
        else constant += fixed[f];
      }
      if (free == 0 || constant > 2) continue;
      if (constant == 2 || free == 1) {
        for (auto h : cs.edges[e])
          if (fixed[cs.face(h)] < 0) fixed[cs.face(h)] = constant == 2 ? 0 : constant;
        changed = true;
      }
    }
  }
  return fixed;
}

// The program's view of the candidates: fixed values, and a GLPK column (1-based) per free
// candidate, 0 for a fixed one (the face map candidate_props::variable); the answer in selected.
struct Columns {
  const SelectionProgram& pg;
  std::vector<int> fixed;  // pg.fixed and the faces the edges force (forced_by_edges)
  CandidateMap<int> variable;
  CandidateMap<bool> selected;
  int faces = 0;
  int free = 0;
  int column(int f) const { return variable[CandidateFace(f)]; }
  int fixed_value(int f) const { return fixed[f]; }
  int outside(int e) const { return pg.outside.empty() ? 0 : pg.outside[e]; }
  bool warm(int f) const { return !pg.warm.empty() && pg.warm[f]; }
};

// Decides the variables: a column per free candidate; fixed ones take their value in
// candidate_props::selected.
Columns candidate_columns(CandidateSet& cs, const SelectionProgram& pg, SelectionResult& res) {
  const int nf = cs.size();
  Columns c{pg,
            forced_by_edges(cs, pg.fixed.empty() ? std::vector<int>(nf, -1) : pg.fixed, pg.outside),
            candidate_props::variable.add(cs.mesh),
            candidate_props::selected.add(cs.mesh),
            nf,
            0};
  for (int f = 0; f < nf; ++f) {
    const CandidateFace fi(f);
    c.variable[fi] = 0;
    c.selected[fi] = false;
    if (c.fixed_value(f) >= 0) ++res.fixed, c.selected[fi] = c.fixed_value(f) != 0;
    else c.variable[fi] = ++c.free;
    res.forced += c.fixed_value(f) >= 0 && (pg.fixed.empty() || pg.fixed[f] < 0);
  }
  return c;
}

// Whether the starting point may be handed to GLPK, which takes a heuristic solution unchecked:
// every edge used 0 or 2 times, and the fixed candidates as fixed.
bool warm_start_feasible(const CandidateSet& cs, const Columns& c) {
  if (!every_edge_used_0_or_2(cs, c.pg.warm, c.pg.outside)) return false;
  for (int f = 0; f < cs.size(); ++f)
    if (c.fixed_value(f) >= 0 && c.fixed_value(f) != c.pg.warm[f]) return false;
  for (const auto& x : c.pg.excluded)
    if (std::all_of(x.selected.begin(), x.selected.end(), [&](int f) { return c.pg.warm[f] != 0; }) &&
        std::none_of(x.unselected.begin(), x.unselected.end(), [&](int f) { return c.pg.warm[f] != 0; }))
      return false;
  return true;
}

// The GLPK problem under construction: its matrix triplets (1-based) and the starting value of
// each column (start[0] unused, like GLPK's).
struct Program {
  glp_prob* lp = glp_create_prob();
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  std::vector<double> start{0.0};
  Program() { glp_set_obj_dir(lp, GLP_MIN); }
  ~Program() { glp_delete_prob(lp); }
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;
  int new_binary(double cost, double value) {
    const int c = glp_add_cols(lp, 1);
    glp_set_col_kind(lp, c, GLP_BV);
    glp_set_obj_coef(lp, c, cost);
    start.push_back(value);
    return c;
  }
  void add_row(const std::vector<std::pair<int, double>>& terms, int type, double lo, double hi) {
    const int r = glp_add_rows(lp, 1);
    glp_set_row_bnds(lp, r, type, lo, hi);
    for (const auto& [c, val] : combined(terms)) {
      ia.push_back(r);
      ja.push_back(c);
      ar.push_back(val);
    }
  }
};

// A binary column per free candidate, costing its objective coefficient as built (objective.h).
void add_face_columns(Program& p, const CandidateSet& cs, const Columns& c) {
  if (c.free > 0) glp_add_cols(p.lp, c.free);
  for (int f = 0; f < cs.size(); ++f) {
    if (c.column(f) == 0) continue;
    glp_set_col_kind(p.lp, c.column(f), GLP_BV);
    glp_set_obj_coef(p.lp, c.column(f), c.pg.cost[f]);
    p.start.push_back(c.warm(f) ? 1.0 : 0.0);
  }
}

// Edge e used by 0 or 2 selected faces: sum x_free + constant = 2 y, y binary. Returns false when
// the fixed faces alone use it once or 3+ times (the program is infeasible).
bool add_edge_constraint(Program& p, const CandidateSet& cs, const Columns& c, int e) {
  std::vector<std::pair<int, double>> terms;
  int constant = c.outside(e), warm_count = c.outside(e);
  for (auto h : cs.edges[e]) {
    const int f = cs.face(h);
    if (c.column(f) > 0) terms.emplace_back(c.column(f), 1.0);
    else constant += c.fixed_value(f);
    warm_count += c.warm(f);
  }
  if (terms.empty()) return constant == 0 || constant == 2;
  terms.emplace_back(p.new_binary(0.0, warm_count == 2 ? 1.0 : 0.0), -2.0);
  p.add_row(terms, GLP_FX, -constant, -constant);
  return true;
}

// The complexity term of edge e: one binary s costing `sharp`, with s >= xi + xj - 1 for every
// two of its faces on different planes (fixed faces folded in; none when one is fixed out or
// both are fixed in).
void add_sharp_edge(Program& p, const CandidateSet& cs, const CandidateMap<int>& support, const Columns& c, int e,
                    double sharp) {
  std::vector<int> faces;
  for (auto h : cs.edges[e]) faces.push_back(cs.face(h));
  int s = 0;
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (std::size_t j = i + 1; j < faces.size(); ++j) {
      const int fi = faces[i], fj = faces[j];
      if (support[CandidateFace(fi)] == support[CandidateFace(fj)]) continue;
      if (c.fixed_value(fi) == 0 || c.fixed_value(fj) == 0) continue;
      if (c.column(fi) == 0 && c.column(fj) == 0) continue;  // both fixed in: a constant
      const bool both_warm = c.warm(fi) && c.warm(fj);
      if (s == 0) s = p.new_binary(sharp, both_warm ? 1.0 : 0.0);
      else if (both_warm) p.start[s] = 1.0;
      std::vector<std::pair<int, double>> t{{s, 1.0}};
      double rhs = -1.0;
      for (int g : {fi, fj}) {
        if (c.column(g) > 0) t.emplace_back(c.column(g), -1.0);
        else rhs += 1.0;  // fixed in
      }
      p.add_row(t, GLP_LO, rhs, 0.0);
    }
}

// No local selection of program.excluded made: sum x(selected) - sum x(unselected) <=
// |selected| - 1, fixed faces folded in; false when the fixed faces make one.
bool add_exclusions(Program& p, const Columns& c) {
  for (const auto& x : c.pg.excluded) {
    std::vector<std::pair<int, double>> terms;
    double bound = double(x.selected.size()) - 1.0;
    bool made_otherwise = false;  // a fixed face already differs from it
    for (int f : x.selected) {
      if (c.column(f) > 0) terms.emplace_back(c.column(f), 1.0);
      else if (c.fixed_value(f) == 1) bound -= 1.0;
      else made_otherwise = true;
    }
    for (int f : x.unselected) {
      if (c.column(f) > 0) terms.emplace_back(c.column(f), -1.0);
      else if (c.fixed_value(f) == 1) made_otherwise = true;
    }
    if (made_otherwise) continue;
    if (terms.empty()) return false;
    p.add_row(terms, GLP_UP, 0.0, bound);
  }
  return true;
}

// Every edge's constraint and complexity term; false when the fixed faces contradict one.
bool add_edges(Program& p, const CandidateSet& cs, const Columns& c, const SelectionConfig& prm) {
  const double uniform_sharp = uniform_sharp_cost(cs, prm);
  const auto support = cs.supports();
  bool feasible = true;
  for (int e = 0; e < int(cs.edges.size()); ++e) {
    feasible = add_edge_constraint(p, cs, c, e) && feasible;
    const double sharp = c.pg.sharp_cost.empty() ? uniform_sharp : c.pg.sharp_cost[e];
    if (sharp > 0) add_sharp_edge(p, cs, support, c, e, sharp);
  }
  return feasible;
}

// Branch and cut with MIR and clique cuts, the gap, the work budget (tableau entries) and the
// wall-clock ceiling (s). No Gomory or cover cuts: generating Gomory cuts (a tableau row per
// fractional column) and sorting the cover cuts into the pool (a tableau row per cut) cost ~25 %
// of the selection's time on the real dev tile and changed no selection on the dev tiles.
// Without MIR cuts too, one roof there came out worse.
glp_iocp search_parameters(const SelectionConfig& prm, double time_limit, Search& search) {
  glp_iocp parm;
  glp_init_iocp(&parm);
  parm.mir_cuts = GLP_ON;
  parm.gmi_cuts = GLP_OFF;
  parm.cov_cuts = GLP_OFF;
  parm.clq_cuts = GLP_ON;
  parm.mip_gap = prm.mip_gap;
  parm.tm_lim = int(std::min(kMaxTimeLimitMs, std::ceil(time_limit * 1000.0)));
  parm.msg_lev = GLP_MSG_OFF;
  parm.cb_func = on_search;
  parm.cb_info = &search;
  search.budget = prm.mip_work_limit * 1e6;
  return parm;
}

// Solves the MIP; returns GLPK's return code. With a warm start the callback sees the original
// columns only without the MIP presolver, which then needs an optimal basis of the LP relaxation;
// its iterations count against the work budget (each rows + columns entries).
int solve(glp_prob* lp, glp_iocp& parm, Search& search, bool warm) {
  int ret = 0;
  if (!warm) {
    parm.presolve = GLP_ON;
  } else {
    glp_smcp lpp;
    glp_init_smcp(&lpp);
    lpp.msg_lev = GLP_MSG_OFF;
    lpp.presolve = GLP_ON;
    lpp.tm_lim = parm.tm_lim;
    const double per_iteration = iteration_size(lp);
    lpp.it_lim = int(std::min(2.0e9, std::floor(search.budget / per_iteration)));
    const auto t0 = std::chrono::steady_clock::now();
    ret = glp_simplex(lp, &lpp);
    search.iterations = glp_get_it_cnt(lp);
    search.work += per_iteration * search.iterations;
    parm.presolve = GLP_OFF;
    // The relaxation spent part of the budget: the search gets what is left, not all of it again.
    const double spent_ms = 1000.0 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    parm.tm_lim = std::max(1, parm.tm_lim - int(spent_ms));
  }
  if (ret == 0) ret = glp_intopt(lp, &parm);
  return ret;
}

// What GLPK made of it: the status from glp_intopt's return code and glp_mip_status (a zero
// return code alone is not success: only a primal feasible MIP point counts), the gap, the warm
// start's fate and the selection.
void read_solution(glp_prob* lp, int ret, const Search& search, Columns& c, SelectionResult& res) {
  const int status = glp_mip_status(lp);
  res.status = classify(ret, status);
  res.glpk_code = ret;
  res.warm_asked = search.asked;
  res.warm_accepted = search.accepted;
  res.gap = status == GLP_OPT ? 0.0 : search.gap;
  res.work = search.work / 1e6;
  res.ok = status == GLP_OPT || status == GLP_FEAS;
  if (!res.ok) {
    for (int f = 0; f < c.faces; ++f) c.selected[CandidateFace(f)] = false;
    return;
  }
  res.objective = glp_mip_obj_val(lp);
  for (int f = 0; f < c.faces; ++f)
    if (c.column(f) > 0) c.selected[CandidateFace(f)] = glp_mip_col_val(lp, c.column(f)) > kChosen;
}

// The relaxation ended at the budget or the ceiling before the search began: the warm start,
// feasible, is the best selection known.
void take_start(glp_prob* lp, const Search& search, Columns& c, int ret, SelectionResult& res) {
  res.status = ret == GLP_ETMLIM ? SolveStatus::FeasibleTimeLimit : SolveStatus::FeasibleBudget;
  res.ok = true;
  res.objective = 0.0;
  for (int j = 1; j < int(search.start.size()); ++j) res.objective += glp_get_obj_coef(lp, j) * search.start[j];
  for (int f = 0; f < c.faces; ++f)
    c.selected[CandidateFace(f)] = c.column(f) > 0 ? search.start[c.column(f)] > kChosen : c.fixed_value(f) == 1;
}

}  // namespace

SelectionResult select_faces(CandidateSet& cs, const SelectionProgram& pg, const SelectionConfig& prm,
                             double time_limit) {
  const auto t0 = std::chrono::steady_clock::now();
  SelectionResult res;
  Columns c = candidate_columns(cs, pg, res);
  auto done = [&](SolveStatus status) {
    res.status = status;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return res;
  };
  if (cs.size() == 0) return done(SolveStatus::NoCandidates);  // GLPK aborts on empty column sets
  res.warm_given = !pg.warm.empty();
  res.warm_feasible = res.warm_given && warm_start_feasible(cs, c);

  glp_term_out(GLP_OFF);
  Program p;
  add_face_columns(p, cs, c);
  const bool feasible = add_edges(p, cs, c, prm) && add_exclusions(p, c);
  res.variables = glp_get_num_cols(p.lp);
  res.constraints = glp_get_num_rows(p.lp);
  res.nonzeros = int(p.ia.size()) - 1;
  if (!feasible) {  // no selection, not the fixed and forced values that contradict each other
    for (auto f : cs.mesh.faces()) c.selected[f] = false;
    return done(SolveStatus::Infeasible);
  }
  if (res.variables == 0) {  // everything fixed: the fixed selection is the answer
    res.ok = true;
    return done(SolveStatus::Optimal);
  }
  glp_load_matrix(p.lp, int(p.ia.size()) - 1, p.ia.data(), p.ja.data(), p.ar.data());

  Search search;
  if (res.warm_feasible) search.start = p.start;
  glp_iocp parm = search_parameters(prm, time_limit, search);
  const int ret = solve(p.lp, parm, search, !search.start.empty());
  read_solution(p.lp, ret, search, c, res);
  if (!res.ok && !search.start.empty() && (at_budget(ret) || ret == GLP_ETMLIM)) take_start(p.lp, search, c, ret, res);
  return done(res.status);
}

SelectionResult select_faces(CandidateSet& cs, const std::vector<double>& cost, const std::vector<int>& outside,
                             const SelectionConfig& prm, const std::vector<int>* fixed) {
  SelectionProgram pg;
  pg.cost = cost;
  pg.outside = outside;
  if (fixed != nullptr) pg.fixed = *fixed;
  return select_faces(cs, pg, prm);
}

SelectionResult select_faces(CandidateSet& cs, const SelectionProgram& program, const SelectionConfig& config) {
  return select_faces(cs, program, config, config.mip_time_limit);
}

std::vector<char> selected_faces(const CandidateSet& cs) {
  const auto selected = candidate_props::selected.find(cs.mesh);
  std::vector<char> out(std::size_t(cs.size()), 0);
  if (selected.second)
    for (auto f : cs.mesh.faces()) out[std::size_t(f)] = char(selected.first[f]);
  return out;
}

}  // namespace lodrefine
