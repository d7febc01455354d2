// The simulated MLS crop (internal to synth): which walls a street-side van scans, and the
// points it records on them with windows, occlusion holes and street clutter. Building frame.
#pragma once
#include <vector>

#include "perturb.h"

namespace lodrefine::synth {

// A street-side run of 1..k adjacent walls, the first one picked by length (indices into walls).
std::vector<int> choose_scanned(const Mesh& m, const std::vector<WallInfo>& walls, int k, Rng& r);

// The truth faces of walls[chosen].
std::vector<int> wall_faces(const std::vector<int>& chosen, const std::vector<WallInfo>& walls);

struct ScanResult {
  std::vector<Vec3> pts;    // facade points first, then clutter, ground and neighbours
  std::vector<int> labels;  // per point, as SynthBuilding::point_label
  double spacing = 0.0;     // facade sampling grid step (m)
};

// Scans the truth's walls `faces` (ground at z0) with o.target_points on the facades before
// nuisances, range noise o.noise, and with o.nuisances windows, holes and clutter.
ScanResult simulate_scan(const Mesh& truth, const std::vector<int>& faces, double z0, const SynthOptions& o, Rng& r);

}  // namespace lodrefine::synth
