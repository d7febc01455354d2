#include "commands.h"
namespace lodrefine::app {
void add_refine_command(CLI::App& app) { app.add_subcommand("refine", "(not yet available)"); }
}  // namespace lodrefine::app
