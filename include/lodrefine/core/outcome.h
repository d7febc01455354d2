// What became of one building, decided once (decide_outcome) by refine_building (refine.h), and
// by the city refine and the evaluation only for what the core cannot know (a building no scan
// point reaches, a run's building with no model); the city refine, the evaluation and the gate
// report it and read it back from reports: one enum, named only where written (outcome_name) and
// checked where read (parse_outcome).
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

// How the handling of a building ended, before its output is checked: what decide_outcome takes.
enum class Ending {
  Refined,    // the judge accepted a refinement
  Kept,       // the (repaired) input stands: nothing to change, or the refinement was refused
  AsRead,     // the input cannot be made a valid solid, or its handling failed: written as read
  Untouched,  // not handled: a city file's building the cloud does not reach, or one found valid
              // as read by lodrefine repair (cityfile.h)
  NoModel,    // a building of an evaluated run whose refinement left no model to measure
};

struct OutcomeFacts {
  Ending ending = Ending::AsRead;
  // The input was no valid solid and the output is it made one: its shell rebuilt on its own
  // planes (refine_building), or a city file's building invalid as read that its repair alone
  // made valid to val3dity's tolerances (lodrefine repair, cityfile.h).
  bool mended = false;
  bool valid = false;  // the output passed validation (validate_mesh)
};

// The one rule that names a building's outcome, for refine_building, the city refine and the
// evaluated run alike: an ending of Untouched is untouched, NoModel failed, AsRead kept-invalid;
// otherwise an output that does not validate is kept-invalid (its input is written as read), a
// refinement is refined, and a kept input is repaired when it was mended, else kept.
Outcome decide_outcome(const OutcomeFacts& facts);
const char* outcome_name(Outcome outcome);
// The outcome outcome_name() calls `name`; none for any other text (what outcomes read back
// from reports and files are checked with).
std::optional<Outcome> parse_outcome(const std::string& name);

}  // namespace lodrefine
