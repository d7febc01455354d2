// A mesh of some of another's faces (a building's solid apart from its fins, a repaired soup).
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// A mesh of `faces` (indices into `vertices`, each in range) holding only the vertices they use,
// in order of first use; the faces keep their semantics and sources.
Mesh compacted(const std::vector<Vec3>& vertices, std::vector<Face> faces, const std::string& id);

}  // namespace lodrefine
