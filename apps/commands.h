// Each subcommand of `lodrefine` registers itself on the CLI here; its work runs in the
// callback. Callbacks report failure by throwing (InputError for bad input) or by setting
// the exit code through the returned reference.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace lodrefine::app {

// Exit code the command wants (0 by default); main returns it after parsing.
int& exit_code();

// A message for one stderr line: control characters (a newline or an escape code in an id,
// a key or a file's text quoted by an error) as \n, \r, \t or \xHH, so the line stays one
// and the terminal untouched.
inline std::string one_line(const std::string& message) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  for (const char c : message) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) out += std::string("\\x") + kHex[u >> 4] + kHex[u & 15];
    else out += c;
  }
  return out;
}

void add_refine_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_crop_command(CLI::App& app);
void add_params_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_convert_command(CLI::App& app);

}  // namespace lodrefine::app
