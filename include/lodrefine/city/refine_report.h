// The JSON report of one refined building (`lodrefine refine --report`), built from the
// pipeline's result after the fact: what every stage found, the outcome and its reason.
#pragma once
#include <nlohmann/json.hpp>

#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine {

// The report's format version, written as its top-level `report_version` (an integer). Raise it
// when a key eval reads (outcome, reason, facades, seconds, selection) changes meaning or name;
// `lodrefine eval` refuses reports of a newer version than this.
constexpr int kRefineReportVersion = 1;

// Keys: report_version, lodrefine_version (the program's, LODREFINE_VERSION), id, origin, outcome, reason, refined,
// faces, seconds, output_validation, and as far as the building got: repair, input_validation, cloud, planes, matches,
// rejected_matches, q_model, substitution, replacements, facades, judgement (never worse: ok, the refusing check and
// why, the building's and each moved wall's fit). The command adds model, cloud.path, params, written and warnings.
nlohmann::json refine_report(const RefineResult& result);

// A validation: watertight, valid, problem (the first defect in words), the counts, and
// `errors`: each defect as val3dity reports one (validity_errors_json).
nlohmann::json validation_json(const Validation& v);

// Defects as a val3dity report lists them: {"code": 302, "description": "SHELL_NOT_CLOSED",
// "id": "face=3" (the first face it concerns; "" for the shell), "info": the words}, plus
// "faces" (every face it concerns, indices of the geometry's surfaces) when there are any.
nlohmann::json validity_errors_json(const std::vector<ValidityError>& errors);

// One building of a city file's run, as refine --report and repair --report list it: id,
// outcome, reason, facades_moved, refused_by, points, seconds, errors_before, errors_after.
nlohmann::json city_outcome_json(const CityBuildingOutcome& outcome);

// Every parameter's value by name (flat, the CLI's snake_case names): a report's "params".
nlohmann::json params_json(const RefineConfig& config);

}  // namespace lodrefine
