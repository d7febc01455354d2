// Internal to core: the supporting planes a soup's holes need (shell_rebuild), after its own
// (add_start_planes, shell_supports.h), and whether it stands on a ground plane.
#pragma once
#include "lodrefine/base/types.h"
#include "shell_supports.h"

namespace lodrefine::detail {

// The planes a soup's holes need to close (after add_start_planes): the vertical plane through each
// boundary edge (an edge of one face; through a vertical one, whose plan length is under 5 cm,
// across the wall's end) unless a supporting plane carries it already (within kSurfaceAngleDeg,
// and kSurfaceDistance of both ends: matching.h). Each is a wall of provenance added, without
// scan points; counted in Supports::hole_planes.
void add_hole_planes(const Mesh& soup, Supports& s);
// Whether a supporting plane lies on the soup's lowest level, horizontal, across its whole box:
// the ground its walls stand on.
bool carries_ground(const Mesh& soup, const Supports& s);

}  // namespace lodrefine::detail
