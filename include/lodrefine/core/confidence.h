// Stage 4a: confidence of each candidate face (paper Sec. 3.3): angle, distance and bbox
// filters against each reference (a kept model face or a scan plane's points), then the
// projected-overlap ratio; a candidate keeps its best score, 0 without a valid match.
#pragma once
#include <vector>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

struct ModelReference {
  std::vector<Vec3> polygon;  // a kept face of the coarse model
};

struct CloudReference {
  std::vector<Vec3> points;  // the inliers of a matched scan plane
};

struct Confidence {
  double value = 0.0;  // best projected-overlap ratio, 0..1
  int model_ref = -1;  // which reference gave it (-1: none)
  int cloud_ref = -1;
};

std::vector<Confidence> candidate_confidence(const CandidateSet& cs, const std::vector<ModelReference>& model,
                                             const std::vector<CloudReference>& cloud, const ConfidenceConfig& config);

// The paper's sigmoid coverage cost of a face of area `area` and confidence `c`:
// A * (1 / (1 + exp(-(1 - c) + (1 - tau))) - 0.5); negative (a reward) above tau.
double coverage_cost(double area, double c, double tau);

}  // namespace lodrefine
