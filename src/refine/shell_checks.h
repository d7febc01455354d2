// Internal to core: an assembled shell checked before it is written (the selection's and the
// rebuild's): whether it validates, which changes from the start put solid where the scan saw
// through, and its vertices put back on the start's where they only approximate them.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/refine/candidates.h"

namespace lodrefine::detail {

// The changed candidates (`changed`, per candidate) of the connected pieces that put solid where
// the scan saw through: at least PlaneEvidence::ransac_min_points of `evidence` (the supporting
// planes' points) more than 0.5 m inside `shell` though not inside `start`, nearest the piece.
std::vector<int> enclosing_changes(const CandidateSet& cs, const std::vector<char>& changed, const Mesh& start,
                                   const Mesh& shell, const std::vector<Vec3>& evidence, const PlaneEvidence& prm);

// Output vertices within this (m) of a starting-shell vertex are put back on it: the plane meets
// of the arrangement only approximate a model that is planar within tolerance, and where the
// selection changed nothing a roof must not move by that. Used only when the shell still
// validates after it.
inline constexpr double kSnapBack = 0.03;
// `m` with its vertices within kSnapBack of a vertex of `start` put on it (those snapped to one start
// vertex become one; faces left with fewer than 3 vertices dropped).
Mesh snapped_to_start(const Mesh& m, const Mesh& start);
// Why an assembled shell cannot be written, or empty: validate_mesh's problem, or a face that
// passes through one vertex twice.
std::string shell_problem(const Mesh& m, const RepairConfig& prm);

}  // namespace lodrefine::detail
