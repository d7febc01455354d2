// The one rule naming a building's outcome (decide_outcome), its names, and refine_building
// reporting what the rule decides.
#include <gtest/gtest.h>

#include <initializer_list>

#include "lodrefine/core/outcome.h"
#include "lodrefine/refine/refine.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

constexpr std::initializer_list<Outcome> kEveryOutcome = {Outcome::Refined,     Outcome::Kept,      Outcome::Repaired,
                                                          Outcome::KeptInvalid, Outcome::Untouched, Outcome::Failed};

Outcome decided(Ending ending, bool mended, bool valid) { return decide_outcome({ending, mended, valid}); }

}  // namespace

// A handled building's output that validates: a refinement is refined (also on a rebuilt input),
// a kept input is repaired when it was mended, else kept.
TEST(Outcome, AValidOutputIsRefinedRepairedOrKept) {
  EXPECT_EQ(decided(Ending::Refined, false, true), Outcome::Refined);
  EXPECT_EQ(decided(Ending::Refined, true, true), Outcome::Refined);
  EXPECT_EQ(decided(Ending::Kept, false, true), Outcome::Kept);
  EXPECT_EQ(decided(Ending::Kept, true, true), Outcome::Repaired);
}

// No output that does not validate is written as refined, repaired or kept: it is kept-invalid
// (the city refine and the evaluation had their own copy of this rule).
TEST(Outcome, AnOutputThatDoesNotValidateIsKeptInvalid) {
  for (bool mended : {false, true}) {
    EXPECT_EQ(decided(Ending::Refined, mended, false), Outcome::KeptInvalid);
    EXPECT_EQ(decided(Ending::Kept, mended, false), Outcome::KeptInvalid);
  }
}

// The endings that say it all, whatever the output: as read, untouched (a city file's building no
// scan point reaches), no model (a run's building refine left nothing to measure).
TEST(Outcome, EndingsThatNameTheOutcomeWhateverTheOutput) {
  for (bool mended : {false, true})
    for (bool valid : {false, true}) {
      EXPECT_EQ(decided(Ending::AsRead, mended, valid), Outcome::KeptInvalid);
      EXPECT_EQ(decided(Ending::Untouched, mended, valid), Outcome::Untouched);
      EXPECT_EQ(decided(Ending::NoModel, mended, valid), Outcome::Failed);
    }
  EXPECT_EQ(decide_outcome({}), Outcome::KeptInvalid);  // the default facts: as read
}

TEST(Outcome, NamesReadBackAsTheSameOutcome) {
  for (Outcome o : kEveryOutcome) EXPECT_EQ(parse_outcome(outcome_name(o)), o) << outcome_name(o);
  EXPECT_EQ(std::string(outcome_name(Outcome::KeptInvalid)), "kept-invalid");
  EXPECT_FALSE(parse_outcome("Refined").has_value());
  EXPECT_FALSE(parse_outcome("").has_value());
}

// refine_building's result carries the rule's outcome for what it found: a valid box the scan does
// not reach is kept (valid, not mended), a model beyond the size bounds kept-invalid as read.
TEST(Outcome, RefineBuildingReportsTheRulesOutcome) {
  Mesh model = box(Vec3(0, 0, 0), Vec3(10, 8, 6));
  model.id = "b";
  PointCloud far;
  for (int i = 0; i < 100; ++i) far.points.push_back(Vec3(500.0 + 0.1 * i, 0.0, 0.0));
  const RefineResult kept = refine_building(model, far, RefineConfig{});
  EXPECT_TRUE(kept.valid);
  EXPECT_EQ(kept.outcome, decided(Ending::Kept, false, true));
  EXPECT_EQ(kept.outcome, Outcome::Kept);

  Mesh huge = model;
  huge.faces.front().v.resize(1001, huge.faces.front().v.front());  // a face of 1,001 corners
  const RefineResult refused = refine_building(huge, far, RefineConfig{});
  EXPECT_EQ(refused.outcome, decided(Ending::AsRead, false, refused.valid));
  EXPECT_EQ(refused.mesh.faces.front().v.size(), 1001u);  // written as read
}
