// Stage 5, selection: face selection by GLPK over the candidate arrangement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/objective.h"
#include "lodrefine/refine/selection.h"
#include "support/candidate_fixtures.h"
#include "support/cpu_burners.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

// The box's confidence: 1 on its six faces (the candidates inside the box), 0 on the pieces
// beyond it, as a starting shell without contrary scan evidence has it (shell_describe).
std::vector<double> box_confidence(const CandidateSet& cs, double a, double b, double c) {
  std::vector<double> conf;
  for (int f = 0; f < cs.size(); ++f) conf.push_back(inside_box(centroid_of(cs, f), a, b, c) ? 1.0 : 0.0);
  return conf;
}

// Each candidate's coverage cost from its confidence (the paper's sigmoid).
std::vector<double> coverage_costs(const CandidateSet& cs, const std::vector<double>& conf,
                                   const SelectionConfig& prm) {
  std::vector<double> cost;
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f)
    cost.push_back(coverage_cost(area_of(cs, f), conf[f], prm.tau_cov));
  return cost;
}

}  // namespace

TEST(Selection, RecoversTheClosedBoxFromConfidence) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  SelectionConfig prm;
  const auto conf = box_confidence(cs, a, b, c);
  const std::vector<double> cost = coverage_costs(cs, conf, prm);
  const auto full = std::count_if(conf.begin(), conf.end(), [](double x) { return x > 0.99; });
  EXPECT_EQ(full, 6);
  const SelectionResult sel = select_faces(cs, cost, std::vector<int>(cs.edges.size(), 0), prm);
  ASSERT_TRUE(sel.ok) << sel.status_text();
  EXPECT_EQ(sel.status_text(), "optimal");
  const std::vector<char> selected = selected_faces(cs);
  double area = 0.0;
  int count = 0;
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f)
    if (selected[f]) {
      ++count;
      area += area_of(cs, f);
      EXPECT_TRUE(inside_box(centroid_of(cs, f), a, b, c));
    }
  EXPECT_EQ(count, 6);
  EXPECT_NEAR(area, 2 * (a * b + b * c + a * c), 1e-6);
  // Every edge carries 0 or 2 selected faces.
  for (const auto& e : cs.edges) {
    int n = 0;
    for (auto h : e) n += selected[cs.face(h)];
    EXPECT_TRUE(n == 0 || n == 2);
  }
}

// An excluded local selection is never made: the box's six faces are not chosen together again
// (another closed selection is), and with all six fixed in the program has no solution.
TEST(Selection, AnExcludedLocalSelectionIsNotMade) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  SelectionConfig prm;
  const auto conf = box_confidence(cs, a, b, c);
  SelectionProgram pg;
  pg.cost = coverage_costs(cs, conf, prm);
  ASSERT_TRUE(select_faces(cs, pg, prm).ok);
  LocalSelection box;
  for (int f = 0; f < cs.size(); ++f)
    if (selected_faces(cs)[std::size_t(f)]) box.selected.push_back(f);
  ASSERT_EQ(box.selected.size(), 6u);
  pg.excluded = {box};
  const SelectionResult again = select_faces(cs, pg, prm);
  ASSERT_TRUE(again.ok) << again.status_text();
  const std::vector<char> now = selected_faces(cs);
  EXPECT_FALSE(std::all_of(box.selected.begin(), box.selected.end(), [&](int f) { return now[std::size_t(f)] != 0; }));
  EXPECT_TRUE(every_edge_used_0_or_2(cs, now));
  pg.fixed.assign(std::size_t(cs.size()), -1);
  for (int f : box.selected) pg.fixed[std::size_t(f)] = 1;
  EXPECT_EQ(select_faces(cs, pg, prm).status_text(), "infeasible");
}

// The solver applies no weight: a program's costs are the columns' coefficients as built
// (objective.h). At lambda_coverage 2 and lambda_data 5 the box's objective is still the sum of
// its six faces' costs (it was twice that when select_faces weighted them).
TEST(Selection, TakesEachCostAsBuiltWithoutWeights) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  SelectionConfig prm;
  SelectionProgram pg;
  pg.cost = coverage_costs(cs, box_confidence(cs, a, b, c), prm);
  pg.sharp_cost.assign(cs.edges.size(), 0.0);
  prm.lambda_coverage = 2.0;
  prm.lambda_data = 5.0;
  const SelectionResult sel = select_faces(cs, pg, prm);
  ASSERT_TRUE(sel.ok) << sel.status_text();
  double box_cost = 0.0;
  for (int f = 0; f < cs.size(); ++f)
    if (inside_box(centroid_of(cs, f), a, b, c)) box_cost += pg.cost[std::size_t(f)];
  EXPECT_NEAR(box_cost, 2 * (a * b + b * c + a * c) * (1.0 / (1.0 + std::exp(0.7)) - 0.5), 1e-9);
  EXPECT_NEAR(sel.objective, box_cost, 1e-6);
}

