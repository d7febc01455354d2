// OBJ and PLY reading and writing.
//
// The OBJ reader is our own line parser, not tinyobjloader: the library the build links
// (tinyobjloader::tinyobjloader) stores coordinates as float, which loses centimetres at
// georeferenced magnitudes (5801234.567), and it tolerates zero indices and garbage lines that
// we must reject. The subset CityGML exports use (v, f, g, o, usemtl, comments) is small.
// Numbers are parsed and printed with <charconv>, so a C locale change cannot break files.
#include "lodrefine/io/obj.h"
#include "lodrefine/io/ply.h"
#include "lodrefine/io/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>

namespace lodrefine {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& fault) {
  throw InputError(path + ": " + fault);
}

// Quotes file content safely: printable, short, so messages stay on one line.
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

// Whole-token number parsing (double or integer); nullopt on any trailing junk or overflow.
template <class T>
std::optional<T> parse_number(std::string_view t) {
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  T v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open (") + std::strerror(errno) + ")");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail(path, "read error");
  return ss.str();
}

// ---------------------------------------------------------------------------------------------
// OBJ reading

class ObjParser {
 public:
  explicit ObjParser(const std::string& path) : path_(path) {}

  Mesh parse(std::string text, int* skipped_faces) {
    if (trim(text).empty()) fail(path_, "empty file");
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);  // UTF-8 byte order mark
    reject_binary(text);
    std::size_t start = 0;
    while (start < text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      ++line_;
      statement(std::string_view(text).substr(start, end - start));
      start = end + 1;
    }
    finish();
    if (skipped_faces) *skipped_faces = skipped_;
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail_line(const std::string& fault) const {
    fail(path_, "line " + std::to_string(line_) + ": " + fault);
  }

  void reject_binary(const std::string& text) const {
    int line = 1;
    for (char c : text) {
      const auto u = static_cast<unsigned char>(c);
      if (c == '\n') ++line;
      else if ((u < 0x20 && !std::isspace(u)) || u == 0x7f)
        fail(path_, "line " + std::to_string(line) + ": binary data in a text OBJ");
    }
  }

  void statement(std::string_view line) {
    line = trim(line);
    if (line.empty()) return;
    if (line[0] == '#') return comment(trim(line.substr(1)));
    const auto tok = split_ws(line);
    const std::string_view kw = tok[0];
    const std::string_view rest = trim(line.substr(kw.size()));
    if (kw == "v") vertex(tok);
    else if (kw == "f") face(tok);
    else if (kw == "g") group_sem_ = semantic_from_name(std::string(rest));
    else if (kw == "usemtl") mtl_sem_ = semantic_from_name(std::string(rest));
    else if (kw == "o") { if (object_.empty()) object_ = rest; }
    else if (!ignored(kw)) fail_line("unknown statement " + quote(kw));
  }

  static bool ignored(std::string_view kw) {
    static const std::array<std::string_view, 10> kws = {"vt", "vn", "vp",  "s",  "mtllib",
                                                         "l",  "p",  "mg", "lod", "usemap"};
    for (auto k : kws)
      if (kw == k) return true;
    return false;
  }

  void comment(std::string_view c) {
    if (c.size() > 3 && (c.substr(0, 3) == "id:" || c.substr(0, 3) == "ID:") && comment_id_.empty())
      comment_id_ = trim(c.substr(3));
  }

  void vertex(const std::vector<std::string_view>& tok) {
    // x y z, optionally w or r g b (colour extension); we keep x y z.
    if (tok.size() < 4) fail_line("vertex with fewer than 3 coordinates (truncated?)");
    if (tok.size() > 8) fail_line("vertex with too many values");
    Vec3 p;
    for (std::size_t i = 1; i < tok.size(); ++i) {
      const auto v = parse_number<double>(tok[i]);
      if (!v) fail_line("bad number " + quote(tok[i]));
      if (!std::isfinite(*v)) fail_line("non-finite coordinate " + quote(tok[i]));
      if (i <= 3 && std::abs(*v) > kMaxCoordinate) fail_line("coordinate " + quote(tok[i]) + " is beyond 1e9 m");
      if (i <= 3) p[int(i - 1)] = *v;
    }
    mesh_.vertices.push_back(p);
  }

