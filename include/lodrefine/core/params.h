// Every method parameter, declared once with its stage, default, bounds and description.
// The table generates one config per stage (the knobs that stage reads, each with its range
// check), the CLI options, `lodrefine params` (docs) and the reports' "params".
#pragma once
#include <string>
#include <vector>

namespace lodrefine {

// One block per stage, in pipeline order; each row is X(type, name, default, min, max, description).
// The CLI option of a row is --kebab-case of its name; names are unique across stages.
#define LODREFINE_REPAIR_PARAMS(X)                                                                    \
  X(double, weld_tolerance, 0.01, 0.0, 1.0, "model repair: vertices closer than this are welded (m)") \
  X(double, planarity_tolerance, 0.01, 0.0, 1.0, "validation: max vertex distance from its face plane (m)")

#define LODREFINE_PLANE_PARAMS(X)                                                                                    \
  X(int, ransac, 1, 0, 1,                                                                                            \
    "1: planes by CGAL's Efficient RANSAC (the paper's); 0: by region growing on the same points, normals and "      \
    "thresholds (the same planes on the dev tiles, faster)")                                                         \
  X(int, seed, 42, 0, 2147483647,                                                                                    \
    "RANSAC random seed (runs are reproducible); applies only with ransac 1, and changes the planes only where "     \
    "Efficient RANSAC's random draws decide which planes it finds (a clearly scanned building's come out the same)") \
  X(double, ransac_epsilon, 0.03, 0.001, 1.0, "RANSAC: max point-to-plane distance of an inlier (m)")                \
  X(double, ransac_cluster_epsilon, 0.25, 0.01, 10.0, "RANSAC: max gap between connected inliers (m)")               \
  X(double, ransac_normal_deg, 25.0, 1.0, 90.0, "RANSAC: max angle between point normal and plane (deg)")            \
  X(int, ransac_min_points, 150, 3, 100000000, "RANSAC: min inliers of a plane")                                     \
  X(double, ransac_probability, 0.01, 1e-6, 1.0,                                                                     \
    "RANSAC: probability to miss the largest shape; applies only with ransac 1, and changes the planes only "        \
    "where the search's length decides which planes it finds (a clearly scanned building's come out the same)")      \
  X(double, detect_voxel, -1.0, -1.0, 1.0,                                                                           \
    "plane detection runs on one point per voxel of this size, then takes back every point near its planes (m; 0: "  \
    "all points; negative: sqrt(min_plane_area / (normal_neighbors + 1)), the largest voxel at which the smallest "  \
    "plane "                                                                                                         \
    "kept still holds a neighbourhood of representatives)")                                                          \
  X(int, normal_neighbors, 12, 3, 200, "neighbours for PCA normal estimation")                                       \
  X(double, min_plane_area, 1.0, 0.0, 1e6, "scan planes whose inlier hull is smaller are ignored (m^2)")             \
  X(double, facade_max_tilt_deg, 10.0, 0.0, 45.0,                                                                    \
    "scan plane counts as facade if its normal is within this of horizontal (deg)")                                  \
  X(double, vertical_snap_deg, 1.5, 0.0, 10.0,                                                                       \
    "facade planes tilted less than this are refitted exactly vertical (deg)")

#define LODREFINE_MATCH_PARAMS(X)                                                                                      \
  X(double, change_tolerance, 0.02, 0.0, 1.0,                                                                          \
    "a matched wall within this of its scan plane everywhere is kept as is (m)")                                       \
  X(double, match_angle_deg, 10.0, 0.0, 90.0, "matching hard filter: max angle between normals (deg)")                 \
  X(double, match_distance, 1.25, 0.0, 100.0,                                                                          \
    "matching hard filter: max distance of a wall to its scan points (m); airborne facades are decimetres to a metre " \
    "off")                                                                                                             \
  X(double, match_min_overlap, 0.2, 0.0, 1.0,                                                                          \
    "matching: min coverage of a wall by its points, the largest of the IoU of the wall's and the points' in-plane "   \
    "boxes and the share of either box inside the other")                                                              \
  X(double, match_margin, 0.5, 0.0, 10.0,                                                                              \
    "matching: scan points up to this far beyond a wall's outline (in its plane) still belong to it (m)")              \
  X(double, corner_gap, 0.6, 0.0, 100.0,                                                                               \
    "a wall match is rejected if the new corner lies farther than this beyond the adjacent scanned facade's points "   \
    "and its wall's end in the model (m); applies only at a corner between two matched walls")                         \
  X(double, w_normal, 0.5, 0.0, 1.0, "matching score weight of |S_normal|")                                            \
  X(double, w_coverage, 0.5, 0.0, 1.0, "matching score weight of the OBB IoU C_bbox")

#define LODREFINE_SELECTION_PARAMS(X)                                                                               \
  X(double, bbox_expand, 0.1, 0.0, 2.0, "relative expansion of the bounding box on each side")                      \
  X(double, bbox_margin, 1.0, 0.0, 100.0, "absolute expansion of the bounding box on each side (m)")                \
  X(double, merge_angle_deg, 5.0, 0.0, 30.0,                                                                        \
    "planes within this angle (and merge_distance) are merged (deg); applies only where a scan facade lies near a " \
    "start plane it was not moved onto (a wall kept within change_tolerance, a step)")                              \
  X(double, merge_distance, 0.05, 0.0, 5.0,                                                                         \
    "planes closer than this (and within merge_angle_deg) are merged (m); applies only where a scan facade lies "   \
    "near a start plane it was not moved onto (a wall kept within change_tolerance, a step)")                       \
  X(double, tau_cov, 0.3, 0.0, 1.0, "coverage threshold tau_cov: inflection of the sigmoid coverage cost")          \
  X(double, lambda_coverage, 1.0, 0.0, 1e6, "weight of the coverage term")                                          \
  X(double, lambda_data, 0.1, 0.0, 1e6,                                                                             \
    "weight of the data-fitting term (the scanned area a face's supporting points explain, each weighted by its "   \
    "fit to the face's plane); applies only where the coverage and complexity terms leave a choice between "        \
    "scanned candidates (a recess, a step); where they decide every face it changes nothing")                       \
  X(double, lambda_complexity, 0.2, 0.0, 1e6, "weight of the complexity (sharp edge) term")                         \
  X(double, mip_work_limit, 60.0, 0.0, 1e9,                                                                         \
    "GLPK work budget of a face selection (millions of tableau entries: rows + columns per simplex iteration, "     \
    "rows x columns per round of cuts; 60 is ~0.3 s of CPU; up to 4 budgets until a first selection is found); at " \
    "the budget the best selection found, at least the starting shell, is taken")                                   \
  X(double, mip_time_limit, 30.0, 0.001, 86400.0,                                                                   \
    "wall-clock safety ceiling of a face selection (s), far above what mip_work_limit takes; results that reach "   \
    "it depend on the machine's load")                                                                              \
  X(double, mip_gap, 1e-4, 0.0, 1.0,                                                                                \
    "GLPK relative MIP gap; applies only where the search runs past the root (a program whose relaxation is "       \
    "not integral there); one solved at its root is the same at any gap")

// S(Config, stage, what the stage does, rows). `stage` names the stage: its Config::stage, the
// RefineConfig member that holds its config, its CLI help group.
#define LODREFINE_STAGES(S)                                                                                     \
  S(RepairConfig, repair, "repair the exported soup into a closed shell, validate it", LODREFINE_REPAIR_PARAMS) \
  S(PlaneConfig, plane, "detect planes in the scan near the model (RANSAC)", LODREFINE_PLANE_PARAMS)            \
  S(MatchConfig, match, "match scan planes to walls; decide which walls are outdated", LODREFINE_MATCH_PARAMS)  \
  S(SelectionConfig, selection, "candidate faces and the GLPK program that selects the shell",                  \
    LODREFINE_SELECTION_PARAMS)

// Every row of every stage, in pipeline order.
#define LODREFINE_PARAMS(X)  \
  LODREFINE_REPAIR_PARAMS(X) \
  LODREFINE_PLANE_PARAMS(X) LODREFINE_MATCH_PARAMS(X) LODREFINE_SELECTION_PARAMS(X)

// One field of a stage config (roofer's ConfigField pattern): its name, stage, bounds and
// meaning, and the member it is (`config.*member`).
template <class Config, class T>
struct ConfigField {
  const char* name;   // snake_case; the CLI option is --kebab-case
  const char* type;   // "int" or "double"
  const char* stage;  // Config::stage
  T Config::*member;
  T default_value, min, max;
  const char* description;
};

#define LODREFINE_CONFIG_MEMBER(type, name, def, lo, hi, help) type name = def;
#define LODREFINE_CONFIG_VISIT(type, name, def, lo, hi, help) \
  visit(ConfigField<Self, type>{#name, #type, stage, &Self::name, type(def), type(lo), type(hi), help});
#define LODREFINE_CONFIG_STRUCT(Config, stage_name, what, ROWS)                      \
  struct Config {                                                                    \
    using Self = Config;                                                             \
    static constexpr const char* stage = #stage_name;                                \
    static constexpr const char* summary = what;                                     \
    ROWS(LODREFINE_CONFIG_MEMBER)                                                    \
    /* Calls visit(ConfigField) for each row, in table order. */                     \
    template <class Visitor>                                                         \
    static void visit_fields(Visitor&& visit) {                                      \
      ROWS(LODREFINE_CONFIG_VISIT)                                                   \
    }                                                                                \
    /* Throws InputError "<stage>: parameter <name> = <v> is outside [min, max]". */ \
    void validate() const;                                                           \
  };
LODREFINE_STAGES(LODREFINE_CONFIG_STRUCT)
#undef LODREFINE_CONFIG_STRUCT
#undef LODREFINE_CONFIG_VISIT
#undef LODREFINE_CONFIG_MEMBER

// What other stages read of the plane stage's rows, named here once (each row keeps its
// meaning): a point within ransac_epsilon of a scan plane lies on it (a RANSAC inlier's
// farthest), and ransac_min_points such points are a scanned surface (a plane's fewest). The
// match stage's corner_moves and judge_refinement take it beside their MatchConfig, the
// selection's test for enclosed scan points alone; a PlaneConfig converts to it. (The other
// borrowed value is RefineConfig::scan_reach.)
struct PlaneEvidence {
  double ransac_epsilon;
  int ransac_min_points;
  PlaneEvidence(const PlaneConfig& plane)
      : ransac_epsilon(plane.ransac_epsilon), ransac_min_points(plane.ransac_min_points) {}
};

// The whole method's configuration: one member per stage, named after it
// (`config.plane.ransac_epsilon`). A stage function takes its own config (`detect_planes(cloud,
// config.plane)`), so its signature says which knobs it reads; a function that reads several
// stages' (the orchestrator, the selection of the whole shell) takes the RefineConfig.
struct RefineConfig {
#define LODREFINE_STAGE_MEMBER(Config, stage, what, rows) Config stage;
  LODREFINE_STAGES(LODREFINE_STAGE_MEMBER)
#undef LODREFINE_STAGE_MEMBER

  // The scan's reach around the model (m): a wall off by up to match_distance, plus the
  // selection's bbox_margin (a bay). The cloud is cropped to it (with bbox_expand), and the
  // selection's scan supports and evidence zone and the judge's facade lines reach that far.
  double scan_reach() const { return match.match_distance + selection.bbox_margin; }

  // Every stage's fields (ConfigFields of that stage's config), stage by stage in pipeline order.
  template <class Visitor>
  static void visit_fields(Visitor&& visit) {
#define LODREFINE_STAGE_VISIT(Config, stage, what, rows) Config::visit_fields(visit);
    LODREFINE_STAGES(LODREFINE_STAGE_VISIT)
#undef LODREFINE_STAGE_VISIT
  }
  // Each stage's validate() (the error names the stage), then the rules across rows.
  void validate() const;
};

// visitor(field, value) for each field of `config`, a stage config (its ConfigFields' members
// are its own)...
template <class Config, class Visitor>
void for_each_field(const Config& config, Visitor&& visitor) {
  Config::visit_fields([&](const auto& field) { visitor(field, config.*(field.member)); });
}
template <class Config, class Visitor>
void for_each_field(Config& config, Visitor&& visitor) {
  Config::visit_fields([&](const auto& field) { visitor(field, config.*(field.member)); });
}
// ... or the RefineConfig: each stage's, stage by stage in pipeline order.
#define LODREFINE_STAGE_FIELDS(Config, stage, what, rows) for_each_field(config.stage, visitor);
template <class Visitor>
void for_each_field(const RefineConfig& config, Visitor&& visitor) {
  LODREFINE_STAGES(LODREFINE_STAGE_FIELDS)
}
template <class Visitor>
void for_each_field(RefineConfig& config, Visitor&& visitor) {
  LODREFINE_STAGES(LODREFINE_STAGE_FIELDS)
}
#undef LODREFINE_STAGE_FIELDS

// Read-only description of one parameter, for CLI and docs.
struct ParamInfo {
  std::string name;   // snake_case field name; the CLI option is --kebab-case
  std::string type;   // "int" or "double"
  std::string stage;  // the stage config it belongs to ("plane", "match", ...)
  double default_value;
  double min, max;
  std::string description;
};
// Every row, stage by stage in pipeline order.
const std::vector<ParamInfo>& param_table();

struct StageInfo {
  std::string name;     // Config::stage
  std::string summary;  // what the stage does
};
// The stages, in pipeline order.
const std::vector<StageInfo>& stage_table();

}  // namespace lodrefine
