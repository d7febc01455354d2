// The regression gate of a CI job: a run's figures stored as a baseline, a later run compared
// with it (a figure worse beyond a tolerance, an outcome worse, a building gone), absolute gates
// read from a small JSON file, and the verdict as JUnit XML that CI servers show per building.
// Plain data in, text out: the caller (lodrefine eval) fills the figures and writes the files.
#pragma once
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/core/outcome.h"

namespace lodrefine {

// What a run measured of one building, refined model side. Distances in metres; an absent value
// was not measured (no facade points, no truth, a failed building).
struct BuildingFigures {
  std::string id;
  Outcome outcome = Outcome::Failed;                         // refined, kept, kept-invalid or failed (best to worst)
  std::string reason;                                        // why kept / failed (informative only)
  std::optional<double> c2m_rmse, c2m_mae;                   // facade points to the refined model
  std::optional<double> truth_facade_rmse, truth_roof_rmse;  // truth samples to the refined model
  bool watertight = false;                                   // the refined model
  std::size_t facades_moved = 0;
  std::optional<double> moved_max;  // largest facade displacement
};

// A run: its buildings (any order; ids unique) and the pooled figures (over all facade points /
// truth samples of all buildings, as `lodrefine eval` pools them).
struct RunFigures {
  std::vector<BuildingFigures> buildings;
  std::size_t failed = 0, refined = 0;
  double watertight_rate = 0.0;  // refined models, 0..1
  std::optional<double> c2m_rmse_original, c2m_rmse, c2m_mae, truth_facade_rmse, truth_roof_rmse;
};

// Rank of an outcome, higher is better: refined 3, kept or repaired 2, kept-invalid 1, failed (or
// untouched) 0.
int outcome_rank(Outcome outcome);

// The baseline file: {"format": "lodrefine-baseline", "version": 1, "pooled": {...},
// "buildings": [{...}]}, absent figures as null. Strings that are not UTF-8 are written with
// U+FFFD in place of the bad bytes.
std::string baseline_json(const RunFigures& run);
// Reads baseline_json()'s output back. Throws InputError (one line naming `source`) on anything
// else: not JSON, another format or version, a building without an id, a repeated id.
RunFigures read_baseline(const std::string& text, const std::string& source);

// Absolute limits, by name (see gate_names()): keys "max_*" are upper and "min_*" lower bounds.
// Pooled ones give one check each; "max_building_*" apply to every building.
using Gates = std::map<std::string, double>;
// The known gate names, each with what it bounds.
const std::map<std::string, std::string>& gate_names();
// A JSON object of gate name -> number; keys starting with "_" are comments. Throws InputError
// (one line naming `source`) on an unknown name, a value that is not a finite number, or
// anything but an object.
Gates read_gates(const std::string& text, const std::string& source);

// One line of the verdict, e.g. "b12: c2m_rmse 0.012 m -> 0.301 m (worse by 0.289 m, tolerance
// 0.005 m)". `building` is empty for a pooled line; `check` names the pooled check it belongs to
// ("baseline" or a gate name).
struct GateLine {
  std::string building, check, figure, text;
};

struct GateVerdict {
  std::vector<std::string> buildings;      // every building of the run, then the missing ones, sorted
  std::vector<std::string> new_buildings;  // in the run, not in the baseline (listed, never failed)
  std::vector<std::string> pooled_checks;  // "baseline" (with a baseline) and each gate that is not per building
  std::vector<GateLine> failures;          // regressions and breaches, in check order
  bool failed() const { return !failures.empty(); }
};

// Compares `run` with `baseline` (when given; `tolerance` in metres applies to every distance)
// and checks `gates` (when given). A building fails when its outcome got worse (then its figures
// are not compared), a distance grew by more than the tolerance, a figure the baseline measured
// is no longer measured, it is no longer watertight, a per-building gate is breached, or it is in
// the baseline but not in the run. Pooled: the same figures, the failed count and the
// watertight rate against the baseline, and each pooled gate (a gate on a figure the run did not
// measure is breached).
GateVerdict check_run(const RunFigures& run, const RunFigures* baseline, const Gates* gates, double tolerance);

// JUnit XML of a verdict: a <testsuite name="buildings"> with one <testcase> per building and a
// <testsuite name="pooled"> with one per pooled check; a failing one holds <failure message=
// "its first line"> with all its lines. New buildings pass with a <system-out> note.
std::string junit_xml(const GateVerdict& verdict, const std::string& name);

// `s` as XML 1.0 character data or attribute value: & < > " ' and tab / newline / carriage
// return as references; bytes that are not UTF-8 and characters XML 1.0 does not allow (other
// control characters, U+FFFE/FFFF, surrogates) become U+FFFD.
std::string xml_escape(const std::string& s);

}  // namespace lodrefine
