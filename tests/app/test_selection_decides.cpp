// End to end: the GLPK selection decides every refined building, on every sample and every
// generated building type. Each refined shell is closed and 2-manifold (every edge used by two
// faces in opposite directions), its report's selection solved, its faces are the selection's,
// it is nowhere worse than the coarse model on the truth's scanned walls, and the walls the
// scan moved sit on the truth. The street-facade types (recess, bay, setback) need faces the
// model lacks: SelectionAddsFaces runs ten of each, one test per seed (KNOWN SHORT seeds are
// skipped after the checks that still hold).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <tuple>
#include <utility>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"
#include "support/test_paths.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

// m: the coarse facades are 0.2-0.8 m off; a refinement that lands the scanned walls within this
// of the truth has chosen the moved walls.
constexpr double kOnTruth = 0.05;
// m: "not worse" up to the rounding of the arrangement's vertices and the truth's sampling.
constexpr double kNotWorse = 0.01;

double rms(const std::vector<double>& d) {
  double s = 0.0;
  for (double x : d) s += x * x;
  return d.empty() ? 0.0 : std::sqrt(s / double(d.size()));
}

// Every edge used by exactly two faces, once in each direction (core/topology's edge map).
int edges_not_used_twice(const Mesh& m) {
  int bad = 0;
  for (const auto& [e, uses] : edge_uses(m.faces)) bad += uses.size() != 2 || uses[0].forward == uses[1].forward;
  return bad;
}

struct Figures {
  bool refined = false;
  double before = 0.0, after = 0.0;  // truth facade RMSE of the coarse model and of the output (m)
};

// Every building: not worse than the coarse model (never worse). `on_truth`: also on the truth
// when refined; without it only the shell, the selection's status and never worse are asserted.
Figures expect_selection_decided(const Mesh& coarse, const Mesh& truth, const PointCloud& cloud, bool on_truth = true) {
  Figures fig;
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  SCOPED_TRACE(coarse.id + ": " + outcome_name(r.outcome) + " (" + r.reason + ")");
  EXPECT_TRUE(r.valid);
  if (!r.valid) return fig;
  const Vec3 o = local_origin(truth);
  const Mesh refined = translated(r.mesh, -o), local_truth = translated(truth, -o),
             local_coarse = translated(coarse, -o);
  const Validation v = validate_mesh(refined, RefineConfig{}.repair.planarity_tolerance);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_EQ(v.boundary_edges, 0);
  EXPECT_EQ(v.nonmanifold_edges, 0);
  EXPECT_EQ(v.inconsistent_edges, 0);
  EXPECT_EQ(edges_not_used_twice(refined), 0);

  std::vector<Vec3> local_points;
  for (const auto& p : cloud.points) local_points.push_back(p - o);
  const std::vector<int> scanned = scanned_walls(local_truth, local_points);
  EXPECT_FALSE(scanned.empty());
  if (scanned.empty()) return fig;
  const auto samples = sample_faces(local_truth, scanned, 0.25);
  fig.before = rms(cloud_to_mesh(local_coarse, samples)), fig.after = rms(cloud_to_mesh(refined, samples));
  fig.refined = r.refined();
  EXPECT_LE(fig.after, fig.before + kNotWorse) << "truth facade RMSE " << fig.before << " -> " << fig.after;
  if (!r.refined()) return fig;

  EXPECT_TRUE(r.trace.selection.has_value());
  if (!r.trace.selection) return fig;
  const auto& sel = *r.trace.selection;
  EXPECT_TRUE(sel.selection.status == SolveStatus::Optimal || sel.selection.status == SolveStatus::Feasible ||
              sel.selection.status == SolveStatus::FeasibleTimeLimit ||
              sel.selection.status == SolveStatus::FeasibleBudget)
      << sel.selection.status_text();
  EXPECT_GT(sel.faces_from_selection, 0);
  EXPECT_EQ(sel.faces_from_selection, int(r.mesh.faces.size()));
  if (on_truth) {
    EXPECT_LT(fig.after, kOnTruth) << "truth facade RMSE " << fig.before << " -> " << fig.after;
  }
  return fig;
}

}  // namespace

TEST(SelectionDecides, EverySample) {
  const fs::path samples = fs::path(test_paths::source_dir()) / "data" / "samples";
  int n = 0;
  for (const auto& dir : fs::directory_iterator(samples)) {
    if (!fs::exists(dir.path() / "truth.obj")) continue;
    SCOPED_TRACE(dir.path().filename().string());
    expect_selection_decided(read_obj((dir.path() / "coarse.obj").string()),
                             read_obj((dir.path() / "truth.obj").string()),
                             read_cloud((dir.path() / "cloud.ply").string()));
    ++n;
  }
  EXPECT_GE(n, 4);
}

