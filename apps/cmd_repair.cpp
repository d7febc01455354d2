// `lodrefine repair`: every building of a city file that is no valid solid repaired without a
// scan (the rebuild on its own planes, as refine --repair-all does it), the valid ones written
// as read; each building's outcome and its val3dity codes before and after.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "city_argument.h"
#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/city/progress.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/city/validity.h"
#include "lodrefine/version.h"
#include "options.h"

namespace lodrefine::app {
namespace {

struct RepairArgs {
  std::string city, out, report, lod;
  RefineConfig params;
  int jobs = default_jobs();
  bool quiet = false;
};

nlohmann::json report_json(const RepairArgs& a, const CityRefineSummary& s) {
  nlohmann::json j = {{"lodrefine_version", LODREFINE_VERSION},
                      {"model", a.city},
                      {"written", a.out},
                      {"input", s.input_format},
                      {"buildings", s.buildings},
                      {"valid_as_read", s.untouched},
                      {"repaired", s.repaired},
                      {"kept", s.kept},
                      {"kept_invalid", s.kept_invalid},
                      {"objects_without_lod", s.objects_without_lod},
                      {"seconds", {{"read", s.seconds_read}, {"repair", s.seconds_refine}}},
                      {"params", params_json(a.params)},
                      {"outcomes", nlohmann::json::array()}};
  for (const CityBuildingOutcome& b : s.outcomes) j["outcomes"].push_back(city_outcome_json(b));
  return j;
}

// "302 303 -> none": a building's codes before and after.
std::string codes_text(const std::vector<ValidityError>& before, const std::vector<ValidityError>& after) {
  const auto list = [](const std::vector<ValidityError>& errors) {
    std::string out;
    for (int code : error_codes(errors)) out += (out.empty() ? "" : " ") + std::to_string(code);
    return out.empty() ? std::string("none") : out;
  };
  return list(before) + " -> " + list(after);
}

void run(const RepairArgs& a) {
  a.params.validate();
  refuse_overwrites({{"CITY", a.city}}, {{"--out", a.out}, {"--report", a.report}});
  check_output_dir(a.out);
  check_output_dir(a.report);
  const std::string ext = std::filesystem::path(a.out).extension().string();
  if (ext == ".obj" || ext == ".OBJ")
    throw InputError(a.out + ": repair writes a CityJSON city file; name it e.g. repaired.city.json");
  CityRefineOptions o;
  o.lod = a.lod;
  o.jobs = a.jobs;
  o.repair_all = true;
  o.only_invalid = true;
  std::unique_ptr<Progress> progress;
  const Progress::Mode mode = Progress::mode_for_stderr(a.quiet);
  o.progress = [&](const CityRefineSummary& s) {
    if (!progress) progress = std::make_unique<Progress>("repair", "buildings", std::uint64_t(s.buildings), mode);
    progress->update(std::uint64_t(s.repaired + s.kept + s.kept_invalid + s.untouched));
  };
  const CityRefineSummary s = refine_city(a.city, {}, a.out, a.params, o);
  if (progress) progress->finish();
  if (!a.report.empty())
    write_file_atomic(a.report, report_json(a, s).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  for (const CityBuildingOutcome& b : s.outcomes)
    if (b.outcome != Outcome::Untouched)
      std::printf("%s: %s (%s), codes %s\n", shown_id(b.id).c_str(), outcome_name(b.outcome),
                  escaped_line(b.reason).c_str(), codes_text(b.errors_before, b.errors_after).c_str());
  std::printf(
      "%s: %d building(s): %d valid as read (written as read), %d repaired, %d kept, %d kept-invalid -> %s "
      "(%.1f s)\n",
      escaped_line(s.input_format).c_str(), s.buildings, s.untouched, s.repaired, s.kept, s.kept_invalid,
      escaped_line(a.out).c_str(), s.seconds_read + s.seconds_refine + s.seconds_write);
}

}  // namespace

void add_repair_command(CLI::App& app) {
  static RepairArgs args;
  auto* cmd = app.add_subcommand("repair",
                                 "Repair every building of a city file that is no valid solid, without a scan "
                                 "(its shell rebuilt on its own planes); the valid ones are written as read");
  add_city_argument(cmd, args.city);
  cmd->add_option("--out", args.out,
                  "Repaired city file (CityJSON 2.0; CityJSONSeq for a sequence), written atomically. Each building "
                  "repaired gets lodrefine_outcome, lodrefine_reason and its codes lodrefine_errors_before / "
                  "lodrefine_errors_after")
      ->required();
  cmd->add_option("--report", args.report,
                  "JSON report: every building's outcome, reason and val3dity errors before and after");
  cmd->add_option("--lod", args.lod, "The LoD geometry to repair, e.g. 2.2 (default: the highest 2.x)")
      ->check(lod_validator());
  add_ranged_option(cmd, "--jobs", args.jobs,
                    "Buildings repaired at once, one thread each (default: all cores; the output is the same)", 1,
                    1024);
  cmd->add_flag("--quiet", args.quiet, "No progress line on stderr");
  add_param_options(cmd, args.params);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
