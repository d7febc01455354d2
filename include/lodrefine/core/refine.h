// The whole method: repair the coarse model, detect scan planes, match them to walls, and
// replace each outdated wall through a local candidate arrangement + GLPK face selection.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/core/params.h"
#include "lodrefine/core/types.h"

namespace lodrefine {

struct RefineResult {
  Mesh mesh;               // in the input (georeferenced) frame; valid closed polyhedron
  bool refined = false;    // outcome == "refined"
  // "refined": walls moved, validated, and the matched walls' points fit better than before;
  // "kept": the repaired input (nothing to change, or no refinement fitted better);
  // "kept-invalid": the input cannot be made a valid solid and `mesh` is it as read.
  std::string outcome;
  std::string reason;      // one line: why this outcome
  bool valid = false;      // `mesh` passed validate_mesh
  nlohmann::json report;   // matches, planes, candidates, MIP, timings, validation
};

// Every model gets an output: the refined building, the repaired input, or the input as read,
// with the outcome and its reason in the result and the report. Never throws for a bad model
// (only for parameters out of range).
RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const Params& params);

// The local origin used for a model: its bounding-box minimum rounded down to 100 m, so
// that all computation runs on small coordinates.
Vec3 local_origin(const Mesh& model);

}  // namespace lodrefine
