// LAZ test helpers shared by tests/laz/test_laz*.cpp: the records of a LAS or LAZ file, fields
// read from its bytes, its refusal expected, and the independent decoder (the npm package laz-perf under node, run by
// tests/laz/laz_reference_dump.js), which the tests skip without.
#pragma once
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "lodrefine/formats/las.h"
#include "lodrefine/laz/laz_write.h"
#include "support/io_fixtures.h"
#include "support/test_paths.h"

namespace lodrefine::fixtures {

// All records of a LAS or LAZ file, concatenated.
inline std::string las_records(const std::string& path) {
  std::string all;
  stream_las_records(path, [&](const LasHeader& h, const unsigned char* r) {
    all.append(reinterpret_cast<const char*>(r), h.record_length);
  });
  return all;
}

// sizeof(T) bytes at `at` of a file's bytes (the test machine is little-endian, as LAS is).
template <class T>
T peek(const std::string& bytes, std::size_t at) {
  T v;
  std::memcpy(&v, &bytes[at], sizeof v);
  return v;
}
template <class T>
T peek(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Format-6 records (30 bytes + `extra`): returns 1 of 1, scanner channel `channel`.
inline std::string point14(std::int32_t x, double gps, int channel, std::size_t extra = 0) {
  std::string r(30 + extra, '\0');
  poke<std::int32_t>(r, 0, x);
  r[14] = 0x11;
  r[15] = char((channel & 3) << 4);
  r[16] = 2;
  poke<double>(r, 22, gps);
  return r;
}

// The LAS 1.4 format-6 LAZ of `records` (`record_length` bytes each) in the test's file `name`.
inline std::string write_laz14(const std::string& name, std::uint32_t record_length, const std::string& records,
                               std::uint32_t chunk = 50000) {
  const std::string path = temp_path(name);
  LasRecordFormat f;
  f.version_minor = 4, f.point_format = 6, f.record_length = record_length;
  LasRecordWriter w(path, f, true, chunk);
  for (std::size_t at = 0; at < records.size(); at += record_length)
    w.add(reinterpret_cast<const unsigned char*>(records.data() + at));
  w.finish();
  return path;
}

// The LAS or LAZ file of `bytes` refused by the reader in one line naming it and `fault`.
inline void expect_laz_refused(const std::string& bytes, const std::string& fault) {
  expect_bytes_refused("bad.laz", bytes, fault, las_records);
}

// Where laz-perf's node module may be: $LODREFINE_LAZPERF_MODULES, else the scratch folder
// the README's install line uses.
inline std::string lazperf_modules() {
  if (const char* env = std::getenv("LODREFINE_LAZPERF_MODULES")) return env;
  return "/tmp/lazjs/node_modules";
}

// Why laz-perf cannot run here (empty: it can).
inline std::string lazperf_missing() {
  if (std::system("node --version >/dev/null 2>&1") != 0) return "node not installed";
  if (!std::filesystem::exists(std::filesystem::path(lazperf_modules()) / "laz-perf"))
    return "npm package laz-perf not under " + lazperf_modules() +
           " (mkdir -p /tmp/lazjs && cd /tmp/lazjs && npm install laz-perf@0.0.7)";
  return {};
}

// The shell command that has laz-perf decode `laz` into the raw records file `dump`.
inline std::string lazperf_command(const std::string& laz, const std::string& dump) {
  const std::string script = test_paths::source_dir() + "/tests/laz/laz_reference_dump.js";
  return "node '" + script + "' '" + lazperf_modules() + "' '" + laz + "' '" + dump + "'";
}

}  // namespace lodrefine::fixtures
