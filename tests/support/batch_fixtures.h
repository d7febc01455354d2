// A small generated tile and helpers to drive scripts/batch.mk and the other dispatchers, shared
// by the batch, dispatch and report tests.
#pragma once
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "support/test_paths.h"

namespace lodrefine::batch_fixtures {

namespace fs = std::filesystem;
using nlohmann::json;

inline const fs::path kSource = test_paths::source_dir();
inline const std::string kBinary = test_paths::lodrefine_binary();

// One shell word: in single quotes, a quote inside as '\''.
inline std::string shell_quoted(const fs::path& p) {
  std::string q = "'";
  for (char c : p.string()) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Exit status of a shell command (-1 when it did not exit normally).
inline int shell(const std::string& cmd) {
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

inline fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(testing::TempDir()) / ("lodrefine_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// `n` small generated buildings (few points: fast) of different types in `dir`.
inline void make_tile(const fs::path& dir, int n, int points = 4000) {
  const char* types[] = {"gable", "lshape", "hip", "flat", "stepped", "tshape"};
  for (int i = 0; i < n; ++i)
    ASSERT_EQ(shell(kBinary + " synth --type " + types[i % 6] + " --seed " + std::to_string(7 + i) +
                    " --count 1 --points " + std::to_string(points) + " --out " + shell_quoted(dir) + " > /dev/null"),
              0);
}

// cp -a: timestamps kept, so a copied finished run is still up to date.
inline void copy_run(const fs::path& from, const fs::path& to) {
  EXPECT_EQ(shell("cp -a " + shell_quoted(from) + "/. " + shell_quoted(to)), 0);
}

// The batch Makefile over `run` (extra make arguments appended).
inline std::string batch_command(const fs::path& run, const std::string& extra = "") {
  return "make -s -f " + shell_quoted(kSource / "scripts" / "batch.mk") + " RUN=" + shell_quoted(run) +
         " LODREFINE=" + shell_quoted(kBinary) + " -j2 " + extra;
}

// The report without timings (the only part of a refine that differs between runs): every
// "seconds" or "*_seconds" key.
inline json without_timings(json j) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end();) {
      const std::string& k = it.key();
      if (k == "seconds" || (k.size() > 8 && k.compare(k.size() - 8, 8, "_seconds") == 0)) {
        it = j.erase(it);
      } else {
        *it = without_timings(*it);
        ++it;
      }
    }
  } else if (j.is_array()) {
    for (auto& e : j) e = without_timings(e);
  }
  return j;
}

// Per building: the refined model's bytes, the report without timings, the FAILED reason.
inline std::map<std::string, std::string> outcome_files(const fs::path& run) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(run)) {
    if (!fs::exists(e.path() / "coarse.obj")) continue;
    const std::string id = e.path().filename().string();
    for (const char* name : {"refined.obj", "FAILED"})
      if (fs::exists(e.path() / name)) out[id + "/" + name] = read_text(e.path() / name);
    if (fs::exists(e.path() / "report.json"))
      out[id + "/report.json"] = without_timings(json::parse(read_text(e.path() / "report.json"))).dump(1);
  }
  return out;
}

// A generated tile (inputs only) and a finished local batch.mk run of it.
struct TileRun {
  fs::path inputs, done;
  std::map<std::string, std::string> outputs;  // outcome_files(done)
  double seconds = 0.0;                        // the batch's wall time
};

inline TileRun tile_and_batch(const std::string& name, int buildings) {
  TileRun t{fresh_dir(name + "_inputs"), fresh_dir(name + "_reference"), {}, 0.0};
  make_tile(t.inputs, buildings);
  copy_run(t.inputs, t.done);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(shell(batch_command(t.done) + " > /dev/null 2>&1"), 0);
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.outputs = outcome_files(t.done);
  return t;
}

// Files a finished run must not leave behind (temporaries of killed writers).
inline std::vector<std::string> temporaries(const fs::path& run) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(run))
    if (e.path().filename().string().find(".tmp") != std::string::npos ||
        e.path().filename().string().find("lodrefine-tmp") != std::string::npos)
      found.push_back(e.path().string());
  return found;
}

// Runs `cmd` through sh in its own process group (so the whole tree can be killed at once).
inline pid_t spawn_group(const std::string& cmd) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  return pid;
}

inline int wait_exit(pid_t pid) {
  int st = 0;
  ::waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

}  // namespace lodrefine::batch_fixtures