  void face(const std::vector<std::string_view>& tok) {
    Face f;
    for (std::size_t i = 1; i < tok.size(); ++i) f.v.push_back(vertex_ref(tok[i]));
    if (f.v.size() < 3) {  // a point or a line is no polygon; counted, not fatal
      ++skipped_;
      return;
    }
    f.sem = group_sem_ != Semantic::Other ? group_sem_ : mtl_sem_;
    f.source = int(mesh_.faces.size());
    mesh_.faces.push_back(std::move(f));
    face_line_.push_back(line_);
  }

  // "v", "v/vt", "v//vn" or "v/vt/vn"; returns the 0-based vertex index (checked in finish()
  // for positive indices, since a vertex may legally follow its first use).
  int vertex_ref(std::string_view t) {
    const std::string_view head = t.substr(0, t.find('/'));
    if (t.find_first_not_of("0123456789/-+", head.size()) != std::string_view::npos)
      fail_line("bad face vertex " + quote(t));
    const auto idx = parse_number<long long>(head);
    if (!idx) fail_line("bad face vertex " + quote(t));
    if (*idx == 0) fail_line("face index 0 (OBJ indices start at 1)");
    const long long n = (long long)mesh_.vertices.size();
    const long long i = *idx > 0 ? *idx - 1 : n + *idx;
    if (i < 0 || i >= (long long)std::numeric_limits<int>::max())
      fail_line("face index " + std::to_string(*idx) + " out of range (" + std::to_string(n) + " vertices so far)");
    return int(i);
  }

  void finish() {
    const std::size_t n = mesh_.vertices.size();
    for (std::size_t k = 0; k < mesh_.faces.size(); ++k)
      for (int i : mesh_.faces[k].v)
        if (std::size_t(i) >= n) {
          line_ = face_line_[k];
          fail_line("face index " + std::to_string(i + 1) + " out of range (" + std::to_string(n) + " vertices)");
        }
    if (mesh_.faces.empty())
      fail(path_, skipped_ ? "no faces with 3 or more vertices (" + std::to_string(skipped_) + " skipped)"
                           : "no faces");
    mesh_.id = !object_.empty() ? object_ : !comment_id_.empty() ? comment_id_
                                                                 : std::filesystem::path(path_).stem().string();
  }

  const std::string& path_;
  Mesh mesh_;
  std::vector<int> face_line_;
  int line_ = 0, skipped_ = 0;
  Semantic group_sem_ = Semantic::Other, mtl_sem_ = Semantic::Other;
  std::string object_, comment_id_;
};

// ---------------------------------------------------------------------------------------------
// PLY reading

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };
enum class PlyFormat { Ascii, BinaryLE, BinaryBE };

std::optional<PlyType> ply_type(std::string_view s) {
  static const std::array<std::pair<std::string_view, PlyType>, 16> names = {{
      {"char", PlyType::I8},    {"int8", PlyType::I8},     {"uchar", PlyType::U8},  {"uint8", PlyType::U8},
      {"short", PlyType::I16},  {"int16", PlyType::I16},   {"ushort", PlyType::U16}, {"uint16", PlyType::U16},
      {"int", PlyType::I32},    {"int32", PlyType::I32},   {"uint", PlyType::U32},  {"uint32", PlyType::U32},
      {"float", PlyType::F32},  {"float32", PlyType::F32}, {"double", PlyType::F64}, {"float64", PlyType::F64},
  }};
  for (const auto& [name, t] : names)
    if (s == name) return t;
  return std::nullopt;
}

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::I8: case PlyType::U8: return 1;
    case PlyType::I16: case PlyType::U16: return 2;
    case PlyType::I32: case PlyType::U32: case PlyType::F32: return 4;
    default: return 8;
  }
}

