// The dev tiles (../shared/devtiles: buildings from an independent generator and real Rotterdam
// LoD2 geometry, with ground truth) as a regression gate: every building gets a valid output,
// none fits its truth worse than its coarse model, and the pooled truth-facade RMSE stays low.
// The project's judge is the tiles' own score.py; this is the same kind of measure in-process
// (truth walls the scan saw, sampled, to the model). Skips where ../shared is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "lodrefine/base/geometry.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/refine/refine.h"
#include "support/cli_fixtures.h"
#include "support/fins_fixtures.h"
#include "support/schema_fixtures.h"
#include "support/test_paths.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace fs = std::filesystem;

namespace {

fs::path tiles_dir() { return fs::path(test_paths::source_dir()) / ".." / "shared" / "devtiles"; }

struct Sums {
  double before = 0, after = 0;
  std::size_t n = 0;
};

void run_tile(const std::string& tile, double max_pooled_rmse) {
  const fs::path dir = tiles_dir() / tile;
  if (!fs::is_directory(dir / "models")) GTEST_SKIP() << dir << " absent";
  Sums pooled;
  int buildings = 0;
  std::vector<fs::path> models;
  for (const auto& e : fs::directory_iterator(dir / "models")) models.push_back(e.path());
  std::sort(models.begin(), models.end());
  for (const auto& path : models) {
    const std::string id = path.stem().string();
    const Mesh coarse = read_obj(path.string());
    const Mesh truth = read_obj((dir / "truth" / (id + ".obj")).string());
    const PointCloud cloud = read_ply((dir / "clouds" / (id + ".ply")).string());
    const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
    SCOPED_TRACE(id + ": " + outcome_name(r.outcome) + " (" + r.reason + ")");
    ++buildings;
    EXPECT_NE(r.outcome, Outcome::KeptInvalid);
    const Vec3 o = local_origin(truth);
    const Mesh t = translated(truth, -o), c = translated(coarse, -o), m = translated(r.mesh, -o);
    EXPECT_TRUE(validate_mesh(m, kPlanarity).valid()) << validate_mesh(m, kPlanarity).problem;
    std::vector<Vec3> pts;
    for (const auto& p : cloud.points) pts.push_back(p - o);
    const auto samples = sample_faces(t, scanned_walls(t, pts, 0.05, 50), 0.25);
    if (samples.empty()) continue;
    double sb = 0, sa = 0;
    for (double d : cloud_to_mesh(c, samples)) sb += d * d;
    for (double d : cloud_to_mesh(m, samples)) sa += d * d;
    const double rb = std::sqrt(sb / samples.size()), ra = std::sqrt(sa / samples.size());
    std::printf("%s %-18s %-10s facade %.3f -> %.3f m\n", tile.c_str(), id.c_str(), outcome_name(r.outcome), rb, ra);
    EXPECT_LE(ra, rb + 0.005) << "made worse";
    pooled.before += sb;
    pooled.after += sa;
    pooled.n += samples.size();
  }
  ASSERT_GT(pooled.n, 0u);
  const double before = std::sqrt(pooled.before / pooled.n), after = std::sqrt(pooled.after / pooled.n);
  std::printf("%s: %d buildings, truth facade RMSE %.3f -> %.3f m\n", tile.c_str(), buildings, before, after);
  EXPECT_LT(after, max_pooled_rmse);
}

}  // namespace

// Bounds a little above what the current method reaches by this measure (2026-12-01: synth 0.003 m,
// real 0.067 m; every truth wall with cloud points on it counts, neighbours' included, so the
// figures differ from score.py's 0.019 / 0.029 m): a regression in matching, corners or
// substitution shows here before it reaches a user.
// 0.03 m: the synth tile's unscanned side walls are misplaced too, and its scans show no return
// at the corners (the facade's points just end), which is no evidence to move them (issue 17).
TEST(DevTiles, Synth) { run_tile("synth", 0.03); }
TEST(DevTiles, Real) { run_tile("real", 0.08); }

