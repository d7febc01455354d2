// The selection solver's faults (issue "bad input"): select_faces() on synthetic programs GLPK
// cannot solve (infeasible, no candidates, hard under a time limit, a starved easy one), a
// fuzz finding that aborted GLPK, and the whole refine under a starved solver, in-process and
// through the CLI. Moved from tests/app/ (names kept); each adds a row to the bad-input table
// (support/bad_input_fixtures.h), printed at the end of a one-process run.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "lodrefine/city/refine_report.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/refine/selection.h"
#include "support/bad_input_fixtures.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

// ---------------------------------------------------------------------------------------------
// Library-level regression of a fuzz finding

// tests/fuzz/regressions/fuzz_refine/glpk_duplicate_index_warped_ground: build_candidates
// produced an edge listing one face twice; select_faces put the column twice in one row and
// glp_load_matrix aborted the process ("duplicate indices not allowed"). Run in a child, so a
// regression kills the child, not the test binary.
TEST(BadInputRegression, FaceListedTwiceOnAnEdgeDoesNotAbortTheSolver) {
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(2);  // GLPK prints its error before aborting
    CandidateSet cs = fixtures::hand_built({0, 0}, {1.0, 1.0}, {{0, 0, 1}});
    const SelectionResult r = select_faces(cs, {-1.0, -1.0}, {0}, SelectionConfig{});
    ::_exit(r.status == SolveStatus::NotRun ? 1 : 0);
  }
  int st = 0;
  ::waitpid(pid, &st, 0);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0)
      << "select_faces killed the process (signal " << (WIFSIGNALED(st) ? WTERMSIG(st) : 0) << ")";
}

// ---------------------------------------------------------------------------------------------
// Solver faults: select_faces() on synthetic programs GLPK cannot solve.

namespace {

// Random parity constraints (sum of 3 x's + outside = 2 y per edge) over many faces: GLPK's
// LP relaxation is trivially fractional and branch and bound explodes.
CandidateSet hard_program(int faces, int edges, unsigned seed, std::vector<double>& cost, std::vector<int>& outside) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, faces - 1);
  std::vector<int> plane;
  std::vector<double> area;
  for (int f = 0; f < faces; ++f) {
    plane.push_back(f % 7);
    area.push_back(1.0 + f % 5);
    cost.push_back((f % 3) - 1.0);
  }
  std::vector<std::vector<int>> fans;
  for (int e = 0; e < edges; ++e) {
    std::vector<int> fan;
    while (fan.size() < 3) {
      const int f = pick(rng);
      if (std::find(fan.begin(), fan.end(), f) == fan.end()) fan.push_back(f);
    }
    fans.push_back(fan);
    outside.push_back(int(rng() % 2));
  }
  return fixtures::hand_built(plane, area, fans);
}

}  // namespace

