// Shared by fuzz_las and fuzz_laz: the input as a file and read_las_header's verdict on it, and
// the check that a reader refuses a refused header with the header's words.
#pragma once
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "lodrefine/base/types.h"
#include "lodrefine/formats/las.h"

namespace lodrefine::fuzz {

// Writes the input to `path` and reads its header. A refusal is one line starting with the path
// (returned in `error`, the header left default); an accepted header has a known point format.
inline LasHeader las_header_of(const std::string& path, const std::uint8_t* data, std::size_t size,
                               std::string& error) {
  write_bytes(path, data, size);
  LasHeader header;
  try {
    header = read_las_header(path);
    FUZZ_CHECK(header.point_format >= 0 && header.point_format <= 10, "format %d accepted", header.point_format);
  } catch (const InputError& e) {
    check_message(e.what(), path);
    error = e.what();
  }
  return header;
}

// A reader that refused the file said what the header reader said.
inline void check_same_refusal(const std::string& header_error, const std::string& read_error) {
  FUZZ_CHECK(read_error == header_error, "header says '%s', reader says '%s'", header_error.c_str(),
             read_error.c_str());
}

}  // namespace lodrefine::fuzz
