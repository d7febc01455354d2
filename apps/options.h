// Method parameters as CLI options, generated from the one table in params.h.
#pragma once
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/core/params.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/cloud.h"

namespace lodrefine::app {

// "PLY, LAS or LAZ": a list of format names (kCloudFormatNames, kCityFormatNames) in a help text.
inline std::string formats_text(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

inline std::string option_name(const std::string& field) {
  std::string s = "--" + field;
  std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

// An option with its default shown and a closed range checked.
template <class T>
CLI::Option* add_ranged_option(CLI::App* cmd, const std::string& name, T& value, const std::string& help, T lo, T hi) {
  return cmd->add_option(name, value, help)->capture_default_str()->check(CLI::Range(lo, hi));
}

// Adds one option per parameter to `cmd`, bound to `config` (which must outlive parsing), in
// one help group per stage.
inline void add_param_options(CLI::App* cmd, RefineConfig& config) {
  for_each_field(config, [&](const auto& field, auto& value) {
    add_ranged_option(cmd, option_name(field.name), value, field.description, field.min, field.max)
        ->group(std::string("Method parameters: ") + field.stage);
  });
}

// The default of --jobs: every core the machine has (1 when it cannot tell).
inline int default_jobs() { return int(std::max(1u, std::thread::hardware_concurrency())); }

// `--classes 2,6`: the LAS classification filter of a command that reads a cloud.
inline void add_cloud_options(CLI::App* cmd, CloudOptions& options) {
  cmd->add_option("--classes", options.classes,
                  "Keep only LAS points of these classification codes (comma-separated, e.g. 1,6; "
                  "formats 0-5: 0-31, 6-10: 0-255)")
      ->delimiter(',')
      ->check(CLI::Range(0, 255));
  cmd->add_option("--max-points", options.max_points,
                  "The most points of one building's cloud or crop (a LAZ file of kilobytes can announce "
                  "billions); a cloud read whole, or a crop, with more is refused")
      ->capture_default_str();
}

// `--lod 2.2`: the value must be an LoD as city files write it (lod_number), as is each file's.
inline CLI::Validator lod_validator() {
  return CLI::Validator(
      [](std::string& s) { return lod_number(s) ? std::string() : "must be an LoD such as 2.2, not " + s; }, "LOD");
}

// Fails before any work when an output could not be written (so nothing is left half done):
// its folder must exist and take a new file (a temporary is created and removed again).
inline void check_output_dir(const std::string& path) {
  if (path.empty()) return;
  const std::filesystem::path dir = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(dir))
    throw InputError(path + ": output directory " + dir.string() + " does not exist");
  if (std::filesystem::is_directory(path)) throw InputError(path + ": is a directory");
  try {
    AtomicFile probe(path);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

// Checks every floating option of `app` and its subcommands for a finite value: "nan" and "inf"
// parse as doubles, and CLI::Range lets NaN through (no comparison with it is true), so
// `--tolerance nan` passed every regression. Called once, after every command is declared.
inline void require_finite_numbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& s) {
        double v = 0;
        if (CLI::detail::lexical_cast(s, v) && !std::isfinite(v)) return "must be a finite number, not " + s;
        return std::string();
      },
      "");
  for (CLI::Option* o : app.get_options())
    if (o->get_type_name().rfind("FLOAT", 0) == 0) o->check(finite);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) require_finite_numbers(*sub);
}

}  // namespace lodrefine::app
