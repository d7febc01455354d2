// The walls one refinement moves, as refine_building hands them from stage to stage. Each stage
// takes what it needs of the plan as a value passed to it; the trace (RefineTrace) only records
// what each stage made, and no stage reads its input from it.
//
//   matching (match_surfaces, outdated walls)  makes  surfaces, scan
//   corners (corner_moves)                     makes  corners
//   substitution (the starting shell)          takes  surfaces, scan, corners; makes moved
//   selection (select_shell)                   takes  surfaces, scan (its warm start when no
//                                                     substitution made a starting shell)
//   judge (judge_refinement)                   takes  moved (judged_walls)
//
// The judge's retries hand the plan on again with fewer moves: without the corners, then
// without each scan move whose own wall the judge refused (SubstitutedWall::scan_surface names
// it; a wall the one-at-a-time fallback moved is named by its input faces, which the fallback
// then leaves where they are: MovePlan::refused_faces).
// All geometry is in the building's local frame (refine_building's), in metres.
#pragma once
#include <set>
#include <vector>

#include "lodrefine/core/corners.h"
#include "lodrefine/core/judge.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/substitute.h"

namespace lodrefine {

// A wall the starting shell moved, described on the mesh it was moved on, before the move.
struct SubstitutedWall {
  JudgedWall wall;  // its faces before the move and its planes: what the judge judges
  // The surface (index into MovePlan::surfaces) of the scan move that moved it; -1 for a corner
  // move and for a wall the one-at-a-time fallback moved (that one re-matches on each new shell,
  // so its surfaces are not the plan's).
  int scan_surface = -1;
  std::set<int> input_faces;  // the input faces (Face::source) it descends from
};

struct MovePlan {
  // model_surfaces() of the shell the moves are made on (the repaired input, merged), at its
  // default tolerances; every WallMove::surface below indexes it.
  std::vector<ModelSurface> surfaces;
  std::vector<WallMove> scan;       // outdated walls onto their scan planes (oriented like the wall)
  std::vector<CornerMove> corners;  // unscanned walls to where the scan shows their corner
  // What the starting shell moved, in order (the scan moves, then the corners; or the fallback's
  // walls one at a time); empty when no starting shell was made.
  std::vector<SubstitutedWall> moved;
  // Input faces (Face::source) of walls the judge refused: the one-at-a-time fallback moves no
  // wall holding one of them.
  std::set<int> refused_faces;
};

// The judge's input: the walls of `plan.moved`, in order (Judgement::wall indexes both).
inline std::vector<JudgedWall> judged_walls(const MovePlan& plan) {
  std::vector<JudgedWall> out;
  out.reserve(plan.moved.size());
  for (const SubstitutedWall& m : plan.moved) out.push_back(m.wall);
  return out;
}

}  // namespace lodrefine