// Decodes one binary value; built from bytes explicitly so host endianness does not matter.
double decode(const unsigned char* p, PlyType t, bool big_endian) {
  const std::size_t n = type_size(t);
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < n; ++i) bits |= std::uint64_t(p[i]) << (8 * (big_endian ? n - 1 - i : i));
  switch (t) {
    case PlyType::I8: return double(std::int8_t(std::uint8_t(bits)));
    case PlyType::U8: return double(std::uint8_t(bits));
    case PlyType::I16: return double(std::int16_t(std::uint16_t(bits)));
    case PlyType::U16: return double(std::uint16_t(bits));
    case PlyType::I32: return double(std::int32_t(std::uint32_t(bits)));
    case PlyType::U32: return double(std::uint32_t(bits));
    case PlyType::F32: {
      const std::uint32_t u = std::uint32_t(bits);
      float f;
      std::memcpy(&f, &u, 4);
      return f;
    }
    default: {
      double d;
      std::memcpy(&d, &bits, 8);
      return d;
    }
  }
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;
  bool list = false;
  PlyType count_type = PlyType::U8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;

  bool has_lists() const {
    for (const auto& p : props)
      if (p.list) return true;
    return false;
  }
  // Smallest possible size of one record (lists may be empty); bytes for binary data, and two
  // characters per value (digit + separator) for ASCII.
  std::uint64_t min_record_size(PlyFormat f) const {
    std::uint64_t s = 0;
    for (const auto& p : props) s += f == PlyFormat::Ascii ? 2 : type_size(p.list ? p.count_type : p.type);
    return s;
  }
};

// Buffered reads from the data section: bytes for binary, tokens for ASCII.
class PlyData {
 public:
  explicit PlyData(std::ifstream& in) : in_(in), buf_(1 << 20) {}

  bool bytes(unsigned char* dst, std::size_t n) {
    while (n > 0) {
      if (pos_ == len_ && !refill()) return false;
      const std::size_t k = std::min(n, len_ - pos_);
      std::memcpy(dst, buf_.data() + pos_, k);
      pos_ += k, dst += k, n -= k;
    }
    return true;
  }

  bool token(std::string& t) {
    t.clear();
    bool overlong = false;  // junk without whitespace must not grow t without bound
    for (;;) {
      if (pos_ == len_ && !refill()) break;
      const char c = buf_[pos_++];
      if (!std::isspace(static_cast<unsigned char>(c))) {
        if (t.size() < 256) t += c;
        else overlong = true;
      } else if (!t.empty()) {
        break;
      }
    }
    if (overlong) t = "<overlong token>";
    return !t.empty();
  }

 private:
  bool refill() {
    in_.read(buf_.data(), std::streamsize(buf_.size()));
    len_ = std::size_t(in_.gcount()), pos_ = 0;
    return len_ > 0;
  }
  std::ifstream& in_;
  std::vector<char> buf_;
  std::size_t pos_ = 0, len_ = 0;
};

class PlyReader {
 public:
  explicit PlyReader(const std::string& path) : path_(path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a file");
    in_.open(path, std::ios::binary);
    if (!in_) fail(path, std::string("cannot open (") + std::strerror(errno) + ")");
    file_size_ = std::filesystem::file_size(path, ec);
    if (ec) fail(path, "cannot determine file size");
    if (file_size_ == 0) fail(path, "empty file");
    parse_header();
  }

  std::uint64_t vertex_count() const { return elements_[vertex_].count; }

  void read(const std::function<void(const Vec3&)>& on_point) {
    PlyData data(in_);
    for (std::size_t e = 0; e < vertex_; ++e) skip_element(data, elements_[e]);
    read_vertices(data, on_point);  // later elements (faces ...) are not needed
  }

 private:
  // Header lines are short; reading byte-wise with a cap stops junk without newlines early.
  std::string header_line() {
    std::string s;
    char c;
    while (in_.get(c) && c != '\n') {
      if (s.size() > 4096) fail(path_, "not a PLY file (header line over 4096 bytes)");
      s += c;
    }
    if (!in_ && s.empty()) fail(path_, "header ends before end_header (truncated)");
    if (!s.empty() && s.back() == '\r') s.pop_back();
    return s;
  }

