// lodrefine: refine coarse LoD2 building models with MLS point clouds.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"
#include "lodrefine/version.h"
#include "options.h"

namespace lodrefine::app {
int& exit_code() {
  static int code = 0;
  return code;
}
}  // namespace lodrefine::app

namespace {

// Memory running out can end in std::terminate rather than in main's catch: nlohmann::json's
// destructor allocates (its stack of children), so a large document destroyed while a
// bad_alloc unwinds throws again from a noexcept destructor. That is still memory running out:
// one line and exit 3, as main says it, instead of an abort, naming the file being read.
[[noreturn]] void terminated() {
  try {
    if (const std::exception_ptr e = std::current_exception()) std::rethrow_exception(e);
  } catch (const std::bad_alloc&) {
    // Formatted into a static buffer: nothing to allocate.
    static char line[1024];
    const char* file = lodrefine::ReadingFile::name();
    const int n = *file
                      ? std::snprintf(line, sizeof line, "lodrefine: error: %s: out of memory reading the file\n", file)
                      : std::snprintf(line, sizeof line, "lodrefine: error: out of memory\n");
    const ssize_t w = ::write(2, line, std::size_t(std::clamp(n, 0, int(sizeof line) - 1)));
    (void)w;
    ::_exit(3);
  } catch (...) {
  }
  std::abort();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace lodrefine;
  std::set_terminate(terminated);
  CLI::App app{"lodrefine: refine coarse LoD2 building models with mobile laser scanning point clouds"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lodrefine " LODREFINE_VERSION);
  app::add_refine_command(app);
  app::add_synth_command(app);
  app::add_eval_command(app);
  app::add_crop_command(app);
  app::add_params_command(app);
  app::add_bench_command(app);
  app::add_convert_command(app);
  app::add_validate_command(app);
  app::add_repair_command(app);
  app::require_finite_numbers(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {  // one line, like every other error (batch logs keep the last line)
    std::fprintf(stderr, "lodrefine: error: %s (see --help)\n", escaped_line(e.what()).c_str());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "lodrefine: error: %s\n", escaped_line(e.what()).c_str());
    return 2;
  } catch (const OutOfMemory& e) {  // names the file
    std::fprintf(stderr, "lodrefine: error: %s\n", escaped_line(e.what()).c_str());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lodrefine: error: out of memory\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lodrefine: error: %s\n", escaped_line(e.what()).c_str());
    return 1;
  }
  return app::exit_code();
}
