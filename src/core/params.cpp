#include "lodrefine/core/params.h"

#include <cmath>
#include <sstream>

#include "lodrefine/base/types.h"

namespace lodrefine {
namespace {

// Throws InputError naming the stage and the first field outside its bounds.
template <class Config>
void check_ranges(const Config& config) {
  for_each_field(config, [](const auto& field, auto value) {
    const double v = double(value);
    if (std::isfinite(v) && v >= double(field.min) && v <= double(field.max)) return;
    std::ostringstream os;
    os << field.stage << ": parameter " << field.name << " = " << value << " is outside [" << field.min << ", "
       << field.max << "]";
    throw InputError(os.str());
  });
}

}  // namespace

#define LODREFINE_STAGE_VALIDATE(Config, stage, what, rows) \
  void Config::validate() const { check_ranges(*this); }
LODREFINE_STAGES(LODREFINE_STAGE_VALIDATE)
#undef LODREFINE_STAGE_VALIDATE

void RefineConfig::validate() const {
  repair.validate();
  plane.validate();
  match.validate();
  if (match.w_normal + match.w_coverage <= 0) throw InputError("match: parameters w_normal + w_coverage must be > 0");
  selection.validate();
}

const std::vector<ParamInfo>& param_table() {
  static const std::vector<ParamInfo> table = [] {
    std::vector<ParamInfo> t;
    RefineConfig::visit_fields([&](const auto& f) {
      t.push_back({f.name, f.type, f.stage, double(f.default_value), double(f.min), double(f.max), f.description});
    });
    return t;
  }();
  return table;
}

const std::vector<StageInfo>& stage_table() {
  static const std::vector<StageInfo> table = {
#define LODREFINE_STAGE_INFO(Config, name, what, rows) {Config::stage, what},
      LODREFINE_STAGES(LODREFINE_STAGE_INFO)
#undef LODREFINE_STAGE_INFO
  };
  return table;
}

}  // namespace lodrefine
