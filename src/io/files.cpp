// Atomic writes and telling formats apart by content.
#include "lodrefine/io/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string_view>

#include "text.h"

namespace lodrefine {

AtomicFile::AtomicFile(const std::string& path) : path_(path), tmp_(path + ".tmp." + std::to_string(::getpid())) {
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) fail(std::strerror(errno));
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::write(const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::write(fd_, data, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) fail(std::strerror(errno));
    data += k, n -= std::size_t(k);
  }
}

void AtomicFile::commit() {
  if (::fsync(fd_) != 0) fail(std::strerror(errno));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail(std::strerror(errno));
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) fail(std::strerror(errno));
  committed_ = true;
}

void AtomicFile::fail(const std::string& reason) {
  discard();
  throw std::runtime_error("cannot write " + path_ + ": " + reason);
}

void AtomicFile::discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!committed_) ::unlink(tmp_.c_str());
}

FileKind sniff_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  if (in) in.read(head, sizeof head);
  const std::string h(head, std::size_t(in.gcount()));
  if (h.rfind("LASF", 0) == 0) return FileKind::Las;
  if (h.rfind("ply\n", 0) == 0 || h.rfind("ply\r", 0) == 0) return FileKind::Ply;
  std::string_view s = h;
  if (s.compare(0, 3, "\xEF\xBB\xBF") == 0) s.remove_prefix(3);  // UTF-8 byte order mark
  s = io_text::trim(s);
  if (!s.empty() && s[0] == '<') return FileKind::Xml;
  if (!s.empty() && (s[0] == '{' || s[0] == '[')) return FileKind::Json;
  return FileKind::Other;
}

std::string file_kind_text(FileKind kind) {
  switch (kind) {
    case FileKind::Ply: return "a PLY point cloud";
    case FileKind::Las: return "a LAS/LAZ point cloud";
    case FileKind::Xml: return "XML (a CityGML model?)";
    case FileKind::Json: return "JSON (a CityJSON model?)";
    default: return "";
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  AtomicFile file(path);
  file.write(content);
  file.commit();
}

std::string read_file(const std::string& path) { return io_text::read_whole_file(path); }

}  // namespace lodrefine
