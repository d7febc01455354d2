#include "lodrefine/core/params.h"

#include <cmath>
#include <sstream>

#include "lodrefine/core/types.h"

namespace lodrefine {

void Params::validate() const {
#define LODREFINE_PARAM_CHECK(type, name, def, lo, hi, help)                                   \
  if (!std::isfinite(double(name)) || double(name) < double(lo) || double(name) > double(hi)) { \
    std::ostringstream os;                                                                     \
    os << "parameter " #name " = " << name << " is outside [" << lo << ", " << hi << "]";       \
    throw InputError(os.str());                                                                \
  }
  LODREFINE_PARAMS(LODREFINE_PARAM_CHECK)
#undef LODREFINE_PARAM_CHECK
  if (w_normal + w_coverage <= 0) throw InputError("parameters w_normal + w_coverage must be > 0");
}

const std::vector<ParamInfo>& param_table() {
  static const std::vector<ParamInfo> table = {
#define LODREFINE_PARAM_INFO(type, name, def, lo, hi, help) {#name, #type, double(def), double(lo), double(hi), help},
      LODREFINE_PARAMS(LODREFINE_PARAM_INFO)
#undef LODREFINE_PARAM_INFO
  };
  return table;
}

}  // namespace lodrefine