TEST(Selection, InfeasibleBoundaryIsReportedNotCrashed) {
  // One plane only: its faces can never close, yet the boundary demands a continuation.
  std::vector<SupportPlane> planes = {{Plane(Vec3(0, 0, 1), -1), Semantic::Roof, false, 0}};
  const Region region = Region::around({Vec3(0, 0, 0), Vec3(2, 2, 2)}, 0.0, 0.5);
  CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.size(), 1);
  std::vector<int> outside(cs.edges.size(), 0);
  outside[0] = 1;  // one continuing edge: the face must be selected, then 3 edges are open
  SelectionConfig prm;
  const SelectionResult sel = select_faces(cs, {-1.0}, outside, prm);
  EXPECT_FALSE(sel.ok);
  EXPECT_EQ(sel.status_text(), "infeasible");
}

TEST(Selection, StartsFromAClosedWarmStartAndRefusesAnOpenOne) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  SelectionConfig prm;
  const auto conf = box_confidence(cs, a, b, c);
  SelectionProgram pg;
  std::vector<char> box(std::size_t(cs.size()), 0);
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f) {
    pg.cost.push_back(coverage_cost(area_of(cs, f), conf[f], prm.tau_cov));
    box[f] = inside_box(centroid_of(cs, f), a, b, c);
  }
  EXPECT_TRUE(every_edge_used_0_or_2(cs, box));
  pg.warm = box;
  const SelectionResult sel = select_faces(cs, pg, prm);
  ASSERT_TRUE(sel.ok) << sel.status_text();
  EXPECT_TRUE(sel.warm_given);
  EXPECT_TRUE(sel.warm_feasible);
  EXPECT_TRUE(sel.warm_text() == "accepted" || sel.warm_text() == "not needed") << sel.warm_text();
  EXPECT_EQ(selected_faces(cs), box);
  EXPECT_EQ(sel.gap, 0.0);

  // One face short of the box: an open start is not handed to GLPK.
  std::vector<char> open = box;
  for (std::size_t f = 0; f < open.size(); ++f)
    if (open[f]) {
      open[f] = 0;
      break;
    }
  EXPECT_FALSE(every_edge_used_0_or_2(cs, open));
  pg.warm = open;
  const SelectionResult r = select_faces(cs, pg, prm);
  EXPECT_FALSE(r.warm_feasible);
  EXPECT_EQ(r.warm_text(), "infeasible");
  EXPECT_EQ(selected_faces(cs), box);  // the program still finds the box
}

TEST(Selection, FixedFacesAreConstantsOfTheProgram) {
  const double a = 10, b = 8, c = 6;
  CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  SelectionConfig prm;
  SelectionProgram pg;
  std::vector<char> box(std::size_t(cs.size()), 0);
  int inside = 0;
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f) {
    box[f] = inside_box(centroid_of(cs, f), a, b, c);
    inside += box[f];
    pg.cost.push_back(box[f] ? -1.0 : 1.0);
    pg.fixed.push_back(box[f] ? 1 : -1);  // the box fixed in, the rest free
  }
  const SelectionResult sel = select_faces(cs, pg, prm);
  ASSERT_TRUE(sel.ok) << sel.status_text();
  EXPECT_EQ(sel.fixed - sel.forced, inside);
  EXPECT_EQ(selected_faces(cs), box);
  // The box's edges are each used twice by it: every other face there is decided 0 by the edge
  // constraints, and so on outwards; nothing is left for GLPK (its presolve would find the same,
  // but it is off under a warm start).
  EXPECT_EQ(sel.forced, cs.size() - inside);
  EXPECT_EQ(sel.variables, 0);
  // Everything fixed, the box one face short: the constants alone break an edge constraint.
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f) pg.fixed[f] = box[f];
  for (std::size_t f = 0; f < std::size_t(cs.size()); ++f)
    if (box[f]) {
      pg.fixed[f] = 0;
      break;
    }
  const SelectionResult bad = select_faces(cs, pg, prm);
  EXPECT_FALSE(bad.ok);
  EXPECT_EQ(bad.status_text(), "infeasible");
}

