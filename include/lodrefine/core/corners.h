// Stage 3, matching: corners from the scan's extent. A scanned facade ends where the building's corner
// is; when it ends short of the model's corner (or runs on a little past it, then stops), the
// adjacent wall that was not scanned is misplaced, and moves so that the corner is where the
// scan says. Evidence must hold over the facade's height (an occluding car or tree does not),
// and the scan must show the corner, one of:
//  - the return: points on the side wall's new plane where the facade's points end;
//  - an open end on a facade the scan itself moves by decimetres: the street scanned on past the
//    end, nothing in front hiding the facade there, no facade beyond, and the end off the model's
//    own corner edge (there the scan agrees with the model). Open ends look the same
//    where a scan of a correct neighbour was cut off, so they count only on a building the scan
//    already shows mis-modelled.
//  - a party wall on a facade the scan moves by decimetres that runs on, flush, into a
//    neighbour's: where the neighbour's points above this wall's top start (a taller neighbour)
//    or this wall's own points above the neighbour's end (a lower one), the same over 2 m of
//    height. Those points past the moved wall are the neighbour's (the judge leaves them out).
// A scan that just stops (tile or crop edge, occlusion shadow, the vehicle turning) or a
// neighbour's facade running on past the outline, alone, moves no wall.
#pragma once
#include <optional>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/substitute.h"

namespace lodrefine {

struct ScannedWall {
  int surface = -1;  // model surface
  int scan_plane = -1;
  Plane plane;  // the scan plane oriented like the wall
};

struct CornerMove {
  WallMove move;        // the unscanned adjacent wall and its new plane
  int scanned_surface;  // the scanned wall whose extent shows the corner
  double shift = 0.0;   // how far the corner moves along the scanned facade (m, + outwards)
  // Set when the scanned facade runs on into a flush neighbour's and the party wall showed the
  // corner: the facade's plane, whose points past the moved wall are the neighbour's.
  std::optional<Plane> flush_facade;
};

// A point within this of a scan plane lies on it (m): the plane's noise band (two RANSAC
// epsilons), at least the corners' tolerance of 5 cm.
double on_plane_band(const PlaneEvidence& detection);

// Street ground: points lower than this above the building's foot (m). Corners count them to see
// the street go on past a facade's end; the judge leaves them out (ground in front of a wall
// moved inwards would count against a right move).
constexpr double kStreetGroundBand = 0.3;

std::vector<CornerMove> corner_moves(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                     const std::vector<ScannedWall>& scanned, const PointCloud& cloud,
                                     const std::vector<ScanPlane>& planes, const MatchConfig& match,
                                     const PlaneEvidence& detection);

}  // namespace lodrefine
