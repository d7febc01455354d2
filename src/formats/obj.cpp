// OBJ reading and writing.
//
// Reading: tinyobjloader's double-precision build parses the file (its callback API: faces in
// file order and untriangulated, `g`/`usemtl`/`o` names as they come, even for materials no
// .mtl defines). It is lenient where we must not be: it reads a malformed number as 0, accepts
// out-of-range indices, skips unknown lines, and reports neither comments nor line numbers. So
// a line check of ours runs first (ObjCheck): it refuses what tinyobjloader would misread, with
// one line naming the file, the line and the fault, and keeps what tinyobjloader does not give
// (the `# id:` comment, the `o` name with its blanks as written, the lines of faces, faces with
// no vertex).
//
// Coordinates are the check's: it parses every number anyway (std::from_chars, correctly
// rounded, locale-free) to refuse bad ones. tinyobjloader's own parser sums digit by digit:
// about a quarter of real coordinates (435685.799) come out 1-2 ulp off, which moves report
// values in the 11th digit, and 0e999999999 becomes NaN. Its vertices are only counted (relative
// indices) and must agree with the check's.
//
// Writing is ours: fixed 6 decimals via <charconv>, so a C locale change cannot break files.
#include "lodrefine/formats/obj.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "lodrefine/base/files.h"
#include "lodrefine/base/submesh.h"
#include "lodrefine/base/text.h"

#ifndef TINYOBJLOADER_USE_DOUBLE
#error "tinyobjloader must be the double build (CMakeLists.txt defines TINYOBJLOADER_USE_DOUBLE)"
#endif

namespace lodrefine {

namespace {

using namespace io_text;

// What the line check passes on to the build step.
struct CheckedObj {
  std::string statements;       // the text with the only blanks tinyobjloader knows (see ObjCheck)
  std::vector<int> face_lines;  // line of each `f` with at least one vertex, in file order
  int empty_faces = 0;          // `f` without any vertex (tinyobjloader does not report them)
  std::vector<Vec3> vertices;
  std::string object;      // the first `o` name, as written (tinyobjloader sees plain blanks)
  std::string comment_id;  // `# id: X`
};

// The strict line check. Line by line it refuses what the reader does not accept: binary
// data, unknown statements, vertices that are not 3 to 7 finite numbers within kMaxCoordinate,
// face vertices that are not `v`, `v/vt`, `v//vn` or `v/vt/vn`, index 0, negative indices before
// the first vertex. Positive indices may point to later vertices: ObjBuild checks them at the end.
class ObjCheck {
 public:
  explicit ObjCheck(const std::string& path) : path_(path) {}

