// OBJ reading and writing.
//
// The reader is our own line parser, not tinyobjloader: the library the build links
// (tinyobjloader::tinyobjloader) stores coordinates as float, which loses centimetres at
// georeferenced magnitudes (5801234.567), and it tolerates zero indices and garbage lines that
// we must reject. The subset CityGML exports use (v, f, g, o, usemtl, comments) is small.
// Numbers are parsed and printed with <charconv>, so a C locale change cannot break files.
#include "lodrefine/io/obj.h"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>

#include "text.h"

namespace lodrefine {

namespace {

using namespace io_text;

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

void append_fixed(std::string& out, double v) {
  char buf[400];  // any finite double in fixed notation with 6 decimals fits
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 6);  // µm
  if (r.ec != std::errc()) throw std::runtime_error("cannot print coordinate");
  out.append(buf, r.ptr);
}

std::string obj_text(const Mesh& mesh, const Vec3& origin, AtomicFile& file) {
  std::string out = "# lodrefine\n";
  if (!mesh.id.empty()) out += "o " + one_token(mesh.id) + "\n";
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

}  // namespace

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

}  // namespace lodrefine
