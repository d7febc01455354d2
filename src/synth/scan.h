// The simulated MLS crop (internal to synth): which walls a street-side van scans, and the
// points it records on them with windows, occlusion holes and street clutter. Building frame.
#pragma once
#include <vector>

#include "perturb.h"

namespace lodrefine::synth {

// A street-side run of 1..k adjacent walls, the first one picked by length (indices into walls).
std::vector<int> choose_scanned(const Mesh& m, const std::vector<WallInfo>& walls, int k, Rng& r);

// The street-facade types: every wall on a `street` footprint line (the front, a recess's back
// wall and returns, a bay's front and sides), and with a chance of 0.4 one side wall next to them.
std::vector<int> choose_street(const Mesh& m, const std::vector<WallInfo>& walls, const std::vector<int>& street,
                               Rng& r);

// The truth faces of walls[chosen].
std::vector<int> wall_faces(const std::vector<int>& chosen, const std::vector<WallInfo>& walls);

struct ScanResult {
  std::vector<Vec3> pts;    // facade points first, then clutter, ground and neighbours
  std::vector<int> labels;  // per point, as SynthBuilding::point_label
  double spacing = 0.0;     // facade sampling grid step (m)
};

// Scans the truth's walls `faces` (ground at z0) with o.target_points on the facades before
// nuisances, range noise o.noise, and with o.nuisances windows, holes and clutter. Each wall is
// scanned from its own front, except with a `street` (the street-facade types' outward front
// normal; zero for the others): walls turned more than 45 degrees from it (returns, bay sides)
// are seen from the street, obliquely: fewer points at grazing angles, none the building hides.
// Clutter stands only in front of the walls the van drives along.
ScanResult simulate_scan(const Mesh& truth, const std::vector<int>& faces, double z0, const Vec2& street,
                         const SynthOptions& o, Rng& r);

}  // namespace lodrefine::synth
