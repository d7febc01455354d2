// What `lodrefine eval` writes of evaluated buildings (run.h): the paper's Table 1 as text, the
// tile table (JSON rows, CSV) worst first, the run's outcome totals, the HTML page's table rows
// and views, and the figures the regression gate compares (gate.h). Text in, text out: the caller
// writes the files.
#pragma once
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/core/params.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/tools/gate.h"
#include "lodrefine/tools/report.h"
#include "lodrefine/tools/run.h"

namespace lodrefine {

// Count, largest and mean displacement (m) of moved facades (NaN when none moved).
struct MovedSummary {
  std::size_t count = 0;
  double max = std::numeric_limits<double>::quiet_NaN(), mean = std::numeric_limits<double>::quiet_NaN();
};
MovedSummary summarize_moved(const std::vector<MovedFacade>& moved);

// Outcome counts by outcome_name ("refined", "kept", "failed" always present; the others, e.g.
// "repaired", "kept-invalid", when a row has them) and moved facades over a run,
// and the refine seconds summed over the buildings that recorded them.
struct RunTotals {
  std::map<std::string, std::size_t> outcomes{{"refined", 0}, {"kept", 0}, {"failed", 0}};
  MovedSummary moved;
  double refine_seconds = 0.0;
};
RunTotals run_totals(const std::vector<RunRow>& rows);

// Worst first: failed, then not watertight after refinement, then by refined C2M RMSE (largest
// first, unmeasured last), then by id. Pointers into `rows`.
std::vector<const RunRow*> worst_first(const std::vector<RunRow>& rows);

// The paper's Table 1 (pooled over points; `batch` adds the mean of per-building values), as
// printed: "-" for what was not measured.
std::string table1_text(const PooledEval& pooled, bool batch);
// "\noutcomes: refined N, kept N, failed N; facades moved N (max X m, mean X m); refine S s in all\n",
// with ", <outcome> N" after "failed N" for each other outcome counted (in Outcome's order).
std::string totals_text(const RunTotals& totals);

// `eval --json`: {"pooled": {... figures, outcomes, facades_moved, refine_seconds_total},
// "buildings": [row per building, in `order`], "params": params, "run_dir": run_dir (when not
// empty)}. Centroids in the input frame (each row's origin added back).
nlohmann::json run_json(const std::vector<const RunRow*>& order, const PooledEval& pooled, const RunTotals& totals,
                        const nlohmann::json& params, const std::string& run_dir);
// `eval --csv`: a header and one line per row, in `order`; fields with , " or newline quoted.
std::string csv_text(const std::vector<const RunRow*>& order);

// The per-building table of the HTML page: its columns ([[key, heading], ...]) and one row.
const nlohmann::json& html_columns();
nlohmann::json html_row(const RunRow& row);
// The 3D + footprint view of one building, read again from its files (measured again when its
// per-point series were dropped: the evaluation is deterministic). Throws InputError when its
// inputs cannot be read.
BuildingView html_view(const RunRow& row, const RefineConfig& params);

// A row's figures for the gate: its outcome as refine decided it (failed without one).
BuildingFigures building_figures(const RunRow& row);
RunFigures run_figures(const std::vector<RunRow>& rows, const PooledEval& pooled);

}  // namespace lodrefine
