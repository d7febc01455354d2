// `lodrefine params`: the parameter table (defaults, bounds, meaning) by stage, as text or Markdown.
#include <cstdio>

#include "commands.h"
#include "lodrefine/core/params.h"
#include "options.h"

namespace lodrefine::app {

void add_params_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("params", "List every method parameter with default, bounds and meaning, by stage");
  static bool markdown = false;
  cmd->add_flag("--markdown", markdown, "Print one Markdown table per stage (used for the README)");
  cmd->callback([] {
    for (const auto& stage : stage_table()) {
      if (markdown)
        std::printf("%s**%s**: %s\n\n| option | default | range | meaning |\n|---|---|---|---|\n",
                    &stage == &stage_table().front() ? "" : "\n", stage.name.c_str(), stage.summary.c_str());
      else
        std::printf("%s%s: %s\n", &stage == &stage_table().front() ? "" : "\n", stage.name.c_str(),
                    stage.summary.c_str());
      for (const auto& p : param_table()) {
        if (p.stage != stage.name) continue;
        const std::string opt = option_name(p.name);
        if (markdown)
          std::printf("| `%s` | %g | %g … %g | %s |\n", opt.c_str(), p.default_value, p.min, p.max,
                      p.description.c_str());
        else std::printf("  %-28s %-8g %s\n", opt.c_str(), p.default_value, p.description.c_str());
      }
    }
  });
}

}  // namespace lodrefine::app
