// What became of one building, as refine_building decides it (refine.h) and as the city
// refine, the evaluation and the gate read it back from reports: one enum, named only where
// written (outcome_name) and checked where read (parse_outcome).
#pragma once
#include <optional>
#include <string>

namespace lodrefine {

// "refined": walls moved, validated, and never worse: the scan points near the building and
// each moved wall's own points fit better than before (judge.h);
// "kept": the repaired input (nothing to change, or the judge refused the refinement);
// "repaired": as kept, but the input was no valid solid and its shell was rebuilt on its own
// planes (rebuild_shell, shell_rebuild.h): faces added, split or dropped, nothing moved;
// "kept-invalid": the input cannot be made a valid solid and the output is it as read.
// Never from refine_building: "untouched", a building of a city file that the cloud does not
// reach, written exactly as read (cityfile.h); "failed", a building of an evaluated run whose
// refinement left no model to measure (eval/run.h, eval/gate.h).
enum class Outcome { Refined, Kept, Repaired, KeptInvalid, Untouched, Failed };
const char* outcome_name(Outcome outcome);
// The outcome outcome_name() calls `name`; none for any other text (what outcomes read back
// from reports and files are checked with).
std::optional<Outcome> parse_outcome(const std::string& name);

}  // namespace lodrefine