// synth_stepped_1402 (from the 2,000-building bench): substitution moves walls 0 and 9 onto their
// scan planes, and the judge refuses wall 0 (no scan points in its region). The building was kept
// whole, its scanned walls 0.17 m off the truth (RMS; eval: 0.29 m). Dropping that one move and
// refining again on the other's, the selection still moves wall 0 onto its scan (judged on the
// building's points) and the building comes out on the truth.
TEST(SelectionDecides, AScanMoveTheJudgeRefusesIsDroppedAndTheBuildingRefinedOnTheOthers) {
  const fs::path dir = fs::path(test_paths::source_dir()) / "data" / "samples" / "synth_stepped_1402";
  const Mesh coarse = read_obj((dir / "coarse.obj").string());
  const PointCloud cloud = read_cloud((dir / "cloud.ply").string());
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  ASSERT_EQ(r.trace.walls_refused.size(), 1u);
  EXPECT_NE(r.trace.walls_refused[0].find("wall check: moved wall 0"), std::string::npos) << r.trace.walls_refused[0];
  ASSERT_TRUE(r.trace.judgement.has_value());
  EXPECT_TRUE(r.trace.judgement->ok);
  const Figures fig = expect_selection_decided(coarse, read_obj((dir / "truth.obj").string()), cloud);
  EXPECT_GT(fig.before, 0.15);  // the scanned walls sampled here (eval: 0.29 m)
  EXPECT_LT(fig.after, kOnTruth);
}

class SelectionDecidesType : public ::testing::TestWithParam<BuildingType> {};

TEST_P(SelectionDecidesType, GeneratedBuilding) {
  SynthOptions opt;
  opt.target_points = 20000;
  const SynthBuilding b = make_building(GetParam(), 21, opt);
  expect_selection_decided(b.coarse, b.truth, b.cloud);
}

INSTANTIATE_TEST_SUITE_P(AllTypes, SelectionDecidesType, ::testing::ValuesIn(all_building_types()),
                         [](const auto& info) { return std::string(building_type_name(info.param)); });

// The street-facade types: the truth has faces the coarse model lacks (a recess's back wall and
// returns, a bay's front and sides, a facade line stepping back). Moving the model's walls
// cannot reach them; the selection must add them: each building is refined, its scanned walls
// within kOnTruth of the truth. One test per type and seed (StreetFacades/...<type>_seed_<n>),
// so a seed that breaks fails on its own and no other seed can make up for it.
//
// KNOWN SHORT (measured 2026-12-04, target_points 20000): the pipeline does not reach the
// truth on this seed. Its test (KnownShort_<type>_seed_<n>) still checks a valid, closed,
// 2-manifold shell, a solved selection and never worse, then is skipped with its figures; it
// fails once the seed reaches the truth, to be made a regular seed. Truth facade RMSE coarse ->
// output: recess 9: 0.402 -> 0.406 m.
// (bay 1 and 7 and setback 4, 7 and 8 reach the truth since each scanned plane's neighbourhood is
// solved before the whole program, its answer the warm start: their programs ended at the work
// budget, or at a first solve whose shell was refused, on the start.)
// Why (diagnosed 2026-12-02, still open):
//   recess 9: the back wall 1.34 m behind the start's and both returns unscanned (hypothesised,
//     12.4 m² each at confidence 0, +0.93 each): at lambda_data 0.3 the program takes the
//     recess (its back wall's points explain 20 m²; the truth not measured), at 0.1 not.
const std::set<std::pair<BuildingType, std::uint64_t>> kKnownShort{{BuildingType::Recess, 9}};
constexpr std::uint64_t kStreetSeeds = 10;

class SelectionAddsFaces : public ::testing::TestWithParam<std::tuple<BuildingType, std::uint64_t>> {};

TEST_P(SelectionAddsFaces, RefinedOntoTheTruth) {
  const auto [type, seed] = GetParam();
  SynthOptions opt;
  opt.target_points = 20000;
  const SynthBuilding b = make_building(type, seed, opt);
  SCOPED_TRACE(b.id);
  const bool known_short = kKnownShort.count({type, seed}) > 0;
  const Figures fig = expect_selection_decided(b.coarse, b.truth, b.cloud, !known_short);
  if (!known_short) {
    EXPECT_TRUE(fig.refined) << "truth facade RMSE " << fig.before;
    return;
  }
  const bool on_truth = fig.refined && fig.after < kOnTruth;
  EXPECT_FALSE(on_truth) << b.id << " now reaches the truth (" << fig.before << " -> " << fig.after
                         << " m): remove it from kKnownShort";
  if (!HasFailure())
    GTEST_SKIP() << "known short: " << b.id << " " << (fig.refined ? "refined" : "kept") << " " << fig.before << " -> "
                 << fig.after << " m (kKnownShort)";
}

// recess_seed_3, or KnownShort_recess_seed_9 for a seed of kKnownShort.
std::string street_case_name(const ::testing::TestParamInfo<SelectionAddsFaces::ParamType>& info) {
  const auto [type, seed] = info.param;
  return std::string(kKnownShort.count({type, seed}) ? "KnownShort_" : "") + building_type_name(type) + "_seed_" +
         std::to_string(seed);
}

INSTANTIATE_TEST_SUITE_P(StreetFacades, SelectionAddsFaces,
                         ::testing::Combine(::testing::Values(BuildingType::Recess, BuildingType::Bay,
                                                              BuildingType::Setback),
                                            ::testing::Range<std::uint64_t>(1, kStreetSeeds + 1)),
                         street_case_name);
