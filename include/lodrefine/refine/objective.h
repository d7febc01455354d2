// The selection program's costs (paper Sec. 3.4; PolyFit's objective): every term of what the
// binary program over the candidates minimises, in one place. select_faces (selection.h) only
// solves: it takes SelectionProgram::cost and ::sharp_cost as the columns' coefficients.
//
// All costs are in m² (a face's area, an edge's length times a width), so the weights of
// SelectionConfig (params.h: lambda_coverage, lambda_data, lambda_complexity, tau_cov) compare
// like with like whatever the region's size. Negative is a reward: the program selects a face
// whose cost is below what closing the shell around it costs.
//
// Per candidate face (candidate_cost):
// - coverage: the paper's sigmoid of the face's confidence (coverage_cost);
// - prior: the confidence of a face the starting shell has (face_confidence);
// - data fitting: the scanned area its supporting points explain (PolyFit's supporting points,
//   fit_weight each), subtracted.
// Per candidate edge: complexity, a cost when the edge is sharp (two selected faces of different
// planes meet there: sharp_edge_cost; uniform_sharp_cost where a program gives none).
// Mending a selection (nearest_closed_selection) has its own objective: the changed area
// (mend_cost).
#pragma once
#include <vector>

#include "lodrefine/core/params.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/selection.h"

namespace lodrefine {

// The coverage term of a face of area `area` (m²) and confidence `c` (0..1) at the coverage
// threshold `tau` (0..1, SelectionConfig::tau_cov), the paper's sigmoid:
// A * (1 / (1 + exp(-(1 - c) + (1 - tau))) - 0.5); negative (a reward) above tau, 0 at tau, m².
double coverage_cost(double area, double c, double tau);

// The confidence c (0..1) of a candidate face: the share `scanned` (0..1) of its area that its
// plane's scan points cover (an occupancy grid), or, where the starting shell has a face
// (`in_start`), the model's prior: 1 less the share `contradicted` (0..1) of its area before or
// behind which the scan shows another parallel facade, whichever is larger. Rewards a scanned
// face and an unscanned face of the model alike; a model face the scan saw elsewhere loses it.
double face_confidence(double scanned, double contradicted, bool in_start);

// The data-fitting weight (0..1) of one supporting point at distance `distance` (m) from its
// candidate's plane: 1 - (distance / tolerance)^2, 0 beyond `tolerance` (fit_tolerance).
double fit_weight(double distance, double tolerance);
// The distance (m) at which a point stops explaining a plane: a RANSAC inlier's farthest
// (PlaneConfig::ransac_epsilon) plus how far a supporting plane may lie from the points merged
// onto it (SelectionConfig::merge_distance).
double fit_tolerance(const RefineConfig& config);

// A candidate's objective coefficient: lambda_coverage * coverage_cost(area, c, tau_cov) -
// lambda_data * `fit` (the scanned area its supporting points explain, the sum of their
// fit_weight times the scanned area a point stands for, m²). Rewards coverage and fit.
double candidate_cost(double area, double c, double fit, const SelectionConfig& config);

// The complexity term of one edge of length `length` (m) when it is sharp: lambda_complexity *
// length * kSharpEdgeWidth (m²), independent of how large the region is. Rewards fewer, longer
// straight runs of faces.
inline constexpr double kSharpEdgeWidth = 0.25;  // m
double sharp_edge_cost(double length, const SelectionConfig& config);
// PolyFit's complexity per edge, for a program that gives none (SelectionProgram::sharp_cost
// empty): lambda_complexity * the candidates' total area / their edges, the same on every edge.
double uniform_sharp_cost(const CandidateSet& cs, const SelectionConfig& config);

// `program`'s cost and sharp_cost for the selection of a building (select_shell): per candidate
// candidate_cost of its area, `confidence` and `fit` (face maps of cs.mesh), per edge
// sharp_edge_cost of its length. Replaces both vectors; the rest of `program` is left.
void set_selection_costs(const CandidateSet& cs, const CandidateMap<double>& confidence,
                         const CandidateMap<double>& fit, const SelectionConfig& config, SelectionProgram& program);

// The cost of a candidate of area `area` (m²) in the program that mends a selection into the
// nearest closed one: a candidate of the selection (`in_start`) kept is a reward of
// `keep_weight` times its area (dropping it costs that), one added costs its area. Rewards the
// least changed area.
double mend_cost(double area, bool in_start, double keep_weight);
// `program`'s cost (mend_cost per candidate, `in_start` 0/1 per candidate) and sharp_cost (0 on
// every edge: the mend does not weigh complexity). Replaces both vectors.
void set_mend_costs(const CandidateSet& cs, const std::vector<char>& in_start, double keep_weight,
                    SelectionProgram& program);

}  // namespace lodrefine