  void parse_header() {
    if (header_line() != "ply") fail(path_, "not a PLY file (no 'ply' magic line)");
    bool have_format = false;
    for (int n = 0;; ++n) {
      if (n > 10000) fail(path_, "header too long");
      const std::string line = header_line();
      const auto tok = split_ws(line);
      if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
      if (tok[0] == "end_header") break;
      if (tok[0] == "format") format_line(tok), have_format = true;
      else if (tok[0] == "element") element_line(tok);
      else if (tok[0] == "property") property_line(tok);
      else fail(path_, "unknown header line " + quote(line));
    }
    if (!have_format) fail(path_, "header has no format line");
    // Records without properties take no bytes, so no file size bounds their count: a huge
    // count would be skipped forever.
    for (const auto& el : elements_)
      if (el.props.empty() && el.count > 0)
        fail(path_, "element " + quote(el.name) + " has " + std::to_string(el.count) + " records but no properties");
    find_vertex_element();
    check_counts_fit_file();
  }

  void format_line(const std::vector<std::string_view>& tok) {
    if (tok.size() != 3) fail(path_, "bad format line");
    if (tok[1] == "ascii") format_ = PlyFormat::Ascii;
    else if (tok[1] == "binary_little_endian") format_ = PlyFormat::BinaryLE;
    else if (tok[1] == "binary_big_endian") format_ = PlyFormat::BinaryBE;
    else fail(path_, "unknown format " + quote(tok[1]));
  }

  void element_line(const std::vector<std::string_view>& tok) {
    if (tok.size() != 3) fail(path_, "bad element line");
    const auto count = parse_number<std::uint64_t>(tok[2]);
    if (!count) fail(path_, "bad element count " + quote(tok[2]));
    elements_.push_back({std::string(tok[1]), *count, {}});
  }

  void property_line(const std::vector<std::string_view>& tok) {
    if (elements_.empty()) fail(path_, "property before any element");
    PlyProperty p;
    const bool list = tok.size() == 5 && tok[1] == "list";
    if (!list && tok.size() != 3) fail(path_, "bad property line");
    const std::string_view type_name = list ? tok[3] : tok[1];
    const auto t = ply_type(type_name);
    if (!t) fail(path_, "unknown property type " + quote(type_name));
    p.type = *t;
    p.name = std::string(tok.back());
    if (list) {
      const auto ct = ply_type(tok[2]);
      if (!ct || *ct == PlyType::F32 || *ct == PlyType::F64) fail(path_, "bad list count type " + quote(tok[2]));
      p.list = true, p.count_type = *ct;
    }
    elements_.back().props.push_back(p);
  }

  void find_vertex_element() {
    vertex_ = elements_.size();
    for (std::size_t e = 0; e < elements_.size(); ++e)
      if (elements_[e].name == "vertex") vertex_ = e;
    if (vertex_ == elements_.size()) fail(path_, "no vertex element");
    const auto& props = elements_[vertex_].props;
    for (int axis = 0; axis < 3; ++axis) {
      const std::string name(1, char('x' + axis));
      xyz_[axis] = props.size();
      for (std::size_t i = 0; i < props.size(); ++i)
        if (props[i].name == name && !props[i].list) xyz_[axis] = i;
      if (xyz_[axis] == props.size()) fail(path_, "vertex element has no scalar property " + name);
    }
  }

