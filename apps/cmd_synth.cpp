// Placeholder registration; replaced by the real command.
#include "commands.h"

namespace lodrefine::app {
void add_synth_command(CLI::App& app) { app.add_subcommand("synth", "(not yet available)"); }
}  // namespace lodrefine::app
