// The CityJSON 2.0.2 schemas of ../shared/schemas run on a written city file
// (scripts/validate_cityjson.py): the tests of every writer of city files share the verdict.
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "support/test_paths.h"

namespace lodrefine::schema_fixtures {

inline std::filesystem::path shared_dir() { return std::filesystem::path(test_paths::source_dir()) / ".." / "shared"; }

// "valid", or the validator's complaint; "" when the schemas or python3-jsonschema are absent.
// `seq`: a CityJSONSeq (a header line, then features).
inline std::string schema_verdict(const std::string& path, bool seq = false) {
  const std::filesystem::path schemas = shared_dir() / "schemas" / "cityjson-2.0.2";
  if (!std::filesystem::exists(schemas) || !std::filesystem::exists("/usr/bin/python3")) return "";
  const std::string out = path + ".verdict";
  const std::string cmd = "/usr/bin/python3 " + test_paths::source_dir() + "/scripts/validate_cityjson.py " +
                          schemas.string() + " " + path + (seq ? " --seq" : "") + " >" + out + " 2>&1";
  const int st = std::system(cmd.c_str());
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  if (WIFEXITED(st) && WEXITSTATUS(st) == 2) return "";
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

}  // namespace lodrefine::schema_fixtures
