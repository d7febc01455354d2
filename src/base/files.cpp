// Atomic writes, exclusive temporaries, safe names and telling formats apart by content.
#include "lodrefine/base/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string_view>

#include <nlohmann/json.hpp>

#include "lodrefine/base/text.h"

namespace lodrefine {

namespace fs = std::filesystem;

int create_temp_file(const std::string& dir, const std::string& for_path, std::string& path) {
  static const char kChars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  thread_local std::mt19937_64 random{std::random_device{}() ^ (std::uint64_t(::getpid()) << 32)};
  const fs::path folder = dir.empty() ? fs::path(".") : fs::path(dir);
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = kTempPrefix;
    for (int i = 0; i < 10; ++i) name += kChars[random() % (sizeof kChars - 1)];
    path = (folder / name).string();
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) return fd;
    if (errno != EEXIST) throw std::runtime_error("cannot write " + for_path + ": " + std::strerror(errno));
  }
  throw std::runtime_error("cannot write " + for_path + ": no free temporary name in " + folder.string());
}

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  // Renaming over a FIFO, device or socket (or a link to one, /dev/stdout) would replace it:
  // a reader of the FIFO hangs, and under root a device node becomes a regular file.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
    throw std::runtime_error("cannot write " + path +
                             ": not a regular file (a FIFO, device or socket); outputs are written to a "
                             "temporary file renamed into place: give a file path");
  fd_ = create_temp_file(fs::path(path).parent_path().string(), path, tmp_);
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::write(const char* data, std::size_t n) { write_from(data, n, -1); }

void AtomicFile::write_at(std::size_t offset, const std::string& s) {
  write_from(s.data(), s.size(), static_cast<long long>(offset));
}

void AtomicFile::write_from(const char* data, std::size_t n, long long offset) {
  while (n > 0) {
    const ssize_t k = offset < 0 ? ::write(fd_, data, n) : ::pwrite(fd_, data, n, off_t(offset));
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) fail(std::strerror(errno));
    data += k, n -= std::size_t(k);
    if (offset >= 0) offset += k;
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
  if (!committed_ && !tmp_.empty()) ::unlink(tmp_.c_str());
}

FileKind sniff_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return FileKind::Other;  // a FIFO would block
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  if (in) in.read(head, sizeof head);
  return sniff_head(std::string(head, std::size_t(in.gcount())));
}

FileKind sniff_head(const std::string& h) {
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

void copy_file_atomic(const std::string& from, const std::string& to) {
  require_regular_file(from);
  std::ifstream in(from, std::ios::binary);
  if (!in) throw InputError(from + ": cannot open (" + std::strerror(errno) + ")");
  AtomicFile file(to);
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) file.write(buffer, std::size_t(in.gcount()));
  if (in.bad()) file.fail("read error in " + from);
  file.commit();
}

namespace {

// The folders from the root down to <root>/<rel>, the root first.
std::vector<fs::path> folders_down(const std::string& root, const std::string& rel) {
  fs::path base(root);
  while (!base.has_filename() && base.has_relative_path()) base = base.parent_path();  // "out/"
  std::vector<fs::path> out{base};
  const fs::path r(rel);
  if (r.is_absolute()) throw std::logic_error("OutputTree: an absolute path " + rel);
  for (const fs::path& part : r) {
    if (part == "..") throw std::logic_error("OutputTree: a path leaving the root " + rel);
    if (part.empty() || part == ".") continue;
    out.push_back(out.back() / part);
  }
  return out;
}

}  // namespace

OutputTree::~OutputTree() {
  if (kept_) return;
  std::error_code ec;  // a folder something else was put in stays
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
}

namespace {

// Throws when a folder of `down` (folders_down) is a link, or anything but a folder.
void check_down(const std::vector<fs::path>& down, const std::string& root) {
  for (std::size_t i = 0; i < down.size(); ++i) {
    std::error_code ec;
    const fs::file_status st = i == 0 ? fs::status(down[i], ec) : fs::symlink_status(down[i], ec);
    if (!fs::exists(st)) break;
    if (fs::is_symlink(st))
      throw InputError(down[i].string() + ": is a symbolic link; outputs are written only inside " + root);
    if (!fs::is_directory(st)) throw InputError(down[i].string() + ": not a folder");
  }
}

}  // namespace

std::string OutputTree::check_folder(const std::string& rel) const {
  const std::vector<fs::path> down = folders_down(root_, rel);
  check_down(down, root_);
  return down.back().string();
}

std::string OutputTree::folder(const std::string& rel) {
  std::vector<fs::path> down = folders_down(root_, rel);
  check_down(down, root_);
  std::vector<fs::path> above;  // the root's missing parents
  for (fs::path p = down.front().parent_path(); !p.empty() && !fs::exists(p); p = p.parent_path())
    above.insert(above.begin(), p);
  down.insert(down.begin(), above.begin(), above.end());
  for (const fs::path& d : down) {
    std::error_code ec;
    if (fs::create_directory(d, ec)) created_.push_back(d.string());
    else if (ec) throw InputError("cannot create the folder " + d.string() + ": " + ec.message());
  }
  return down.back().string();
}

std::string OutputTree::file(const std::string& rel) {
  const fs::path path = fs::path(check_folder(fs::path(rel).parent_path().string())) / fs::path(rel).filename();
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) created_.push_back(path.string());
  return path.string();
}

