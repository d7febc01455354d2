// Placeholder registration; replaced by the real command.
#include "commands.h"

namespace lodrefine::app {
void add_crop_command(CLI::App& app) { app.add_subcommand("crop", "(not yet available)"); }
}  // namespace lodrefine::app
