// `lodrefine params`: the parameter table (defaults, bounds, meaning) as text or Markdown.
#include <cstdio>

#include "commands.h"
#include "lodrefine/core/params.h"
#include "options.h"

namespace lodrefine::app {

void add_params_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("params", "List every method parameter with default, bounds and meaning");
  static bool markdown = false;
  cmd->add_flag("--markdown", markdown, "Print a Markdown table (used for the README)");
  cmd->callback([] {
    if (markdown) std::printf("| option | default | range | meaning |\n|---|---|---|---|\n");
    for (const auto& p : param_table()) {
      const std::string opt = option_name(p.name);
      if (markdown)
        std::printf("| `%s` | %g | %g … %g | %s |\n", opt.c_str(), p.default_value, p.min, p.max, p.description.c_str());
      else
        std::printf("%-28s %-8g %s\n", opt.c_str(), p.default_value, p.description.c_str());
    }
  });
}

}  // namespace lodrefine::app
