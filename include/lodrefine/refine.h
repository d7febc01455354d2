// The whole method: repair the coarse model, detect scan planes, match them to walls, and
// replace each outdated wall through a local candidate arrangement + GLPK face selection.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/params.h"
#include "lodrefine/types.h"

namespace lodrefine {

struct RefineResult {
  Mesh mesh;               // in the input (georeferenced) frame; valid closed polyhedron
  bool refined = false;    // at least one facade was replaced
  std::string outcome;     // "refined", "original (<reason>)"
  bool valid = false;      // passed validate_mesh
  nlohmann::json report;   // matches, planes, candidates, MIP, timings, validation
};

// Throws InputError when the model cannot be repaired into a closed polyhedron (the caller
// then has no valid building to write). Everything else degrades to the repaired original
// with the reason in `outcome` and the report.
RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const Params& params);

// The local origin used for a model: its bounding-box minimum rounded down to 100 m, so
// that all computation runs on small coordinates.
Vec3 local_origin(const Mesh& model);

}  // namespace lodrefine
