#include "lodrefine/core/outcome.h"

namespace lodrefine {

const char* outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::Refined: return "refined";
    case Outcome::Kept: return "kept";
    case Outcome::Repaired: return "repaired";
    case Outcome::KeptInvalid: return "kept-invalid";
    case Outcome::Untouched: return "untouched";
    case Outcome::Failed: return "failed";
  }
  return "?";
}

Outcome decide_outcome(const OutcomeFacts& facts) {
  switch (facts.ending) {
    case Ending::Untouched: return Outcome::Untouched;
    case Ending::NoModel: return Outcome::Failed;
    case Ending::AsRead: return Outcome::KeptInvalid;
    case Ending::Refined:
    case Ending::Kept: break;
  }
  if (!facts.valid) return Outcome::KeptInvalid;  // no output is written that does not validate
  if (facts.ending == Ending::Refined) return Outcome::Refined;
  return facts.mended ? Outcome::Repaired : Outcome::Kept;
}

std::optional<Outcome> parse_outcome(const std::string& name) {
  for (Outcome o :
       {Outcome::Refined, Outcome::Kept, Outcome::Repaired, Outcome::KeptInvalid, Outcome::Untouched, Outcome::Failed})
    if (name == outcome_name(o)) return o;
  return std::nullopt;
}

}  // namespace lodrefine