// The dev city tile refined, and its output refined again with the same scan (re-refining a
// district with a newer scan is an ordinary job): every fin of either output stands on its
// solid. Before, the second pass read the Solids alone and wrote refinements that left the
// first pass's fins off them.
TEST(DevTiles, CityRefinedTwiceKeepsEveryFinOnItsSolid) {
  const fs::path dir = tiles_dir() / "city";
  if (!fs::exists(dir / "coarse.city.json")) GTEST_SKIP() << dir << " absent";
  const std::string out = cli_fixtures::test_dir("lodrefine_devtiles_city");
  CityRefineOptions options;
  options.jobs = 2;
  std::string in = (dir / "coarse.city.json").string();
  for (int pass = 1; pass <= 2; ++pass) {
    const std::string written = out + "/pass" + std::to_string(pass) + ".city.json";
    const CityRefineSummary s = refine_city(in, {(dir / "tile.ply").string()}, written, RefineConfig{}, options);
    std::ifstream file(written);
    const fixtures::FinsInFile fins = fixtures::fins_in_file(nlohmann::ordered_json::parse(file));
    std::printf(
        "city pass %d: %d refined, %d repaired, %d kept, %d kept-invalid; %d building(s) with fins, the "
        "farthest %.4f m apart from its solid (%s)\n",
        pass, s.refined, s.repaired, s.kept, s.kept_invalid, fins.buildings, fins.apart, fins.worst_id.c_str());
    EXPECT_LE(fins.apart, RefineConfig{}.repair.weld_tolerance) << "pass " << pass << ": " << fins.worst_id;
    in = written;
  }
}

// The dev city tile (real Rotterdam buildings in their city file, a generated scan): every
// semantic surface of every refined or repaired building says where it comes from (with its
// coverage when the scan's), no other building carries the attributes (they are written as
// read), and the file still passes the CityJSON 2.0.2 schemas.
TEST(DevTiles, CityTileSaysWhereEachSurfaceComesFrom) {
  const fs::path dir = tiles_dir() / "city";
  if (!fs::exists(dir / "coarse.city.json")) GTEST_SKIP() << dir << " absent";
  const fs::path out = fs::path(cli_fixtures::test_dir("lodrefine_devtiles_city")) / "provenance.city.json";
  CityRefineOptions options;
  options.jobs = 2;
  const CityRefineSummary sum =
      refine_city((dir / "coarse.city.json").string(), {(dir / "tile.ply").string()}, out.string(), {}, options);
  ASSERT_GT(sum.refined, 0);
  std::ifstream in(out);
  const nlohmann::json doc = nlohmann::json::parse(in);
  int refined = 0, surfaces = 0, scan = 0;
  for (const auto& [id, obj] : doc["CityObjects"].items()) {
    const std::string outcome = obj.contains("attributes") ? obj["attributes"].value("lodrefine_outcome", "") : "";
    const bool written = outcome == "refined" || outcome == "repaired";
    refined += outcome == "refined";
    for (const auto& g : obj.value("geometry", nlohmann::json::array())) {
      if (!g.contains("semantics")) continue;
      for (const auto& s : g["semantics"]["surfaces"]) {
        SCOPED_TRACE(id + " (" + outcome + "): " + s.dump());
        if (!written) {
          EXPECT_FALSE(s.contains("lodrefine_source"));
          continue;
        }
        ++surfaces;
        ASSERT_TRUE(s.contains("lodrefine_source"));
        const std::string source = s["lodrefine_source"];
        EXPECT_TRUE(source == "scan" || source == "model" || source == "added");
        EXPECT_EQ(s.contains("lodrefine_coverage"), source == "scan");
        if (source != "scan") continue;
        ++scan;
        EXPECT_GE(s["lodrefine_coverage"].get<double>(), 0.0);
        EXPECT_LE(s["lodrefine_coverage"].get<double>(), 1.0);
      }
    }
  }
  std::printf("dev city: %d refined, %d repaired; %d semantic surfaces of theirs, %d from the scan\n", refined,
              sum.repaired, surfaces, scan);
  EXPECT_EQ(refined, sum.refined);
  EXPECT_GT(scan, 0);
  const std::string verdict = schema_fixtures::schema_verdict(out.string());
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
}