  CheckedObj run(std::string_view text) {
    if (trim(text).empty()) fail(path_, "empty file");
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
    reject_binary(text);
    out_.statements.reserve(text.size() + text.size() / 16);
    std::size_t start = 0;
    while (start < text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      ++line_;
      statement(text.substr(start, end - start));
      start = end + 1;
    }
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail_line(const std::string& fault) const {
    fail(path_, "line " + std::to_string(line_) + ": " + fault);
  }

  void reject_binary(std::string_view text) const {
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
    pass_on(line);
    if (line.empty()) return;
    if (line[0] == '#') return comment(trim(line.substr(1)));
    const auto tok = split_ws(line);
    const std::string_view kw = tok[0];
    if (kw == "v") vertex(tok);
    else if (kw == "f") face(tok);
    else if (kw == "o") {
      if (out_.object.empty()) out_.object = trim(line.substr(1));
    } else if (kw != "g" && kw != "usemtl" && !ignored(kw)) fail_line("unknown statement " + quote(kw));
  }

  // To tinyobjloader every blank is ' ' (it splits at ' ' and '\t' only, and also ends lines at
  // a lone '\r'), and each line ends in one: a bare `g` or `usemtl` stays a statement to it too.
  void pass_on(std::string_view line) {
    for (char c : line) out_.statements += std::isspace(static_cast<unsigned char>(c)) ? ' ' : c;
    out_.statements += " \n";
  }

  static bool ignored(std::string_view kw) {
    static const std::array<std::string_view, 10> kws = {"vt", "vn", "vp", "s",   "mtllib",
                                                         "l",  "p",  "mg", "lod", "usemap"};
    for (auto k : kws)
      if (kw == k) return true;
    return false;
  }

  void comment(std::string_view c) {
    if (c.size() > 3 && (c.substr(0, 3) == "id:" || c.substr(0, 3) == "ID:") && out_.comment_id.empty())
      out_.comment_id = trim(c.substr(3));
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
    out_.vertices.push_back(p);
  }

  void face(const std::vector<std::string_view>& tok) {
    for (std::size_t i = 1; i < tok.size(); ++i) vertex_ref(tok[i]);
    if (tok.size() == 1) ++out_.empty_faces;
    else out_.face_lines.push_back(line_);
  }

  // "v", "v/vt", "v//vn" or "v/vt/vn". tinyobjloader would read a third '/' as the start of
  // another vertex.
  void vertex_ref(std::string_view t) const {
    const std::string_view head = t.substr(0, t.find('/'));
    if (t.find_first_not_of("0123456789/-+", head.size()) != std::string_view::npos ||
        std::count(t.begin(), t.end(), '/') > 2)
      fail_line("bad face vertex " + quote(t));
    const auto idx = parse_number<long long>(head);
    if (!idx) fail_line("bad face vertex " + quote(t));
    if (*idx == 0) fail_line("face index 0 (OBJ indices start at 1)");
    const long long i = *idx > 0 ? *idx - 1 : (long long)out_.vertices.size() + *idx;
    if (i < 0 || i >= (long long)std::numeric_limits<int>::max())
      fail_line("face index " + std::to_string(*idx) + " out of range (" + std::to_string(out_.vertices.size()) +
                " vertices so far)");
  }

  const std::string& path_;
  CheckedObj out_;
  int line_ = 0;
};

// Builds the mesh from tinyobjloader's callbacks over the checked statements: faces in file
// order, semantics from the group, else the material (semantic_from_name), faces of fewer than
// 3 vertices skipped and counted; the id from the first `o`, else the `# id:` comment, else the
// file stem.
class ObjBuild {
 public:
  ObjBuild(const std::string& path, CheckedObj checked) : path_(path), checked_(std::move(checked)) {}

  // `fins` (may be null) gets one flag per face of the result: in a fins group (kFinsGroup).
  Mesh run(int* skipped_faces, std::vector<char>* fins = nullptr) {
    tinyobj::callback_t cb;
    cb.vertex_cb = [](void* self, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t) {
      ++static_cast<ObjBuild*>(self)->vertices_seen_;  // the values are the check's (see the top)
    };
    cb.index_cb = [](void* self, tinyobj::index_t* idx, int n) { static_cast<ObjBuild*>(self)->face(idx, n); };
    cb.group_cb = [](void* self, const char** names, int n) {
      std::string joined;  // `g a b` is one group to us: semantic_from_name looks for substrings
      bool fins = false;   // ... but a fin is in a group named exactly so
      for (int i = 0; i < n; ++i) {
        joined += (i ? " " : "") + std::string(names[i]);
        fins = fins || std::string_view(names[i]) == kFinsGroup;
      }
      static_cast<ObjBuild*>(self)->group_sem_ = semantic_from_name(joined);
      static_cast<ObjBuild*>(self)->in_fins_ = fins;
      static_cast<ObjBuild*>(self)->group_provenance_ = provenance_from_group(joined);
    };
    cb.usemtl_cb = [](void* self, const char* name, int) {
      static_cast<ObjBuild*>(self)->mtl_sem_ = semantic_from_name(std::string(trim(name)));
    };
    std::istringstream in(checked_.statements);
    std::string warn, err;
    // No MaterialReader: `mtllib` files are not opened, materials matter by name only.
    if (!tinyobj::LoadObjWithCallback(in, cb, this, nullptr, &warn, &err) || !err.empty())
      fail(path_, "tinyobjloader: " + std::string(trim(err.substr(0, err.find('\n')))));
    finish();
    if (skipped_faces) *skipped_faces = skipped_;
    if (fins) *fins = std::move(fins_);
    return std::move(mesh_);
  }

