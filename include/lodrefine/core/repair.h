// Stage 1, repair: turning an exported polygon soup into a clean closed polyhedron: weld, dedupe, fix
// T-junctions, orient consistently outward, fill a missing ground, merge coplanar neighbours.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

struct RepairReport {
  int input_vertices = 0, input_faces = 0;
  int welded_vertices = 0;           // vertex count removed by welding
  int removed_degenerate_faces = 0;  // < 3 distinct vertices or ~zero area
  int removed_duplicate_faces = 0;
  int split_t_junctions = 0;   // vertices inserted into edges that passed through them
  int flipped_faces = 0;       // faces reversed to make the orientation consistent/outward
  int filled_holes = 0;        // boundary loops closed with a new face (missing ground ...)
  int split_warped_faces = 0;  // faces split by split_warped_faces
  bool closed = false;         // closed 2-manifold after repair
  std::vector<std::string> notes;
};

// Repairs `soup` (any frame; use a local one for georeferenced data). Throws InputError when
// nothing usable remains (e.g. < 4 faces, or a non-closable shape). Face::sem and Face::source
// are carried over; filled holes get Semantic::Ground if they are horizontal facing down,
// Semantic::Roof if horizontal facing up, else the semantic of their neighbours (by shared edge
// length), and Provenance::Added (Face::provenance: the other faces keep theirs). A hole planar
// within 2 cm becomes one face, a non-planar one is triangulated (noted).
// Welding joins the closest pairs first: vertices of different faces within
// max(weld_tolerance, gap_tolerance) (export gaps, jittered corners), two vertices of one face
// only within weld_tolerance, so a face's own short edges never collapse.
Mesh repair_model(const Mesh& soup, double weld_tolerance, RepairReport* report = nullptr, double gap_tolerance = 0.0);

// The soup welded as repair_model welds it at `weld_tolerance`, its degenerate and duplicate faces
// dropped and its T-junctions split; nothing closed, filled or oriented. What a rebuild
// (shell_rebuild.h) reads when the soup cannot be made a valid solid. Throws InputError for a
// vertex that is not finite or a face with a missing vertex.
Mesh welded_soup(const Mesh& soup, double weld_tolerance, RepairReport* report = nullptr);

// Orients the faces of a closed mesh with shared vertices consistently (across manifold edges)
// and outward (each edge-connected component encloses a positive volume); no vertex moves.
// Returns how many faces were reversed.
int orient_outward(Mesh& mesh);

// The repair of a building's input for the pipeline: a ladder of welds (see repair.cpp), the
// first whose shell is valid (validate_mesh at params.planarity_tolerance) wins, else the first
// that closed at all; warped faces come back split into triangles (counted in `report`).
// Throws InputError (the first weld's) when no weld closes a shell.
Mesh repair_input(const Mesh& soup, const RepairConfig& config, RepairReport& report);

// Splits every face farther than `tolerance` from planar into triangles, keeping its semantic
// and source; no vertex moves. Ear clipping, unless one of its diagonals is already an edge of
// the mesh (a sliver the face shares with a neighbour): then a fan around a new vertex at the
// face's centre. Returns how many faces were split.
int split_warped_faces(Mesh& mesh, double tolerance);

// Merges edge-adjacent coplanar faces of the same semantic into single polygons (within
// `angle_deg` / `distance`), removing the then-redundant collinear vertices. Input must be a
// closed oriented mesh with shared vertices; so is the output.
// The defaults merge only what is coplanar up to the rounding of a refined model: half a degree
// and 5 mm, half the default planarity tolerance, so a merged polygon still validates.
constexpr double kCoplanarMergeAngleDeg = 0.5;
constexpr double kCoplanarMergeDistance = 0.005;  // m
Mesh merge_coplanar_faces(const Mesh& mesh, double angle_deg = kCoplanarMergeAngleDeg,
                          double distance = kCoplanarMergeDistance);

}  // namespace lodrefine
