// Writing CityJSON 2.0: quantised vertices and the pieces of a city file.
#pragma once
#include <array>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/base/types.h"

namespace lodrefine {

// CityGML coordinates become CityJSON integers at this resolution (m): 0.1 mm keeps every
// coordinate of a millimetre-precision model exact.
constexpr double kCityGmlResolution = 1e-4;

// A CityJSON "transform": file integers q map to q·scale + translate.
struct CityJsonTransform {
  Vec3 scale = Vec3::Constant(0.001);
  Vec3 translate = Vec3::Zero();
  std::array<long long, 3> quantise(const Vec3& p) const {
    return {std::llround((p.x() - translate.x()) / scale.x()), std::llround((p.y() - translate.y()) / scale.y()),
            std::llround((p.z() - translate.z()) / scale.z())};
  }
};

// The refined mesh as a CityJSON Solid geometry of LoD `lod` with semantics, its vertices
// appended to `vertices` quantised by the document's transform (`scale`, `translate`). A face
// with a provenance (Face::provenance) has it on its semantic surface object as
// "lodrefine_source" ("model", "scan", "added"), a scan face its coverage as
// "lodrefine_coverage" (0..1, in hundredths): one surface object per semantic, source and
// coverage. Faces of no semantic (Semantic::Other) have none (a null value).
nlohmann::ordered_json cityjson_solid(const Mesh& mesh, const std::string& lod, const Vec3& scale,
                                      const Vec3& translate, nlohmann::ordered_json& vertices);
// The same as a MultiSurface (the fins written beside a rebuilt shell: RefineResult::fins).
nlohmann::ordered_json cityjson_multisurface(const Mesh& mesh, const std::string& lod, const Vec3& scale,
                                             const Vec3& translate, nlohmann::ordered_json& vertices);

}  // namespace lodrefine