 private:
  void face(const tinyobj::index_t* idx, int n) {
    if (faces_seen_++ >= checked_.face_lines.size()) return;  // a disagreement, reported by finish()
    if (n < 3) {                                              // a point or a line is no polygon; counted, not fatal
      ++skipped_;
      return;
    }
    kept_lines_.push_back(checked_.face_lines[faces_seen_ - 1]);
    Face f;
    const int known = int(vertices_seen_);
    for (int k = 0; k < n; ++k) {  // raw OBJ indices: 1-based, negative ones relative
      const int i = idx[k].vertex_index;
      f.v.push_back(i > 0 ? i - 1 : known + i);
    }
    f.sem = group_sem_ != Semantic::Other ? group_sem_ : mtl_sem_;
    f.provenance = group_provenance_;
    f.source = int(mesh_.faces.size());
    mesh_.faces.push_back(std::move(f));
    fins_.push_back(in_fins_);
  }

  void finish() {
    // The check and tinyobjloader must have seen the same statements; if not, that is a bug here.
    if (faces_seen_ != checked_.face_lines.size() || vertices_seen_ != checked_.vertices.size())
      throw std::logic_error(path_ + ": tinyobjloader read " + std::to_string(vertices_seen_) + " vertices and " +
                             std::to_string(faces_seen_) + " faces, the line check " +
                             std::to_string(checked_.vertices.size()) + " and " +
                             std::to_string(checked_.face_lines.size()));
    mesh_.vertices = std::move(checked_.vertices);
    skipped_ += checked_.empty_faces;
    const std::size_t n = mesh_.vertices.size();
    for (std::size_t k = 0; k < mesh_.faces.size(); ++k)
      for (int i : mesh_.faces[k].v)
        if (i < 0 || std::size_t(i) >= n)
          fail(path_, "line " + std::to_string(kept_lines_[k]) + ": face index " + std::to_string(i + 1) +
                          " out of range (" + std::to_string(n) + " vertices)");
    if (mesh_.faces.empty())
      fail(path_,
           skipped_ ? "no faces with 3 or more vertices (" + std::to_string(skipped_) + " skipped)" : "no faces");
    mesh_.id = !checked_.object.empty()       ? checked_.object
               : !checked_.comment_id.empty() ? checked_.comment_id
                                              : std::filesystem::path(path_).stem().string();
  }

