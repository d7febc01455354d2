// Stage 5, selection: the output shell traced on the candidate mesh (candidates.h) from the faces the
// selection chose, as CGAL's Polygonal_surface_reconstruction reads its model off the hypothesis:
// no geometric weld and no repair pass.
// - Vertices are the mesh's: a corner of a chosen face is its vertex's point (candidate_props::point,
//   one point for every component through it); a chosen edge shorter than kCollapsedEdge joins
//   its two ends.
// - Which chosen faces meet along a segment, and in which direction each runs along it, comes
//   from its fan of halfedges (CandidateSet::edges). Each face is its candidate, CCW about its
//   supporting plane's normal or reversed: neighbours across a fan of two chosen faces run along
//   it in opposite directions, and each such connected part encloses a positive volume.
// - Chosen neighbours on one supporting plane (a fan of two chosen faces, both on it) become one
//   polygon when their outline is one simple loop (else they stay apart); a corner then used by
//   only two faces lies on the line of their planes' meet and is dropped.
#pragma once
#include "lodrefine/base/types.h"

namespace lodrefine {

struct CandidateSet;  // candidates.h

// Chosen edges shorter than this (m) are a point: planes meeting almost at a point leave edges
// of fractions of a millimetre, which CityJSON's millimetre grid or a reader's weld collapses.
constexpr double kCollapsedEdge = 1e-3;

// The polygon mesh of the candidates chosen in `cs.mesh`'s candidate_props::selected (bool, required: the
// selection's answer, select_faces).
// Per output face: the semantic and provenance of its supporting plane (CandidateSet::planes[].sem,
// .provenance) and the source in the face map candidate_props::source (int, optional: -1 without
// it); a merged polygon takes its largest piece's. Vertex positions are CandidateSet::vertices (same frame). The mesh
// is closed, 2-manifold and outward when the selection uses every edge 0 or 2 times and its pieces meet only along
// edges; it is not validated here (validate_mesh). Precondition: `cs` comes from build_candidates or kept_candidates
// (its mesh holds the faces).
Mesh traced_shell(const CandidateSet& cs);

}  // namespace lodrefine
