// Each subcommand of `lodrefine` registers itself on the CLI here; its work runs in the
// callback. Callbacks report failure by throwing (InputError for bad input) or by setting
// the exit code through the returned reference.
#pragma once
#include <CLI/CLI.hpp>

namespace lodrefine::app {

// Exit code the command wants (0 by default); main returns it after parsing.
int& exit_code();

void add_refine_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_crop_command(CLI::App& app);
void add_params_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_validate_command(CLI::App& app);
void add_repair_command(CLI::App& app);

}  // namespace lodrefine::app
