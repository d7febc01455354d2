// The selection program's costs (objective.h).
#include "lodrefine/refine/objective.h"

#include <algorithm>
#include <cmath>

namespace lodrefine {

double coverage_cost(double area, double c, double tau) {
  return area * (1.0 / (1.0 + std::exp(-(1.0 - c) + (1.0 - tau))) - 0.5);
}

double face_confidence(double scanned, double contradicted, bool in_start) {
  const double prior = in_start ? 1.0 - contradicted : 0.0;
  return std::max(scanned, prior);
}

double fit_weight(double distance, double tolerance) {
  const double d = distance / tolerance;
  return std::max(0.0, 1.0 - d * d);
}

double fit_tolerance(const RefineConfig& config) {
  return config.plane.ransac_epsilon + config.selection.merge_distance;
}

double candidate_cost(double area, double c, double fit, const SelectionConfig& config) {
  return config.lambda_coverage * coverage_cost(area, c, config.tau_cov) - config.lambda_data * fit;
}

double sharp_edge_cost(double length, const SelectionConfig& config) {
  return config.lambda_complexity * length * kSharpEdgeWidth;
}

double uniform_sharp_cost(const CandidateSet& cs, const SelectionConfig& config) {
  double total_area = 0.0;
  const auto area = cs.areas();
  for (auto f : cs.mesh.faces()) total_area += area[f];
  return cs.edges.empty() ? 0.0 : config.lambda_complexity * total_area / double(cs.edges.size());
}

void set_selection_costs(const CandidateSet& cs, const CandidateMap<double>& confidence,
                         const CandidateMap<double>& fit, const SelectionConfig& config, SelectionProgram& program) {
  const auto area = cs.areas();
  program.cost.clear();
  for (int f = 0; f < cs.size(); ++f) {
    const CandidateFace fi(f);
    program.cost.push_back(candidate_cost(area[fi], confidence[fi], fit[fi], config));
  }
  program.sharp_cost.clear();
  for (const auto& e : cs.edges) program.sharp_cost.push_back(sharp_edge_cost(cs.length(e), config));
}

double mend_cost(double area, bool in_start, double keep_weight) { return in_start ? -keep_weight * area : area; }

void set_mend_costs(const CandidateSet& cs, const std::vector<char>& in_start, double keep_weight,
                    SelectionProgram& program) {
  const auto area = cs.areas();
  program.cost.clear();
  for (int f = 0; f < cs.size(); ++f)
    program.cost.push_back(mend_cost(area[CandidateFace(f)], in_start[f] != 0, keep_weight));
  program.sharp_cost.assign(cs.edges.size(), 0.0);
}

}  // namespace lodrefine
