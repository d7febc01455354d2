// The JSON report of one refined building (`lodrefine refine --report`), built from the
// pipeline's result after the fact: what every stage found, the outcome and its reason.
#pragma once
#include <nlohmann/json.hpp>

#include "lodrefine/core/refine.h"
#include "lodrefine/core/validate.h"

namespace lodrefine {

// The report's format version, written as its top-level `report_version` (an integer). Raise it
// when a key eval reads (outcome, reason, facades, seconds, selection) changes meaning or name;
// `lodrefine eval` refuses reports of a newer version than this.
constexpr int kRefineReportVersion = 1;

// Keys: report_version, id, origin, outcome, reason, refined, faces, seconds, output_validation, and as far as
// the building got: repair, input_validation, cloud, planes, matches, rejected_matches,
// q_model, substitution, replacements, facades, judgement (never worse: ok, the refusing check
// and why, the building's and each moved wall's fit). The command adds model, cloud.path,
// params, written and warnings.
nlohmann::json refine_report(const RefineResult& result);

nlohmann::json validation_json(const Validation& v);

// Every parameter's value by name (flat, the CLI's snake_case names): a report's "params".
nlohmann::json params_json(const RefineConfig& config);

}  // namespace lodrefine
