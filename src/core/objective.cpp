// The selection program's costs per candidate face (objective.h).
#include "lodrefine/core/objective.h"

#include <cmath>

namespace lodrefine {

double coverage_cost(double area, double c, double tau) {
  return area * (1.0 / (1.0 + std::exp(-(1.0 - c) + (1.0 - tau))) - 0.5);
}

}  // namespace lodrefine