  // Rejects counts the file cannot possibly hold before anything is allocated or read.
  void check_counts_fit_file() {
    const std::uint64_t pos = std::uint64_t(in_.tellg());
    const std::uint64_t avail = file_size_ > pos ? file_size_ - pos : 0;
    std::uint64_t need = 0;
    for (std::size_t e = 0; e <= vertex_; ++e) {
      const auto& el = elements_[e];
      const std::uint64_t rec = el.min_record_size(format_);
      if (rec > 0 && el.count > (avail + 1) / rec + 1)
        fail(path_, "header declares " + std::to_string(el.count) + " " + el.name +
                        " records but the file holds only " + std::to_string(avail) + " data bytes");
      need += el.count * rec;
    }
    const std::uint64_t slack = format_ == PlyFormat::Ascii ? 1 : 0;  // last value needs no separator
    if (need > avail + slack)
      fail(path_, "header declares more data than the file holds (" + std::to_string(need) + " > " +
                      std::to_string(avail) + " bytes; truncated?)");
  }

  // One value of the data section as a double, false at the end of the data.
  bool value(PlyData& data, PlyType t, double& out) {
    if (format_ != PlyFormat::Ascii) {
      unsigned char b[8];
      if (!data.bytes(b, type_size(t))) return false;
      out = decode(b, t, format_ == PlyFormat::BinaryBE);
      return true;
    }
    if (!data.token(tok_)) return false;
    const auto v = parse_number<double>(tok_);
    if (!v) fail(path_, "bad ASCII value " + quote(tok_));
    out = *v;
    return true;
  }

  // Reads one record's property values into `vals` (list contents are skipped).
  bool record(PlyData& data, const PlyElement& el, std::vector<double>& vals) {
    for (std::size_t i = 0; i < el.props.size(); ++i) {
      const auto& p = el.props[i];
      if (!value(data, p.list ? p.count_type : p.type, vals[i])) return false;
      if (!p.list) continue;
      if (vals[i] < 0 || vals[i] != std::floor(vals[i]) || vals[i] > 1e6) fail(path_, "bad list length in " + el.name);
      for (int k = 0; k < int(vals[i]); ++k) {
        double ignored;
        if (!value(data, p.type, ignored)) return false;
      }
    }
    return true;
  }

  void skip_element(PlyData& data, const PlyElement& el) {
    std::vector<double> vals(el.props.size());
    if (format_ != PlyFormat::Ascii && !el.has_lists()) {
      std::vector<unsigned char> chunk(1 << 16);
      std::uint64_t left = el.count * el.min_record_size(format_);
      while (left > 0) {
        const std::size_t k = std::size_t(std::min<std::uint64_t>(left, chunk.size()));
        if (!data.bytes(chunk.data(), k)) fail(path_, "data ends inside element " + quote(el.name) + " (truncated)");
        left -= k;
      }
      return;
    }
    for (std::uint64_t r = 0; r < el.count; ++r)
      if (!record(data, el, vals)) fail(path_, "data ends inside element " + quote(el.name) + " (truncated)");
  }

  void read_vertices(PlyData& data, const std::function<void(const Vec3&)>& on_point) {
    const PlyElement& el = elements_[vertex_];
    std::vector<double> vals(el.props.size());
    for (std::uint64_t r = 0; r < el.count; ++r) {
      if (!record(data, el, vals))
        fail(path_, "data ends after " + std::to_string(r) + " of " + std::to_string(el.count) +
                        " vertices (truncated)");
      const Vec3 p(vals[xyz_[0]], vals[xyz_[1]], vals[xyz_[2]]);
      if (!p.allFinite()) fail(path_, "vertex " + std::to_string(r) + " has a non-finite coordinate");
      if (p.cwiseAbs().maxCoeff() > kMaxCoordinate)
        fail(path_, "vertex " + std::to_string(r) + " has a coordinate beyond 1e9 m");
      on_point(p);
    }
  }

  const std::string& path_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  PlyFormat format_ = PlyFormat::Ascii;
  std::vector<PlyElement> elements_;
  std::size_t vertex_ = 0;
  std::array<std::size_t, 3> xyz_{};
  std::string tok_;
};

// ---------------------------------------------------------------------------------------------
// Writing

void append_fixed(std::string& out, double v) {
  char buf[400];  // any finite double in fixed notation with 6 decimals fits
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 6);  // µm
  if (r.ec != std::errc()) throw std::runtime_error("cannot print coordinate");
  out.append(buf, r.ptr);
}

