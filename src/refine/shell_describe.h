// Internal to core: what the selection's program knows of each candidate (stage 5,
// shell_selection.h), measured on the starting shell and the supports' scan points: in the
// start, its source, its confidence (objective.h: face_confidence on the occupancy grid), whether
// evidence reaches it, and the scanned area its supporting points explain (the data-fitting
// term's fit, m²).
#pragma once
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/refine/candidates.h"
#include "shell_supports.h"

namespace lodrefine::detail {

using FaceIndex = CandidateMesh::Face_index;

// The face map `in` of a candidate set on the candidates kept_candidates(that set, keep): the
// map `property` added to their mesh `to`, each kept face's value carried.
template <class T>
CandidateMap<T> carried(const CandidateMap<T>& in, const CandidateFaceProperty<T>& property, CandidateMesh& to,
                        const std::vector<char>& keep) {
  auto out = property.add(to);
  int g = 0;
  for (std::size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) out[FaceIndex(g++)] = in[FaceIndex(f)];
  return out;
}

// What the program knows of each candidate, as face property maps of the candidate mesh (their
// names: candidate_props): in_start (the starting shell has a face there), source (that face's
// source, -1 without one; traced_shell gives it to the output's faces), confidence (the data
// term's c), in_zone (scan evidence reaches it), fit (the data-fitting term's scanned area it
// explains, m²). Added once (describe_candidates) and carried whole to the kept candidates. The
// selection adds its own maps (variable, selected).
struct FaceProps {
  CandidateMap<bool> in_start;
  CandidateMap<int> source;
  CandidateMap<double> confidence;
  CandidateMap<bool> in_zone;
  CandidateMap<double> fit;

  // The maps added to `mesh`, every face at each map's unset value.
  static FaceProps add(CandidateMesh& mesh) {
    return {candidate_props::in_start.add(mesh), candidate_props::source.add(mesh),
            candidate_props::confidence.add(mesh), candidate_props::in_zone.add(mesh), candidate_props::fit.add(mesh)};
  }
  // The same maps on `to`, the mesh of kept_candidates(this mesh's set, keep), with the kept
  // faces' values.
  FaceProps carried_to(CandidateMesh& to, const std::vector<char>& keep) const {
    return {carried(in_start, candidate_props::in_start, to, keep), carried(source, candidate_props::source, to, keep),
            carried(confidence, candidate_props::confidence, to, keep),
            carried(in_zone, candidate_props::in_zone, to, keep), carried(fit, candidate_props::fit, to, keep)};
  }
};

// Each candidate's FaceProps, from the starting shell `start` and the supports `s`.
FaceProps describe_candidates(CandidateSet& cs, const Mesh& start, const Supports& s, const RefineConfig& prm);

}  // namespace lodrefine::detail
