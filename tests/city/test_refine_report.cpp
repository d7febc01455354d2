// The refine report: built from RefineResult after the fact, with a key per stage reached.
#include <gtest/gtest.h>

#include "lodrefine/city/refine_report.h"
#include "lodrefine/refine/refine.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

// A georeferenced box 12 × 8 × 6 m and an MLS scan of its front wall 0.4 m further out.
struct Scene {
  Vec3 origin{85000.0, 447000.0, 0.0};
  Mesh model;
  PointCloud scan;
  Scene() {
    model = as_soup(box(Vec3(0, 0, 0), Vec3(12, 8, 6)));
    model.id = "box";
    add_grid(scan, wall_patch(Vec3(0, -0.4, 0), Vec3::UnitX(), 12.0, 0.0, 6.0), 0.1, 0.005);
    for (auto& v : model.vertices) v += origin;
    for (auto& p : scan.points) p += origin;
  }
};

}  // namespace

TEST(RefineReport, RefinedBuildingHasEveryStage) {
  const Scene s;
  const RefineResult r = refine_building(s.model, s.scan, RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  const nlohmann::json j = refine_report(r);
  EXPECT_EQ(j["id"], "box");
  EXPECT_EQ(j["report_version"], 1);
  EXPECT_EQ(j["outcome"], "refined");
  EXPECT_EQ(j["refined"], true);
  EXPECT_EQ(j["origin"], nlohmann::json({85000.0, 447000.0, 0.0}));
  for (const char* key :
       {"repair", "input_validation", "output_validation", "cloud", "planes", "matches", "rejected_matches", "q_model",
        "substitution", "replacements", "facades", "judgement", "selection"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["cloud"]["points"], s.scan.points.size());
  ASSERT_EQ(j["matches"].size(), 1u);
  EXPECT_NEAR(j["matches"][0]["deviation"].get<double>(), 0.4, 0.02);
  EXPECT_EQ(j["substitution"]["ok"], true);
  EXPECT_EQ(j["substitution"]["walls"], 1);
  EXPECT_TRUE(j["replacements"].empty());
  ASSERT_EQ(j["facades"].size(), 1u);
  EXPECT_EQ(j["facades"][0]["evidence"], "scan");
  EXPECT_NEAR(j["facades"][0]["max_move"].get<double>(), 0.4, 0.02);
  EXPECT_EQ(j["judgement"]["ok"], true);
  EXPECT_EQ(j["judgement"]["check"], "");
  EXPECT_LT(j["judgement"]["building"]["rms_after"].get<double>(), 0.05);
  EXPECT_GT(j["judgement"]["building"]["rms_before"].get<double>(), 0.3);
  EXPECT_GT(j["judgement"]["building"]["better"].get<std::size_t>(),
            j["judgement"]["building"]["worse"].get<std::size_t>());
  ASSERT_EQ(j["judgement"]["walls"].size(), 1u);
  EXPECT_EQ(j["output_validation"]["valid"], true);
  EXPECT_EQ(j["faces"], r.trace.faces);
  // Every stage has its lap, the judge and the output validation too: the laps add up to the total.
  double laps = 0.0;
  for (const char* stage : {"repair", "planes", "matching", "substitution", "selection", "judge", "validation"}) {
    EXPECT_TRUE(j["seconds"].contains(stage)) << stage;
    laps += j["seconds"].value(stage, 0.0);
  }
  EXPECT_EQ(j["seconds"].size(), 8u);  // and the total
  EXPECT_NEAR(laps, j["seconds"]["total"].get<double>(), 1e-3);
  // The selection chose every output face, starting from the substituted shell.
  const auto& sel = j["selection"];
  EXPECT_EQ(sel["status"], "optimal");
  EXPECT_EQ(sel["faces_from_selection"], j["faces"]);
  EXPECT_GT(sel["candidates"].get<int>(), 6);
  // Candidates away from the moved wall are fixed to the starting shell; the edges decide the
  // rest (GLPK's columns, or faces the edge constraints force before it runs).
  EXPECT_GT(sel["variables"].get<int>() + sel["forced_candidates"].get<int>(), 0);
  EXPECT_EQ(sel["variables"].get<int>() > 0, sel["constraints"].get<int>() > 0);
  EXPECT_EQ(sel["gap"], 0.0);
  const std::string warm = sel["warm_start"];
  EXPECT_TRUE(warm == "accepted" || warm == "not needed") << warm;
  for (const char* key :
       {"seconds", "scan_planes_added", "step_walls", "fixed_candidates", "forced_candidates", "candidates_changed"})
    EXPECT_TRUE(sel.contains(key)) << key;
}

TEST(RefineReport, ABuildingStoppedAtRepairHasOnlyWhatItReached) {
  Scene s;
  // Two opposite walls: no weld closes a shell, nor do their planes (nothing across their ends).
  s.model.faces = {s.model.faces[2], s.model.faces[4]};
  const RefineResult r = refine_building(s.model, s.scan, RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::KeptInvalid);
  const nlohmann::json j = refine_report(r);
  EXPECT_EQ(j["outcome"], "kept-invalid");
  EXPECT_EQ(j["reason"], r.reason);
  EXPECT_FALSE(r.reason.empty());
  for (const char* key :
       {"repair", "cloud", "planes", "matches", "substitution", "replacements", "judgement", "selection"})
    EXPECT_FALSE(j.contains(key)) << key;
  ASSERT_TRUE(j.contains("rebuild"));
  EXPECT_EQ(j["rebuild"]["ok"], false);
  EXPECT_EQ(j["rebuild"]["why"], r.trace.invalid_input);
  EXPECT_EQ(j["seconds"].size(), 3u);  // repair, validation, total
  EXPECT_EQ(j["faces"], 2u);
}

TEST(RefineReport, ValidationJsonNamesTheProblem) {
  Validation v;
  v.boundary_edges = 3;
  v.problem = "3 boundary edges";
  const nlohmann::json j = validation_json(v);
  EXPECT_EQ(j["valid"], false);
  EXPECT_EQ(j["watertight"], false);
  EXPECT_EQ(j["boundary_edges"], 3);
  EXPECT_EQ(j["problem"], "3 boundary edges");
}

TEST(RefineReport, ParamsJsonHasEveryRowByNameWithItsValue) {
  RefineConfig c;
  c.match.corner_gap = 0.75;
  c.plane.seed = 3;
  const nlohmann::json j = params_json(c);
  EXPECT_EQ(j.size(), param_table().size());
  for (const auto& p : param_table()) EXPECT_TRUE(j.contains(p.name)) << p.name;
  EXPECT_DOUBLE_EQ(j["corner_gap"].get<double>(), 0.75);
  EXPECT_TRUE(j["seed"].is_number_integer());
  EXPECT_EQ(j["seed"].get<int>(), 3);
}