// One-line OBJ names: whitespace runs become '_' so `o` stays a single token for other tools.
std::string obj_name(const std::string& id) {
  std::string s;
  for (char c : id) s += std::isspace(static_cast<unsigned char>(c)) || static_cast<unsigned char>(c) < 0x20 ? '_' : c;
  return s;
}

std::string obj_text(const Mesh& mesh, const Vec3& origin, AtomicFile& file) {
  std::string out = "# lodrefine\n";
  if (!mesh.id.empty()) out += "o " + obj_name(mesh.id) + "\n";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3 p = mesh.vertices[i] + origin;
    if (!p.allFinite()) file.fail("vertex " + std::to_string(i) + " is not finite");
    out += "v ";
    append_fixed(out, p.x()), out += ' ', append_fixed(out, p.y()), out += ' ', append_fixed(out, p.z());
    out += '\n';
  }
  for (Semantic sem : {Semantic::Wall, Semantic::Roof, Semantic::Ground, Semantic::Other}) {
    bool header = false;
    for (std::size_t k = 0; k < mesh.faces.size(); ++k) {
      const Face& f = mesh.faces[k];
      if (f.sem != sem) continue;
      if (f.v.size() < 3) file.fail("face " + std::to_string(k) + " has fewer than 3 vertices");
      if (!header) out += std::string("g ") + semantic_name(sem) + "\n", header = true;
      out += 'f';
      for (int i : f.v) {
        if (i < 0 || std::size_t(i) >= mesh.vertices.size())
          file.fail("face " + std::to_string(k) + " references missing vertex " + std::to_string(i));
        out += ' ' + std::to_string(i + 1);
      }
      out += '\n';
    }
  }
  return out;
}

template <class T>
void put_le(std::string& out, T v) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t> bits;
  std::memcpy(&bits, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) out += char((bits >> (8 * i)) & 0xff);
}

}  // namespace

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

Mesh read_obj(const std::string& path, int* skipped_faces) {
  const FileKind kind = sniff_file(path);
  if (kind != FileKind::Other) fail(path, "not an OBJ model: the file is " + file_kind_text(kind));
  return ObjParser(path).parse(read_whole_file(path), skipped_faces);
}

Mesh read_obj(const std::string& path) { return read_obj(path, nullptr); }

void write_obj(const std::string& path, const Mesh& mesh, const Vec3& origin) {
  AtomicFile file(path);
  file.write(obj_text(mesh, origin, file));
  file.commit();
}

PointCloud read_ply(const std::string& path) {
  PlyReader reader(path);
  PointCloud cloud;
  cloud.points.reserve(reader.vertex_count());  // bounded by the file size (checked in the header)
  reader.read([&](const Vec3& p) { cloud.points.push_back(p); });
  return cloud;
}

void stream_ply(const std::string& path, const std::function<void(const Vec3&)>& on_point) {
  PlyReader(path).read(on_point);
}

std::uint64_t ply_vertex_count(const std::string& path) { return PlyReader(path).vertex_count(); }

void write_ply(const std::string& path, const PointCloud& cloud, const Vec3& origin, const std::vector<float>* scalar,
               const std::string& scalar_name) {
  AtomicFile file(path);
  if (scalar && scalar->size() != cloud.points.size())
    file.fail("scalar has " + std::to_string(scalar->size()) + " values for " + std::to_string(cloud.points.size()) +
              " points");
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment lodrefine\nelement vertex " +
                    std::to_string(cloud.points.size()) + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (scalar) out += "property float " + obj_name(scalar_name) + "\n";
  out += "end_header\n";
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const Vec3 p = cloud.points[i] + origin;
    put_le(out, p.x()), put_le(out, p.y()), put_le(out, p.z());
    if (scalar) put_le(out, (*scalar)[i]);
    if (out.size() >= (1 << 20)) file.write(out), out.clear();
  }
  file.write(out);
  file.commit();
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
  s = trim(s);
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

}  // namespace lodrefine
