// End to end on generated buildings of every type with known truth: the refined model is a
// valid closed shell, the scanned facades sit on the truth, the roofs are kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace {

double median_abs(std::vector<double> d) {
  for (auto& x : d) x = std::abs(x);
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d.empty() ? 0.0 : d[d.size() / 2];
}

struct Pooled {
  double sq = 0.0;
  std::size_t n = 0;
  void add(const std::vector<double>& d) {
    for (double x : d) sq += x * x;
    n += d.size();
  }
  double rms() const { return n ? std::sqrt(sq / double(n)) : 0.0; }
};

class EndToEnd : public ::testing::TestWithParam<BuildingType> {};

}  // namespace

TEST_P(EndToEnd, ScannedFacadesLandOnTheTruthAndTheShellIsValid) {
  Pooled facade_after, facade_before;
  for (std::uint64_t seed = 11; seed < 14; ++seed) {
    SynthOptions opt;
    opt.target_points = 20000;
    const SynthBuilding b = make_building(GetParam(), seed, opt);
    const RefineResult r = refine_building(b.coarse, b.cloud, RefineConfig{});
    SCOPED_TRACE(b.id + ": " + outcome_name(r.outcome));
    ASSERT_TRUE(r.valid);
    const Vec3 o = local_origin(b.truth);
    const Mesh refined = translated(r.mesh, -o), truth = translated(b.truth, -o), coarse = translated(b.coarse, -o);
    const Validation v = validate_mesh(refined, kPlanarity);
    EXPECT_TRUE(v.valid()) << v.problem;
    EXPECT_EQ(r.mesh.id, b.coarse.id);

    // Each scanned truth wall: most of it lies on the refined surface (corners next to an
    // unscanned, misplaced wall may legitimately stay off).
    for (int f : b.scanned_truth_faces) {
      const auto samples = sample_faces(truth, {f}, 0.25);
      const auto after = cloud_to_mesh(refined, samples);
      EXPECT_LT(median_abs(after), 0.02) << "truth face " << f;
      facade_after.add(after);
      facade_before.add(cloud_to_mesh(coarse, samples));
    }
    // Roofs: where the generator's roof planes meet the moved walls the eaves move; the roofs'
    // median distance to the truth stays small and never grows much past the coarse model's.
    std::vector<int> roofs;
    for (int f = 0; f < int(truth.faces.size()); ++f)
      if (truth.faces[f].sem == Semantic::Roof) roofs.push_back(f);
    const auto roof_samples = sample_faces(truth, roofs, 0.5);
    const double roof_after = median_abs(cloud_to_mesh(refined, roof_samples));
    const double roof_before = median_abs(cloud_to_mesh(coarse, roof_samples));
    // Known limit: a hip corner where two moved walls meet two roof planes keeps no roof plane
    // exactly (the corner would need a new edge); its roof may drift up to 10 cm there.
    const double roof_limit = GetParam() == BuildingType::Hip ? 0.10 : 0.05;
    EXPECT_LT(roof_after, std::max(roof_limit, roof_before + 0.02)) << "coarse roof median " << roof_before;
    // Semantics survive: walls, roofs and a ground.
    int walls = 0, roof = 0, ground = 0;
    for (const auto& face : refined.faces) {
      walls += face.sem == Semantic::Wall;
      roof += face.sem == Semantic::Roof;
      ground += face.sem == Semantic::Ground;
    }
    EXPECT_GE(walls, 3);
    EXPECT_GE(roof, 1);
    EXPECT_GE(ground, 1);
  }
  std::printf("%s: scanned-facade RMSE to truth %.4f m -> %.4f m\n", building_type_name(GetParam()),
              facade_before.rms(), facade_after.rms());
  EXPECT_LT(facade_after.rms(), 0.08);
  EXPECT_LT(facade_after.rms(), facade_before.rms());
}

// The shape types, whose scanned walls the model has (moved): the street-facade types need faces
// the model lacks and are run by SelectionAddsFaces (test_selection_decides.cpp).
static std::vector<BuildingType> shape_types() {
  std::vector<BuildingType> out;
  for (auto t : all_building_types())
    if (!street_facade_type(t)) out.push_back(t);
  return out;
}

INSTANTIATE_TEST_SUITE_P(AllTypes, EndToEnd, ::testing::ValuesIn(shape_types()),
                         [](const auto& info) { return std::string(building_type_name(info.param)); });

TEST(EndToEndDeterminism, SameInputSameOutput) {
  const SynthBuilding b = make_building(BuildingType::Gable, 5);
  const RefineResult r1 = refine_building(b.coarse, b.cloud, RefineConfig{});
  const RefineResult r2 = refine_building(b.coarse, b.cloud, RefineConfig{});
  ASSERT_EQ(r1.mesh.vertices.size(), r2.mesh.vertices.size());
  for (std::size_t i = 0; i < r1.mesh.vertices.size(); ++i) EXPECT_EQ(r1.mesh.vertices[i], r2.mesh.vertices[i]);
}
