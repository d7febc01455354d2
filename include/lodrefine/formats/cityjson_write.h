// Writing CityJSON 2.0: quantised vertices and the pieces of a city file.
#pragma once
#include <array>
#include <cmath>

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

}  // namespace lodrefine
