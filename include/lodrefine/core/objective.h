// The selection program's costs per candidate face (paper Sec. 3.4). A candidate's confidence
// (0..1) is the pipeline's: describe_candidates (shell_supports.h) measures it on the scan's
// occupancy of the candidate and the starting shell's prior.
#pragma once

namespace lodrefine {

// The paper's sigmoid coverage cost of a face of area `area` (m^2) and confidence `c` (0..1)
// at the coverage threshold `tau` (0..1, SelectionConfig::tau_cov):
// A * (1 / (1 + exp(-(1 - c) + (1 - tau))) - 0.5); negative (a reward) above tau, 0 at tau.
double coverage_cost(double area, double c, double tau);

}  // namespace lodrefine