TEST(BadInputSolver, InfeasibleProgramIsReportedNotSelected) {
  // Face 0 alone on two edges: once with the outside surface (x0 + 1 = 2 y0 -> x0 = 1), once
  // without (x0 = 2 y1 -> x0 = 0). No selection satisfies both.
  CandidateSet cs = fixtures::hand_built({0}, {1.0}, {{0}, {0}});
  const SelectionResult r = select_faces(cs, {-1.0}, {1, 0}, SelectionConfig{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "infeasible");
  EXPECT_EQ(selected_faces(cs), std::vector<char>(1, 0));
  add_row("select_faces: infeasible program", "ok=false, status '" + r.status_text() + "'", 0);
}

TEST(BadInputSolver, NoCandidatesIsReported) {
  CandidateSet none;
  const SelectionResult r = select_faces(none, {}, {}, SelectionConfig{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "no candidates");
}

TEST(BadInputSolver, TimeLimitWithoutSolutionIsReported) {
  std::vector<double> cost;
  std::vector<int> outside;
  CandidateSet cs = hard_program(3000, 4000, 3, cost, outside);
  SelectionConfig prm;
  prm.mip_time_limit = 0.01;
  const SelectionResult r = select_faces(cs, cost, outside, prm);
  EXPECT_NE(r.status_text().find("time limit"), std::string::npos) << r.status_text();
  if (!r.ok) {
    EXPECT_EQ(r.status_text(), "time limit (no solution)");
    EXPECT_EQ(selected_faces(cs), std::vector<char>(std::size_t(cs.size()), 0));
  } else {
    EXPECT_EQ(r.status_text(), "feasible (time limit)");
  }
  EXPECT_LT(r.seconds, 5.0) << "the time limit was not honoured";
  // The budget is an argument (what is left of mip_time_limit after an earlier solve), not a
  // mutated copy of the config: it rules whatever config.mip_time_limit says.
  SelectionConfig patient = prm;
  patient.mip_time_limit = 3600.0;
  SelectionProgram pg;
  pg.cost = cost;
  pg.outside = outside;
  const SelectionResult budget = select_faces(cs, pg, patient, 0.01);
  EXPECT_NE(budget.status_text().find("time limit"), std::string::npos) << budget.status_text();
  EXPECT_LT(budget.seconds, 5.0) << "the budget argument was not honoured";
  add_row("select_faces: 3000-face parity program, 10 ms limit",
          "ok=" + std::string(r.ok ? "true" : "false") + ", status '" + r.status_text() + "', " + fmt(r.seconds) + " s",
          0);
}

namespace {

// A real, easy program: the arrangement of a cube's six planes in a larger region (54
// candidates); rewarding the pieces on the cube selects exactly its six faces.
CandidateSet cube_program(std::vector<double>& cost, std::vector<int>& outside) {
  std::vector<SupportPlane> planes;
  for (int k = 0; k < 3; ++k)
    for (double sign : {1.0, -1.0}) {
      SupportPlane sp;
      sp.plane = Plane(sign * Vec3::Unit(k), -1.0);
      sp.sem = k == 2 ? (sign > 0 ? Semantic::Roof : Semantic::Ground) : Semantic::Wall;
      planes.push_back(sp);
    }
  Region region;
  region.half = Vec3::Constant(2.0);
  CandidateSet cs = build_candidates(planes, region);
  for (int f = 0; f < cs.size(); ++f)
    cost.push_back(fixtures::centroid_of(cs, f).lpNorm<Eigen::Infinity>() <= 1.0 + 1e-9 ? -fixtures::area_of(cs, f)
                                                                                        : fixtures::area_of(cs, f));
  outside.assign(cs.edges.size(), 0);
  return cs;
}

}  // namespace

TEST(BadInputSolver, OneMillisecondLimitFailsEvenAnEasyProgram) {
  std::vector<double> cost;
  std::vector<int> outside;
  CandidateSet cs = cube_program(cost, outside);
  ASSERT_GE(cs.size(), 6);
  const SelectionResult easy = select_faces(cs, cost, outside, SelectionConfig{});
  ASSERT_TRUE(easy.ok) << easy.status_text();
  EXPECT_EQ(easy.status_text(), "optimal");
  const std::vector<char> chosen = selected_faces(cs);
  EXPECT_EQ(std::count(chosen.begin(), chosen.end(), 1), 6);
  // GLPK stops at its first time check when tm_lim <= 1 ms: a deterministic solver fault.
  SelectionConfig prm;
  prm.mip_time_limit = 0.001;
  const SelectionResult r = select_faces(cs, cost, outside, prm);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "time limit (no solution)");
  const std::vector<char> none = selected_faces(cs);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
  add_row("select_faces: cube arrangement (" + std::to_string(cs.size()) + " candidates), 1 ms limit",
          "ok=false, status '" + r.status_text() + "' (30 s limit: '" + easy.status_text() + "')", 0);
}

// The whole pipeline under a starved solver: refine_building must write a valid shell, either
// the starting shell GLPK took as its incumbent ("feasible (time limit)" or better) or the
// repaired input with the solver status as the reason. The CLI half needs --mip-time-limit to
// accept 1 ms (params.h's minimum), and fails if that bound ever rises.
TEST(BadInputSolver, RefineUnderAStarvedSolverWritesAValidShell) {
  const std::string dir = temp_dir("solver_fallback");
  write_text(dir + "/m.obj", valid_model());
  const Mesh model = read_obj(dir + "/m.obj");
  PointCloud cloud;
  cloud.points = wall_scan();
  RefineConfig prm;
  prm.selection.mip_time_limit = 0.001;
  const RefineResult r = refine_building(model, cloud, prm);
  const nlohmann::json report = refine_report(r);
  ASSERT_TRUE(r.valid) << report.dump(1);
  EXPECT_TRUE(validate_mesh(r.mesh, kPlanarity).valid());
  ASSERT_TRUE(report.contains("selection")) << report.dump(1);
  const std::string status = report["selection"].value("status", std::string());
  if (r.refined())
    EXPECT_TRUE(status == "optimal" || status == "feasible" || status == "feasible (time limit)") << status;
  else EXPECT_EQ(r.reason, "the selection found no valid shell: face selection " + status);
  add_row("refine_building, mip_time_limit 0.001", std::string("outcome '") + outcome_name(r.outcome) + "', " + status,
          0);

  // And through the CLI: exit 0, a valid shell written, the status in the report.
  write_text(dir + "/c.ply", valid_cloud());
  const CliRun cli =
      run_cli("refine --model " + shell_quote(dir + "/m.obj") + " --cloud " + shell_quote(dir + "/c.ply") + " --out " +
                  shell_quote(dir + "/r.obj") + " --report " + shell_quote(dir + "/r.json") + " --mip-time-limit 0.001",
              dir);
  EXPECT_EQ(cli.exit, 0) << cli.err;
  EXPECT_EQ(output_problem(dir + "/r.obj"), "");
  const json rep = json::parse(read_text(dir + "/r.json"));
  EXPECT_FALSE(rep["selection"].value("status", std::string()).empty()) << rep.dump(1);
  add_row("valid input, --mip-time-limit 0.001", first_line(cli.out), cli.exit);
}