namespace {

// A program GLPK cannot close at its root: the box's planes and 3 more per axis cut through it,
// every candidate's cost pseudo-random in [-1, 1] per m^2, the box as the (closed) warm start.
CandidateSet crossed_box_program(SelectionProgram& pg) {
  const double a = 10, b = 8, c = 6;
  std::vector<SupportPlane> planes = box_planes(a, b, c);
  for (int k = 1; k <= 3; ++k) {
    planes.push_back({Plane(Vec3(1, 0, 0), -a * k / 4.0), Semantic::Wall, false, int(planes.size())});
    planes.push_back({Plane(Vec3(0, 1, 0), -b * k / 4.0), Semantic::Wall, false, int(planes.size())});
    planes.push_back({Plane(Vec3(0, 0, 1), -c * k / 4.0), Semantic::Roof, false, int(planes.size())});
  }
  CandidateSet cs = build_candidates(planes, box_region(a, b, c));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto areas = cs.areas();
  const auto centroids = cs.centroids();
  for (auto f : cs.mesh.faces()) {
    const Vec3 p = centroids[f];
    pg.cost.push_back(unit(rng) * areas[f]);
    pg.warm.push_back(inside_box(p, a, b, c) &&
                      (std::abs(p.x()) < 1e-9 || std::abs(p.x() - a) < 1e-9 || std::abs(p.y()) < 1e-9 ||
                       std::abs(p.y() - b) < 1e-9 || std::abs(p.z()) < 1e-9 || std::abs(p.z() - c) < 1e-9));
  }
  return cs;
}

}  // namespace

// The search ends at a count of GLPK's work, not at a wall-clock limit: the same selection,
// status and work on every run, whatever the time limit and however busy the machine is.
TEST(Selection, TheWorkBudgetEndsTheSearchAtTheSamePointUnderAnyLoad) {
  SelectionProgram pg;
  CandidateSet cs = crossed_box_program(pg);
  ASSERT_TRUE(every_edge_used_0_or_2(cs, pg.warm));
  SelectionConfig prm;
  prm.mip_work_limit = 2.0;
  const SelectionResult quiet = select_faces(cs, pg, prm);
  const std::vector<char> quiet_selected = selected_faces(cs);
  ASSERT_TRUE(quiet.ok) << quiet.status_text();
  ASSERT_EQ(quiet.status, SolveStatus::FeasibleBudget) << quiet.status_text();
  EXPECT_EQ(quiet.status_text(), "feasible (budget)");
  EXPECT_GT(quiet.gap, 0.0);
  EXPECT_LE(quiet.work, prm.mip_work_limit);
  EXPECT_TRUE(every_edge_used_0_or_2(cs, quiet_selected));

  fixtures::CpuBurners burners(2);
  std::vector<SelectionResult> runs;
  std::vector<std::vector<char>> selections;
  for (double limit : {prm.mip_time_limit, 3600.0, 1000.0}) {
    if (limit == 1000.0) {  // and once more on a quiet machine
      burners.stop();
    }
    runs.push_back(select_faces(cs, pg, prm, limit));
    selections.push_back(selected_faces(cs));
  }
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const SelectionResult& r = runs[i];
    EXPECT_EQ(r.status, quiet.status) << r.status_text();
    EXPECT_EQ(selections[i], quiet_selected);
    EXPECT_EQ(r.objective, quiet.objective);
    EXPECT_EQ(r.work, quiet.work);
    EXPECT_EQ(r.gap, quiet.gap);
  }
  // A larger budget goes on from where this one stopped: the budget is what ended it.
  prm.mip_work_limit = 20.0;
  const SelectionResult more = select_faces(cs, pg, prm);
  ASSERT_TRUE(more.ok) << more.status_text();
  EXPECT_GT(more.work, 2.0);
  EXPECT_LE(more.objective, quiet.objective);
}

// No budget for even the LP relaxation: the closed warm start is the selection, at the budget.
TEST(Selection, AtTheBudgetBeforeTheSearchTheWarmStartIsTaken) {
  SelectionProgram pg;
  CandidateSet cs = crossed_box_program(pg);
  SelectionConfig prm;
  prm.mip_work_limit = 0.0;
  const SelectionResult r = select_faces(cs, pg, prm);
  ASSERT_TRUE(r.ok) << r.status_text();
  EXPECT_EQ(r.status_text(), "feasible (budget)");
  EXPECT_EQ(selected_faces(cs), pg.warm);
  EXPECT_EQ(r.work, 0.0);
}