  const std::string& path_;
  CheckedObj checked_;
  Mesh mesh_;
  std::vector<int> kept_lines_;  // line of each face in mesh_
  std::size_t vertices_seen_ = 0, faces_seen_ = 0;
  int skipped_ = 0;
  Semantic group_sem_ = Semantic::Other, mtl_sem_ = Semantic::Other;
  bool in_fins_ = false;    // the current group is a fins group
  std::vector<char> fins_;  // per face of mesh_: in a fins group
  Provenance group_provenance_ = Provenance::None;
};

void append_fixed(std::string& out, double v) {
  char buf[400];  // any finite double in fixed notation with 6 decimals fits
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 6);  // µm
  if (r.ec != std::errc()) throw std::runtime_error("cannot print coordinate");
  out.append(buf, r.ptr);
}

// Where a mesh's faces go in the file: its vertices' offset, the prefix of its groups ("" or
// "fins "), and what a refusal calls its faces ("face ", "fin face ").
struct FaceBlock {
  std::size_t base = 0;
  std::string prefix, what;
};

// The faces of one semantic and provenance: `g <prefix>WallSurface` (no provenance) or
// `g <prefix>WallSurface scan`, a scan face after a `# lodrefine_coverage 0.85` comment.
void append_group(std::string& out, const Mesh& mesh, Semantic sem, Provenance from, const FaceBlock& block,
                  AtomicFile& file) {
  bool header = false;
  for (std::size_t k = 0; k < mesh.faces.size(); ++k) {
    const Face& f = mesh.faces[k];
    if (f.sem != sem || f.provenance != from) continue;
    if (f.v.size() < 3) file.fail(block.what + std::to_string(k) + " has fewer than 3 vertices");
    if (!header) {
      out += "g " + block.prefix + semantic_name(sem);
      if (from != Provenance::None) out += std::string(" ") + provenance_name(from);
      out += '\n';
      header = true;
    }
    if (from == Provenance::Scan) {
      char buf[16];  // a share 0..1 in hundredths, locale-free like the coordinates
      const auto r =
          std::to_chars(buf, buf + sizeof buf, std::clamp(f.coverage, 0.0, 1.0), std::chars_format::fixed, 2);
      out += "# lodrefine_coverage " + std::string(buf, r.ptr) + "\n";
    }
    out += 'f';
    for (int i : f.v) {
      if (i < 0 || std::size_t(i) >= mesh.vertices.size())
        file.fail(block.what + std::to_string(k) + " references missing vertex " + std::to_string(i));
      out += ' ' + std::to_string(block.base + std::size_t(i) + 1);
    }
    out += '\n';
  }
}

// `mesh`'s faces by semantic, then provenance.
void append_faces(std::string& out, const Mesh& mesh, const FaceBlock& block, AtomicFile& file) {
  for (Semantic sem : {Semantic::Wall, Semantic::Roof, Semantic::Ground, Semantic::Other})
    for (Provenance from : {Provenance::None, Provenance::Model, Provenance::Scan, Provenance::Added})
      append_group(out, mesh, sem, from, block, file);
}

void append_vertices(std::string& out, const Mesh& mesh, const Vec3& origin, const std::string& what,
                     AtomicFile& file) {
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3 p = mesh.vertices[i] + origin;
    if (!p.allFinite()) file.fail(what + std::to_string(i) + " is not finite");
    out += "v ";
    append_fixed(out, p.x()), out += ' ', append_fixed(out, p.y()), out += ' ', append_fixed(out, p.z());
    out += '\n';
  }
}

// The solid's faces first, then the fins in their own groups (kFinsGroup).
std::string obj_text(const Mesh& mesh, const Mesh& fins, const Vec3& origin, AtomicFile& file) {
  std::string out = "# lodrefine\n";
  // An id with blanks goes in a `# id:` comment (read back as is; `o` takes one token for other
  // tools), unless line breaks or outer blanks would not survive that either.
  const std::string token = one_token(mesh.id);
  const bool one_line_id = std::none_of(mesh.id.begin(), mesh.id.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u < 0x20 && c != '\t') || u == 0x7f;
  });
  if (token != mesh.id && one_line_id && trim(mesh.id) == mesh.id) out += "# id: " + mesh.id + "\n";
  else if (!mesh.id.empty()) out += "o " + token + "\n";
  append_vertices(out, mesh, origin, "vertex ", file);
  append_vertices(out, fins, origin, "fin vertex ", file);
  append_faces(out, mesh, {0, "", "face "}, file);
  append_faces(out, fins, {mesh.vertices.size(), std::string(kFinsGroup) + " ", "fin face "}, file);
  return out;
}

Mesh read_checked(const std::string& path, int* skipped_faces, std::vector<char>* fins) {
  const FileKind kind = sniff_file(path);
  if (kind != FileKind::Other) fail(path, "not an OBJ model: the file is " + file_kind_text(kind));
  return read_naming_memory(
      path, [&] { return ObjBuild(path, ObjCheck(path).run(read_whole_file(path))).run(skipped_faces, fins); });
}

}  // namespace

Mesh read_obj(const std::string& path, int* skipped_faces) { return read_checked(path, skipped_faces, nullptr); }

Mesh read_obj(const std::string& path) { return read_obj(path, nullptr); }

Mesh read_obj(const std::string& path, std::vector<char>& in_fins) { return read_checked(path, nullptr, &in_fins); }

ObjModel split_fins(const Mesh& mesh, const std::vector<char>& in_fins) {
  std::vector<Face> solid, fins;
  for (std::size_t k = 0; k < mesh.faces.size(); ++k)
    (k < in_fins.size() && in_fins[k] ? fins : solid).push_back(mesh.faces[k]);
  return {compacted(mesh.vertices, std::move(solid), mesh.id), compacted(mesh.vertices, std::move(fins), mesh.id)};
}

ObjModel read_obj_model(const std::string& path) {
  std::vector<char> in_fins;
  const Mesh all = read_obj(path, in_fins);
  return split_fins(all, in_fins);
}

void write_obj(const std::string& path, const Mesh& mesh, const Vec3& origin) { write_obj(path, mesh, Mesh(), origin); }

void write_obj(const std::string& path, const Mesh& mesh, const Mesh& fins, const Vec3& origin) {
  AtomicFile file(path);
  file.write(obj_text(mesh, fins, origin, file));
  file.commit();
}

}  // namespace lodrefine