void require_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(path + (S_ISDIR(st.st_mode) ? ": is a directory, not a file"
                                                 : ": not a regular file (a device, FIFO or socket); give a file"));
}

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  const bool has_a = ::stat(a.c_str(), &sa) == 0, has_b = ::stat(b.c_str(), &sb) == 0;
  if (has_a && has_b) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (has_a != has_b) return false;
  auto where = [](const std::string& p) {
    const fs::path abs = fs::absolute(p);
    std::error_code ec;
    const fs::path parent = fs::weakly_canonical(abs.parent_path(), ec);
    return (ec ? abs.parent_path() : parent) / abs.filename();
  };
  return where(a) == where(b);
}

void refuse_overwrites(const std::vector<FileOption>& inputs, const std::vector<FileOption>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const FileOption& out = outputs[i];
    if (out.path.empty()) continue;
    for (const FileOption& in : inputs)
      if (!in.path.empty() && same_file(out.path, in.path))
        throw InputError(out.path + ": " + out.name + " is the " + in.name + " file; it would be overwritten");
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path))
        throw InputError(out.path + ": " + out.name + " is the " + outputs[j].name + " file");
  }
}

namespace {

// Where an output is written: its folder's links resolved, a link at the name itself replaced
// (AtomicFile), not followed.
fs::path written_at(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();  // "out/"
  std::error_code ec;
  const fs::path folder = fs::weakly_canonical(p.parent_path(), ec);
  return (ec ? p.parent_path() : folder) / p.filename();
}

// Where an input is read: every link resolved.
fs::path read_at(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  return ec ? written_at(path) : p;
}

}  // namespace

void refuse_overwritten(const std::vector<RunFile>& inputs, const std::vector<RunFile>& outputs) {
  std::vector<fs::path> read;
  for (const RunFile& in : inputs) read.push_back(in.path.empty() ? fs::path() : read_at(in.path));
  for (const RunFile& out : outputs) {
    const fs::path name = fs::path(out.path).lexically_normal().filename();
    const auto named = [&](const fs::path& in) { return !in.empty() && (name.empty() || in.filename() == name); };
    if (std::none_of(read.begin(), read.end(), named)) continue;  // no folder resolved for most outputs
    const fs::path at = written_at(out.path);
    for (std::size_t i = 0; i < inputs.size(); ++i)
      if (!inputs[i].path.empty() && at == read[i])
        throw InputError(inputs[i].path + ": the " + inputs[i].what + " would be overwritten by " + out.what +
                         "; give another --out");
  }
}

namespace {

bool safe_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
}

std::string hashed_name(const std::string& id) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a
  for (unsigned char c : id) h = (h ^ c) * 1099511628211ull;
  std::string out = id.empty() || id[0] == '-' || id[0] == '.' ? "_" : "";
  for (char c : id.substr(0, 80 - out.size())) out += safe_char(c) ? c : '_';
  char hex[16];
  std::snprintf(hex, sizeof hex, "%012llx", static_cast<unsigned long long>(h & 0xffffffffffffull));
  return out + "--" + hex;
}

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  return s;
}

}  // namespace

std::string escaped_line(const std::string& text) {
  static const char* const kHex = "0123456789abcdef";
  auto hex = [](unsigned char u) { return std::string("\\x") + kHex[u >> 4] + kHex[u & 15]; };
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto u = static_cast<unsigned char>(text[i]);
    const auto next = i + 1 < text.size() ? static_cast<unsigned char>(text[i + 1]) : 0;
    if (text[i] == '\n') out += "\\n";
    else if (text[i] == '\r') out += "\\r";
    else if (text[i] == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) out += hex(u);
    else if (u == 0xc2 && next >= 0x80 && next <= 0x9f) out += hex(u) + hex(next), ++i;  // C1, e.g. CSI
    else out += text[i];
  }
  return out;
}

std::string shown_id(const std::string& id) {
  auto quoted = [](const std::string& s) {
    return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  };
  if (id.size() <= kMaxShownId) return quoted(id);
  std::size_t cut = kMaxShownId;  // at a character's first byte: a cut one would show as U+FFFD
  while (cut > 0 && (static_cast<unsigned char>(id[cut]) & 0xC0) == 0x80) --cut;
  return quoted(id.substr(0, cut) + "...") + " (" + std::to_string(id.size()) + " bytes)";
}

std::string line_id(const std::string& id) { return is_safe_name(id) ? id : shown_id(id); }

bool is_safe_name(const std::string& name) {
  if (name.empty() || name.size() > kMaxSafeName || name[0] == '-' || name[0] == '.') return false;
  for (char c : name)
    if (!safe_char(c)) return false;
  return true;
}

std::string safe_name(const std::string& id) { return is_safe_name(id) ? id : hashed_name(id); }

SafeNames::SafeNames(const std::vector<std::string>& reserved) {
  for (const auto& r : reserved) taken_.insert(lower(r));
}

bool SafeNames::take(const std::string& name) { return taken_.insert(lower(name)).second; }

std::string SafeNames::add(const std::string& id) {
  const std::string name = safe_name(id);
  if (take(name)) return name;
  const std::string hashed = hashed_name(id);
  if (take(hashed)) return hashed;
  for (int k = 2;; ++k)
    if (take(hashed + "-" + std::to_string(k))) return hashed + "-" + std::to_string(k);
}

namespace {
thread_local char reading_name[512] = "";

void copy_name(char (&to)[512], const char* from) noexcept {
  const std::size_t n = strnlen(from, sizeof to - 1);
  std::memmove(to, from, n);
  to[n] = '\0';
}
}  // namespace

ReadingFile::ReadingFile(const std::string& path) noexcept {
  copy_name(previous_, reading_name);
  copy_name(reading_name, path.c_str());
}

ReadingFile::~ReadingFile() { copy_name(reading_name, previous_); }

const char* ReadingFile::name() noexcept { return reading_name; }

std::string read_file(const std::string& path) { return io_text::read_whole_file(path); }

}  // namespace lodrefine
