// The small text and file helpers the readers and writers of the laz and formats libraries share
// (messages, tokens, numbers, little-endian fields). Not meant for the libraries' users.
#pragma once
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine::io_text {

// Every reader's refusal: one line, "<path>: <fault>".
[[noreturn]] inline void fail(const std::string& path, const std::string& fault) {
  throw InputError(path + ": " + fault);
}

// Quotes file content safely: printable, short, so messages stay on one line.
std::string quote(std::string_view s);

std::string_view trim(std::string_view s);
std::vector<std::string_view> split_ws(std::string_view s);

// Whole-token number parsing (double or integer); nullopt on any trailing junk or overflow.
// <charconv>, so a C locale change cannot break files. from_chars takes no '+', so one is
// dropped here, but not in front of a '-': "+-5" is no number.
template <class T>
std::optional<T> parse_number(std::string_view t) {
  if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.remove_prefix(1);
  T v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

// Opens an input file for binary reading, and gives its size if asked; refuses directories and
// unreadable files with the reason.
std::ifstream open_input(const std::string& path, std::uint64_t* size = nullptr);
std::string read_whole_file(const std::string& path);

// Little-endian binary fields (LAS, LAZ), read and written byte-wise so nothing depends on the host.
template <class T>
T get_le(const unsigned char* p) {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) bits |= std::uint64_t(p[i]) << (8 * i);
  if constexpr (std::is_same_v<T, double>) {
    double d;
    std::memcpy(&d, &bits, 8);
    return d;
  } else {
    return T(bits);
  }
}

template <class T>
void put_le(std::string& out, T v) {  // integers, float and double
  std::uint64_t bits = 0;
  if constexpr (std::is_floating_point_v<T>) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8);
    std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t> raw;
    std::memcpy(&raw, &v, sizeof(T));
    bits = raw;
  } else {
    bits = std::uint64_t(v);
  }
  for (std::size_t i = 0; i < sizeof(T); ++i) out += char((bits >> (8 * i)) & 0xff);
}

// Reads n bytes at byte offset pos; false when the file is shorter.
inline bool read_at(std::ifstream& in, std::uint64_t pos, unsigned char* dst, std::size_t n) {
  in.clear();
  in.seekg(std::streamoff(pos));
  in.read(reinterpret_cast<char*>(dst), std::streamsize(n));
  return in.gcount() == std::streamsize(n);
}

// One-token names for OBJ `o` lines and PLY property names: whitespace and control characters
// become '_' so other tools read one token.
std::string one_token(const std::string& name);

}  // namespace lodrefine::io_text
