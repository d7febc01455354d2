// A selection of candidates mended into the nearest closed one (shell_mend.h), on the box
// 10 x 8 x 6's arrangement.
#include <gtest/gtest.h>

#include <algorithm>

#include "refine/shell_mend.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::detail;
using namespace lodrefine::fixtures;

namespace {

constexpr double kA = 10, kB = 8, kC = 6;

std::vector<char> box_selection(const CandidateSet& cs) {
  std::vector<char> out;
  for (int f = 0; f < cs.size(); ++f) out.push_back(char(inside_box(centroid_of(cs, f), kA, kB, kC)));
  return out;
}

}  // namespace

TEST(ShellMend, AClosedSelectionIsItsOwnNearest) {
  CandidateSet cs = build_candidates(box_planes(kA, kB, kC), box_region(kA, kB, kC));
  const auto box = box_selection(cs);
  ASSERT_EQ(std::count(box.begin(), box.end(), 1), 6);
  EXPECT_EQ(nearest_closed_selection(cs, box, SelectionConfig{}), box);
}

TEST(ShellMend, AMissingFaceIsAddedBackNotTheRestDropped) {
  CandidateSet cs = build_candidates(box_planes(kA, kB, kC), box_region(kA, kB, kC));
  const auto box = box_selection(cs);
  // Without its roof (80 m²) the box leaves 4 edges used once: adding the roof back costs 80,
  // dropping the five other faces 248.
  std::vector<char> open = box;
  for (int f = 0; f < cs.size(); ++f)
    if (box[std::size_t(f)] && centroid_of(cs, f).z() > kC - 1e-9) open[std::size_t(f)] = 0;
  ASSERT_EQ(std::count(open.begin(), open.end(), 1), 5);
  EXPECT_EQ(nearest_closed_selection(cs, open, SelectionConfig{}), box);
  // A selection of the roof alone: dropping it (80) is nearer than adding the walls and ground.
  std::vector<char> roof(box.size(), 0);
  for (int f = 0; f < cs.size(); ++f) roof[std::size_t(f)] = char(box[std::size_t(f)] && !open[std::size_t(f)]);
  EXPECT_EQ(nearest_closed_selection(cs, roof, SelectionConfig{}, {true, 1.0}), std::vector<char>(box.size(), 0));
  // Weighted 10x, keeping the roof wins: the box closes around it.
  EXPECT_EQ(nearest_closed_selection(cs, roof, SelectionConfig{}, {true, 10.0}), box);
}

TEST(ShellMend, FaceFlagsReadABooleanMap) {
  CandidateSet cs = build_candidates(box_planes(kA, kB, kC), box_region(kA, kB, kC));
  auto map = candidate_props::in_start.add(cs.mesh);
  const auto box = box_selection(cs);
  for (int f = 0; f < cs.size(); ++f) map[CandidateFace(f)] = box[std::size_t(f)] != 0;
  EXPECT_EQ(face_flags(cs, map), box);
}
