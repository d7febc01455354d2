// No option that changes nothing (issue 51): every parameter `lodrefine params` lists (the
// parameter table, which also makes the command line's options) set to a second value changes
// the refinement of a generated building where it applies: its output mesh or its report
// (timings aside). A new parameter needs a row in kSecondValues, or this test fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <sstream>
#include <string>
#include <type_traits>

#include "lodrefine/city/refine_report.h"
#include "lodrefine/core/params.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

namespace {

// Each parameter's second value: one that applies on the shed below (its default is the first).
const std::map<std::string, double> kSecondValues = {
    // repair
    {"weld_tolerance", 0.0},
    {"planarity_tolerance", 0.0001},
    // plane
    {"ransac", 0},
    {"seed", 7},
    {"ransac_epsilon", 0.06},
    {"ransac_cluster_epsilon", 1.0},
    {"ransac_normal_deg", 10.0},
    {"ransac_min_points", 1000},
    {"ransac_probability", 0.9},
    {"detect_voxel", 0.0},
    {"normal_neighbors", 30},
    {"min_plane_area", 20.0},
    {"facade_max_tilt_deg", 0.01},
    {"vertical_snap_deg", 0.0},
    // match
    {"change_tolerance", 1.0},
    {"match_angle_deg", 0.01},
    {"match_distance", 0.1},
    {"match_min_overlap", 0.99},
    {"match_margin", 5.0},
    {"corner_gap", 0.0},
    {"w_normal", 1.0},
    {"w_coverage", 1.0},
    // selection
    {"bbox_expand", 1.0},
    {"bbox_margin", 5.0},
    {"merge_angle_deg", 0.0},
    {"merge_distance", 2.0},
    {"tau_cov", 0.9},
    {"lambda_coverage", 10.0},
    {"lambda_data", 5.0},
    {"lambda_complexity", 5.0},
    {"mip_work_limit", 0.0},
    {"mip_time_limit", 0.001},  // GLPK stops at its first check (tm_lim - 1 ms elapsed)
    {"mip_gap", 1.0},
};

// The options that change nothing on some buildings say in their help when they apply, by these
// words. On a generated gable (`lodrefine synth --type gable --seed 5`) each of them at its second
// value above leaves the output and the report (timings aside) byte for byte the same.
const std::map<std::string, std::string> kAppliesOnlyWhere = {
    {"seed", "only with ransac 1"},
    {"ransac_probability", "only with ransac 1"},
    {"corner_gap", "only at a corner between two matched walls"},
    {"merge_angle_deg", "only where a scan facade lies near a start plane it was not moved onto"},
    {"merge_distance", "only where a scan facade lies near a start plane it was not moved onto"},
    {"lambda_data", "only where the coverage and complexity terms leave a choice"},
    {"mip_gap", "only where the search runs past the root"},
};

// The defaults with parameter `name` at `value`.
RefineConfig with(const std::string& name, double value) {
  RefineConfig c;
  for_each_field(c, [&](const auto& field, auto& v) {
    if (name == field.name) v = static_cast<std::remove_reference_t<decltype(v)>>(value);
  });
  return c;
}

// The report without its timings ("seconds", "*_seconds" at any depth), as snapshot.sh compares.
void drop_timings(nlohmann::json& j) {
  if (j.is_array())
    for (auto& x : j) drop_timings(x);
  if (!j.is_object()) return;
  for (auto it = j.begin(); it != j.end();) {
    const std::string& k = it.key();
    const bool timing = k == "seconds" || (k.size() > 8 && k.compare(k.size() - 8, 8, "_seconds") == 0);
    if (timing) {
      it = j.erase(it);
    } else {
      drop_timings(*it);
      ++it;
    }
  }
}

// What a refinement is: its report without the timings, and the output mesh to the last bit.
std::string fingerprint(const RefineResult& r) {
  nlohmann::json j = refine_report(r);
  drop_timings(j);
  std::ostringstream s;
  s.precision(17);
  s << j.dump() << '\n';
  for (const auto& v : r.mesh.vertices) s << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& f : r.mesh.faces) {
    for (int i : f.v) s << i << ' ';
    s << int(f.sem) << '\n';
  }
  return s.str();
}

}  // namespace

TEST(ParamsEffect, EveryParameterHasASecondValueInItsRange) {
  for (const auto& p : param_table()) {
    const auto it = kSecondValues.find(p.name);
    ASSERT_NE(it, kSecondValues.end()) << p.name << " has no second value here";
    EXPECT_NE(it->second, p.default_value) << p.name;
    EXPECT_GE(it->second, p.min) << p.name;
    EXPECT_LE(it->second, p.max) << p.name;
  }
  EXPECT_EQ(kSecondValues.size(), param_table().size()) << "a second value of no parameter";
}

TEST(ParamsEffect, EveryParameterChangesTheRefinement) {
  const SynthBuilding b = make_building(BuildingType::Shed, 5);
  const RefineResult base = refine_building(b.coarse, b.cloud, RefineConfig{});
  ASSERT_TRUE(base.refined()) << base.reason;
  const std::string first = fingerprint(base);
  for (const auto& p : param_table()) {
    const auto it = kSecondValues.find(p.name);
    if (it == kSecondValues.end()) continue;  // the test above fails
    const RefineResult r = refine_building(b.coarse, b.cloud, with(p.name, it->second));
    std::string option = p.name;
    std::replace(option.begin(), option.end(), '_', '-');
    EXPECT_TRUE(fingerprint(r) != first) << "--" << option << " " << it->second << " changes nothing";
  }
}

TEST(ParamsEffect, OptionsThatApplyOnlySomewhereSayWhereInTheirHelp) {
  for (const auto& [name, where] : kAppliesOnlyWhere) {
    const auto& table = param_table();
    const auto it = std::find_if(table.begin(), table.end(), [&](const auto& p) { return p.name == name; });
    ASSERT_NE(it, table.end()) << name << " is no parameter";
    EXPECT_NE(std::string(it->description).find("applies " + where), std::string::npos)
        << "--" << name << "'s help does not say it applies " << where << ": " << it->description;
  }
}
