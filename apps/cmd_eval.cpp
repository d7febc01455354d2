// Placeholder registration; replaced by the real command.
#include "commands.h"

namespace lodrefine::app {
void add_eval_command(CLI::App& app) { app.add_subcommand("eval", "(not yet available)"); }
}  // namespace lodrefine::app
