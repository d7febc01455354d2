// `lodrefine validate`: every building of a city file checked as a solid, its defects under
// val3dity's error codes; a report shaped like val3dity's. Exit 0 when all are valid, 1 when not.
#include <cstdio>
#include <map>

#include "city_argument.h"
#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/validity.h"
#include "options.h"

namespace lodrefine::app {
namespace {

struct ValidateArgs {
  std::string city, json, lod;
  ValidityTolerances tolerances;
};

void run(const ValidateArgs& a) {
  refuse_overwrites({{"CITY", a.city}}, {{"--json", a.json}});
  check_output_dir(a.json);
  const CityValidity v = validate_city(a.city, a.lod, a.tolerances);
  if (!a.json.empty())
    write_file_atomic(a.json,
                      validity_report_json(v).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  std::map<int, int> count;  // buildings per code
  for (const BuildingValidity& b : v.buildings) {
    for (int code : error_codes(b.validation)) ++count[code];
    std::printf("%s: %s\n", shown_id(b.id).c_str(),
                b.valid() ? "valid" : escaped_line(errors_text(b.validation.errors)).c_str());
  }
  std::string codes;
  for (const auto& [code, n] : count)
    codes += (codes.empty() ? "" : ", ") + std::to_string(code) + " x" + std::to_string(n);
  std::printf("%s: %zu building(s) (LoD %s): %zu valid, %d invalid%s (snap %g m, planarity %g m)\n",
              escaped_line(v.input_format).c_str(), v.buildings.size(), a.lod.empty() ? "2.x" : a.lod.c_str(),
              v.buildings.size() - std::size_t(v.invalid()), v.invalid(),
              codes.empty() ? "" : ("; buildings per code: " + codes).c_str(), a.tolerances.snap,
              a.tolerances.planarity);
  exit_code() = v.invalid() > 0 ? 1 : 0;
}

}  // namespace

void add_validate_command(CLI::App& app) {
  static ValidateArgs args;
  auto* cmd = app.add_subcommand(
      "validate",
      "Check every building of a city file as a solid; report its defects with val3dity's error codes "
      "(exit 0: all valid, 1: some invalid, 2: bad input)");
  add_city_argument(cmd, args.city);
  cmd->add_option("--json", args.json,
                  "Write the report as JSON in val3dity's shape (features: id, type, validity, errors with code, "
                  "description, id, info)");
  cmd->add_option("--lod", args.lod, "The LoD geometry to check, e.g. 2.2 (default: the highest 2.x)")
      ->check(lod_validator());
  add_ranged_option(cmd, "--snap-tol", args.tolerances.snap,
                    "Vertices closer than this are one point (m; val3dity's snap_tol)", 1e-6, 1.0);
  add_ranged_option(cmd, "--planarity-tol", args.tolerances.planarity,
                    "A face's vertices may lie this far from its plane (m; val3dity's planarity_d2p_tol)", 0.0, 1.0);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
