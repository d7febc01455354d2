// PLY reading (ascii, binary little/big endian, streamed) and writing.
#include "lodrefine/formats/ply.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "lodrefine/base/text.h"

namespace lodrefine {

namespace {

using namespace io_text;

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };
enum class PlyFormat { Ascii, BinaryLE, BinaryBE };

std::optional<PlyType> ply_type(std::string_view s) {
  static const std::array<std::pair<std::string_view, PlyType>, 16> names = {{
      {"char", PlyType::I8},
      {"int8", PlyType::I8},
      {"uchar", PlyType::U8},
      {"uint8", PlyType::U8},
      {"short", PlyType::I16},
      {"int16", PlyType::I16},
      {"ushort", PlyType::U16},
      {"uint16", PlyType::U16},
      {"int", PlyType::I32},
      {"int32", PlyType::I32},
      {"uint", PlyType::U32},
      {"uint32", PlyType::U32},
      {"float", PlyType::F32},
      {"float32", PlyType::F32},
      {"double", PlyType::F64},
      {"float64", PlyType::F64},
  }};
  for (const auto& [name, t] : names)
    if (s == name) return t;
  return std::nullopt;
}

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::I8:
    case PlyType::U8: return 1;
    case PlyType::I16:
    case PlyType::U16: return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32: return 4;
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
  explicit PlyReader(const std::string& path) : path_(path), in_(open_input(path, &file_size_)) {
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
        fail(path_,
             "data ends after " + std::to_string(r) + " of " + std::to_string(el.count) + " vertices (truncated)");
      const Vec3 p(vals[xyz_[0]], vals[xyz_[1]], vals[xyz_[2]]);
      if (!p.allFinite()) fail(path_, "vertex " + std::to_string(r) + " has a non-finite coordinate");
      if (p.cwiseAbs().maxCoeff() > kMaxCoordinate)
        fail(path_, "vertex " + std::to_string(r) + " has a coordinate beyond 1e9 m");
      on_point(p);
    }
  }

  const std::string& path_;
  std::uint64_t file_size_ = 0;  // before in_, whose initialisation sets it
  std::ifstream in_;
  PlyFormat format_ = PlyFormat::Ascii;
  std::vector<PlyElement> elements_;
  std::size_t vertex_ = 0;
  std::array<std::size_t, 3> xyz_{};
  std::string tok_;
};

}  // namespace

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
  if (scalar) out += "property float " + one_token(scalar_name) + "\n";
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

PlyStream::PlyStream(const std::string& path, const std::string& comment, const std::string& properties)
    : file_(path), comment_(comment), properties_(properties) {
  file_.write(header());
}

std::string PlyStream::header() const {
  char count[32];  // wide enough for any count: rewritten in place
  std::snprintf(count, sizeof count, "%015llu", static_cast<unsigned long long>(vertices_));
  return "ply\nformat binary_little_endian 1.0\ncomment " + comment_ + "\nelement vertex " + count + "\n" +
         properties_ + "end_header\n";
}

void PlyStream::write(const char* records, std::size_t bytes, std::uint64_t vertices) {
  file_.write(records, bytes);
  vertices_ += vertices;
}

void PlyStream::commit() {
  file_.write_at(0, header());
  file_.commit();
}

}  // namespace lodrefine
