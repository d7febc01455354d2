// The shared value types' names (src/base/types.cpp): semantics and provenance to and from the
// words the writers and readers use, and OutOfMemory's message kept in a fixed buffer.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "lodrefine/base/types.h"

using namespace lodrefine;

TEST(Types, SemanticNamesAreCityGmlsAndReadBack) {
  EXPECT_STREQ(semantic_name(Semantic::Wall), "WallSurface");
  EXPECT_STREQ(semantic_name(Semantic::Roof), "RoofSurface");
  EXPECT_STREQ(semantic_name(Semantic::Ground), "GroundSurface");
  EXPECT_STREQ(semantic_name(Semantic::Other), "OtherSurface");
  for (Semantic s : {Semantic::Wall, Semantic::Roof, Semantic::Ground, Semantic::Other})
    EXPECT_EQ(semantic_from_name(semantic_name(s)), s) << semantic_name(s);
}

TEST(Types, SemanticFromAGroupNameIsACaseFreeSubstring) {
  EXPECT_EQ(semantic_from_name("g_FACADE_3"), Semantic::Wall);
  EXPECT_EQ(semantic_from_name("wall-8"), Semantic::Wall);
  EXPECT_EQ(semantic_from_name("Dak_ROOF"), Semantic::Roof);
  EXPECT_EQ(semantic_from_name("floor"), Semantic::Ground);
  EXPECT_EQ(semantic_from_name("GROUND scan"), Semantic::Ground);
  EXPECT_EQ(semantic_from_name("ClosureSurface"), Semantic::Other);
  EXPECT_EQ(semantic_from_name(""), Semantic::Other);
}

TEST(Types, ProvenanceIsOneWordOfTheGroup) {
  EXPECT_STREQ(provenance_name(Provenance::Model), "model");
  EXPECT_STREQ(provenance_name(Provenance::Scan), "scan");
  EXPECT_STREQ(provenance_name(Provenance::Added), "added");
  EXPECT_STREQ(provenance_name(Provenance::None), "");
  EXPECT_EQ(provenance_from_group("WallSurface scan"), Provenance::Scan);
  EXPECT_EQ(provenance_from_group("RoofSurface\tmodel"), Provenance::Model);
  EXPECT_EQ(provenance_from_group("added WallSurface"), Provenance::Added);
  // A word, not a substring: "scanned" and "models" name no provenance.
  EXPECT_EQ(provenance_from_group("WallSurface scanned models"), Provenance::None);
  EXPECT_EQ(provenance_from_group("WallSurface"), Provenance::None);
  EXPECT_EQ(provenance_from_group(""), Provenance::None);
}

TEST(Types, OutOfMemoryKeepsItsMessageCutToItsBuffer) {
  const OutOfMemory short_one("cloud.ply: out of memory");
  EXPECT_STREQ(short_one.what(), "cloud.ply: out of memory");
  const std::string long_message(2000, 'x');
  const OutOfMemory cut(long_message);
  EXPECT_EQ(std::strlen(cut.what()), 511u);
  EXPECT_EQ(std::string(cut.what()), long_message.substr(0, 511));
  const std::bad_alloc& as_bad_alloc = cut;  // main's exit 3 catches it as such
  EXPECT_EQ(std::string(as_bad_alloc.what()).size(), 511u);
}

TEST(Types, WithCornersKeepsEverythingButTheCorners) {
  Face f;
  f.v = {0, 1, 2};
  f.sem = Semantic::Wall;
  f.source = 4;
  f.provenance = Provenance::Scan;
  f.coverage = 0.75;
  const Face g = with_corners(f, {3, 4, 5, 6});
  EXPECT_EQ(g.v, (std::vector<int>{3, 4, 5, 6}));
  EXPECT_EQ(g.sem, Semantic::Wall);
  EXPECT_EQ(g.source, 4);
  EXPECT_EQ(g.provenance, Provenance::Scan);
  EXPECT_DOUBLE_EQ(g.coverage, 0.75);
}
