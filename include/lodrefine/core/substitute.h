// Stage 4, substitution: the first choice of starting shell. A matched wall takes its scan plane and every
// vertex it carries is re-solved against the planes of the other walls at that vertex, at its
// own height (or, where the scan shows the eave moved with the roof, along the roof's plane).
// The model keeps its topology, ids and semantics; flat roofs, ridges and the ground keep their
// heights.
// Where that is not possible (a wall moved past a short neighbour, walls that no longer meet
// in one point) it says so, and the caller falls back to the local candidate arrangement.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/matching.h"

namespace lodrefine {

struct WallMove {
  int surface = -1;  // index into the model surfaces
  Plane plane;       // its new plane (oriented like the wall)
  // Where the wall carries a pitched roof: true slides the eave along the roof's plane (the
  // roof plane is right, the footprint was wrong), false keeps the eave's height (the roof
  // outline is right, its pitch follows the wall).
  bool follow_roof = false;
};

struct SubstitutionResult {
  bool ok = false;
  std::string reason;  // why not, when !ok
  Mesh mesh;           // the moved model (closed, same faces; split where needed); moved walls' faces Provenance::Scan
  int moved_vertices = 0;
  int split_faces = 0;         // faces that no longer were planar and were triangulated
  double max_vertex_move = 0;  // (m)
};

// `surfaces` are model_surfaces(mesh). Vertices on no moved wall keep their exact position.
SubstitutionResult substitute_walls(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                    const std::vector<WallMove>& moves, double planarity_tolerance);

// Whether the scan shows a moved wall's eave where its pitched roof's plane meets the new wall
// `plane` (the roof plane was right: WallMove::follow_roof) rather than at the old eave height
// (the roof outline was right): the top of the wall's own points (`m.owned`, indices into
// `cloud`) decides, and only where it clearly does.
bool eave_follows_roof(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const Match& m, const Plane& plane,
                       const PointCloud& cloud);

}  // namespace lodrefine
