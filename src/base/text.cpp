#include "lodrefine/base/text.h"

#include "lodrefine/base/files.h"

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace lodrefine::io_text {

std::string quote(std::string_view s) {
  std::string out = "'";
  for (char c : s.substr(0, 40)) out += (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) ? c : '?';
  return out + (s.size() > 40 ? "...'" : "'");
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n\f\v");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n\f\v") - b + 1);
}

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    const std::size_t b = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i > b) out.push_back(s.substr(b, i - b));
  }
  return out;
}

std::ifstream open_input(const std::string& path, std::uint64_t* size) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a file");
  require_regular_file(path);  // /dev/zero or a FIFO would be read without end
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open (") + std::strerror(errno) + ")");
  if (size) {
    *size = std::filesystem::file_size(path, ec);
    if (ec) fail(path, "cannot determine file size");
  }
  return in;
}

std::string read_whole_file(const std::string& path) {
  std::ifstream in = open_input(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail(path, "read error");
  return ss.str();
}

std::string one_token(const std::string& name) {
  std::string s;
  for (char c : name)
    s += std::isspace(static_cast<unsigned char>(c)) || static_cast<unsigned char>(c) < 0x20 ? '_' : c;
  return s;
}

}  // namespace lodrefine::io_text
