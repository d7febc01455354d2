// The coarse model's errors (internal to synth): facade lines moved and turned, then the export
// as a polygon soup with defects. Building frame.
#pragma once
#include <string>
#include <vector>

#include "shapes.h"

namespace lodrefine::synth {

// A wall of a generated shell, as the perturbations and the scan see it.
struct WallInfo {
  int face, line;
  Vec2 n;    // outward, horizontal
  Vec2 mid;  // middle of the wall's horizontal extent
  double length;
};

// The walls of a build_mesh shell (Face::source = footprint line), in face order.
std::vector<WallInfo> wall_infos(const Mesh& m);

// Moves 1..3 facade lines of `s` (indices into `walls`: mostly scanned ones, now and then a
// scanned one stays right, sometimes an unscanned one moves too) by options' shifts/rotations.
std::vector<MovedWall> move_facades(Spec& s, const std::vector<WallInfo>& walls, const std::vector<int>& scanned,
                                    const SynthOptions& o, Rng& r);

// The street-facade types (s.generalised non-empty): moves the generalised front line
// (s.coarse_front) by 0.1-0.6 m with the default options (no rotation: the detail the model
// lacks is the error under test), and with a chance of 1/4 another generalised line as
// move_facades does. The caller builds the coarse model from s.generalised.
std::vector<MovedWall> move_generalised(Spec& s, const std::vector<WallInfo>& walls, const std::vector<int>& scanned,
                                        const SynthOptions& o, Rng& r);

// The shell as an exporter writes it: every face with its own copy of its corners.
Mesh to_soup(const Mesh& m);

// Export defects applied to a soup in place (missing ground, mm gaps, a reversed or duplicated
// face, jittered roof corners); returns them as logged in meta.json, e.g. "reversed_face:7".
std::vector<std::string> add_defects(Mesh& s, Rng& r);

}  // namespace lodrefine::synth
