// CityJSON / CityJSONSeq reader: LoD 2.x Buildings and BuildingParts as polygon soups.
#include "lodrefine/formats/cityjson.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"

namespace lodrefine {

// strtod alone took "2.2\0<script>" as 2.2 (it stops at the NUL) and "0x2.8p0" as 2.5.
std::optional<double> lod_number(const std::string& s) {
  constexpr std::size_t kMaxLodText = 8;
  if (s.empty() || s.size() > kMaxLodText || s.front() == '.' || s.back() == '.') return std::nullopt;
  if (std::count(s.begin(), s.end(), '.') > 1) return std::nullopt;
  for (char c : s)
    if (c != '.' && (c < '0' || c > '9')) return std::nullopt;
  return std::strtod(s.c_str(), nullptr);
}

std::string shown_json(const nlohmann::json& value) {
  return escaped_line(value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).substr(0, 40));
}

void add_feature_ids(const nlohmann::ordered_json& feature, std::unordered_set<std::string>& seen,
                     const std::string& where) {
  const auto objects = feature.find("CityObjects");
  if (objects == feature.end() || !objects->is_object()) return;  // the reader says what is wrong
  for (const auto& [id, obj] : objects->items())
    if (!seen.insert(id).second)
      throw InputError(where + ": CityObject " + shown_id(id) + " is in an earlier feature too");
}

namespace {

// ordered_json keeps the CityObjects in file order (nlohmann::json would sort them by id).
using json = nlohmann::ordered_json;

// Printable, short, one line: for ids and parser messages quoted in an error.
std::string one_line(const std::string& s, std::size_t max = 120) {
  std::string out;
  for (char c : s.substr(0, max)) out += (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) ? c : '?';
  return s.size() > max ? out + "..." : out;
}

// The member `key` of an object, or a null json when it is absent (no copy, unlike value()).
const json& member(const json& obj, const char* key) {
  static const json null_json;
  if (!obj.is_object()) return null_json;
  const auto it = obj.find(key);
  return it == obj.end() ? null_json : *it;
}

class Reader {
 public:
  Reader(std::string name, std::string lod) : name_(std::move(name)), lod_(std::move(lod)) {}

  [[noreturn]] void fail(const std::string& fault) const {
    throw InputError(name_ + ": " + (where_.empty() ? "" : where_ + ": ") + fault);
  }

  CityJsonFile read(const std::string& text) {
    if (is_cityjson_sequence(text)) {
      const auto eol = text.find('\n');
      return read_sequence(parse_city_json(std::string_view(text).substr(0, eol), name_ + ": line 1"), text, eol + 1);
    }
    return read_document(parse_city_json(text, name_));
  }

  CityJsonFile read_document(const json& root) {
    CityJsonFile out;
    read_header(root, out);
    const std::vector<Vec3> vertices = read_vertices(root, out);
    read_objects(root, vertices, out);
    finish(out);
    return out;
  }

 private:
  std::string name_;
  std::string lod_;    // the LoD asked for ("" = the highest 2.x)
  std::string where_;  // "line N" / "object ID" context for error messages
  int degenerate_rings_ = 0, degenerate_objects_ = 0;
  std::unordered_set<std::string> ids_;  // a sequence's CityObjects so far

  void finish(CityJsonFile& out) const {
    if (degenerate_rings_ > 0)
      out.notes.push_back(std::to_string(degenerate_rings_) + " surface(s) with < 3 distinct vertices dropped in " +
                          std::to_string(degenerate_objects_) + " object(s)");
  }

  CityJsonFile read_sequence(const json& header, const std::string& text, std::size_t pos) {
    CityJsonFile out;
    out.sequence = true;
    where_ = "line 1";
    read_header(header, out);
    int line_no = 1;
    while (pos < text.size()) {
      auto eol = text.find('\n', pos);
      if (eol == std::string::npos) eol = text.size();
      const std::string line = text.substr(pos, eol - pos);
      pos = eol + 1;
      ++line_no;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      where_ = "line " + std::to_string(line_no);
      const json feature = parse_city_json(line, name_ + ": " + where_);
      if (!feature.is_object() || member(feature, "type") != "CityJSONFeature")
        fail("expected a CityJSONFeature object");
      add_feature_ids(feature, ids_, name_ + ": " + where_);
      const std::vector<Vec3> vertices = read_vertices(feature, out);
      read_objects(feature, vertices, out);
    }
    where_.clear();
    finish(out);
    return out;
  }

  void read_header(const json& root, CityJsonFile& out) {
    if (!root.is_object() || member(root, "type") != "CityJSON")
      fail("not a CityJSON file (no \"type\": \"CityJSON\")");
    const json& version = member(root, "version");
    if (!version.is_null() && !version.is_string()) fail("\"version\" is not a string");
    if (version.is_string()) out.version = version.get<std::string>();
    if (root.contains("transform")) {
      const json& t = root["transform"];
      if (!t.is_object()) fail("\"transform\" is not an object");
      out.scale = vec3(member(t, "scale"), "transform.scale");
      out.translate = vec3(member(t, "translate"), "transform.translate");
      if ((out.scale.array() <= 0.0).any())
        fail("transform.scale has a zero or negative factor (every vertex would collapse)");
      // The refined vertices are written back as (p - translate) / scale in 64-bit integers:
      // with both within kMaxCoordinate and the scale at least kMinScale they fit (2e18 < 9.2e18).
      // A scale of 1e-15 wrapped them to -9.2e18 without a word.
      if ((out.scale.array() < kMinScale).any())
        fail("transform.scale has a factor below 1e-9 m (the vertices written back would overflow 64-bit integers)");
      if (out.translate.cwiseAbs().maxCoeff() > kMaxCoordinate) fail("transform.translate is beyond 1e9 m");
    }
    const json& rs = member(member(root, "metadata"), "referenceSystem");
    if (rs.is_string()) out.crs = rs.get<std::string>();
  }

  Vec3 vec3(const json& j, const std::string& what) const {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
      fail(what + " is not an array of 3 numbers");
    const Vec3 v(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
    if (!v.allFinite()) fail(what + " is not finite");
    return v;
  }

  std::vector<Vec3> read_vertices(const json& root, const CityJsonFile& out) const {
    const auto it = root.find("vertices");
    if (it == root.end() || !it->is_array()) fail("no \"vertices\" array");
    std::vector<Vec3> vertices;
    vertices.reserve(it->size());
    for (const json& v : *it) {
      const std::string what = "vertex " + std::to_string(vertices.size());
      vertices.push_back(vec3(v, what).cwiseProduct(out.scale) + out.translate);
      // Beyond this, quantising for the CityJSON written back overflows 64-bit integers.
      if (!vertices.back().allFinite() || vertices.back().cwiseAbs().maxCoeff() > kMaxCoordinate)
        fail(what + " is beyond 1e9 m from the origin");
    }
    return vertices;
  }

  void read_objects(const json& root, const std::vector<Vec3>& vertices, CityJsonFile& out) {
    const auto it = root.find("CityObjects");
    if (it == root.end() || !it->is_object()) fail("no \"CityObjects\" object");
    const std::string outer = where_;
    for (const auto& [id, obj] : it->items()) {
      where_ = (outer.empty() ? "" : outer + ": ") + "object " + shown_id(id);
      if (!obj.is_object()) fail("is not a JSON object");
      const json& type = member(obj, "type");
      if (!type.is_null() && !type.is_string()) fail("\"type\" is not a string");
      if (type != "Building" && type != "BuildingPart") continue;
      // The outcome is written into a building's attributes: any other value there would be lost.
      const json& attributes = member(obj, "attributes");
      if (!attributes.is_null() && !attributes.is_object()) fail("\"attributes\" is not a JSON object");
      const json* geom = best_lod2(obj);
      if (geom == nullptr) {
        ++out.objects_without_lod2;
        out.ids_without_lod2.push_back(id);
        continue;
      }
      CityJsonBuilding b;
      b.mesh.id = id;
      b.type = type.get<std::string>();
      const json& parents = member(obj, "parents");
      if (parents.is_array() && !parents.empty() && parents[0].is_string()) b.parent = parents[0].get<std::string>();
      const json& lod = (*geom)["lod"];
      b.lod = lod.is_string() ? lod.get<std::string>() : lod.dump();
      b.geometry_type = (*geom)["type"].get<std::string>();
      b.geometry_index = int(geom - &obj["geometry"][0]);
      const int sources = read_geometry(*geom, vertices, b);
      read_fins(obj, *geom, vertices, sources, b);
      if (b.skipped_holes > 0)
        out.notes.push_back(shown_id(id) + ": " + std::to_string(b.skipped_holes) +
                            " inner ring(s) dropped (surfaces keep their outer ring)");
      if (b.skipped_shells > 0)
        out.notes.push_back(shown_id(id) + ": " + std::to_string(b.skipped_shells) + " interior shell(s) dropped");
      if (b.skipped_rings > 0) {
        degenerate_rings_ += b.skipped_rings;
        ++degenerate_objects_;
      }
      if (b.mesh.faces.empty()) {
        out.notes.push_back(shown_id(id) + ": LoD " + b.lod + " geometry has no usable surface, skipped");
        continue;
      }
      out.buildings.push_back(std::move(b));
    }
    where_ = outer;
  }

  // The highest LoD 2.x geometry of an object (the first one on ties); null if there is none.
  const json* best_lod2(const json& obj) const {
    const json& geoms = member(obj, "geometry");
    if (geoms.is_null()) return nullptr;
    if (!geoms.is_array()) fail("\"geometry\" is not an array");
    const json* best = nullptr;
    double best_lod = -1.0;
    for (const json& g : geoms) {
      if (!g.is_object()) fail("a geometry is not a JSON object");
      const json& type = member(g, "type");
      if (!type.is_string()) fail("a geometry has no \"type\"");
      if (type == "GeometryInstance") continue;
      const json& lod = member(g, "lod");
      double value = -1.0;
      if (lod.is_number()) {
        value = lod.get<double>();
      } else if (lod.is_string()) {
        const std::optional<double> v = lod_number(lod.get<std::string>());
        if (!v)
          fail("geometry lod " + shown_id(lod.get<std::string>().substr(0, 20)) +
               " is not an LoD (a decimal such as 2.2)");
        value = *v;
      } else {
        fail("a geometry has no \"lod\"");
      }
      if (!lod_.empty()) {  // an exact LoD asked for: "2.2" matches "2.2" and 2.2
        if (best == nullptr && lod_number(lod_) == value) best = &g;
        continue;
      }
      if (value >= 2.0 && value < 3.0 && value > best_lod) {
        best = &g;
        best_lod = value;
      }
    }
    return best;
  }

  // The fins lodrefine wrote beside a building's Solid (a MultiSurface of its LoD right after
  // it, in an object with a `lodrefine_outcome` attribute), appended to the building's soup,
  // their sources after the Solid's `sources` surfaces. A foreign file's second geometry of one
  // LoD is no fin: it is left alone.
  void read_fins(const json& obj, const json& solid, const std::vector<Vec3>& vertices, int sources,
                 CityJsonBuilding& b) {
    const json& geoms = obj["geometry"];
    const std::size_t next = std::size_t(b.geometry_index) + 1;
    if (b.geometry_type != "Solid" || next >= geoms.size() ||
        !member(member(obj, "attributes"), "lodrefine_outcome").is_string())
      return;
    const json& fins = geoms[next];
    if (member(fins, "type") != "MultiSurface" || member(fins, "lod") != member(solid, "lod")) return;
    const std::size_t before = b.mesh.faces.size();
    read_geometry(fins, vertices, b, sources);
    b.fins_index = int(next);
    b.fin_faces = int(b.mesh.faces.size() - before);
  }

  // Reads geometry `g`'s surfaces into b.mesh, their sources numbered from `first_source`;
  // returns the number after the last.
  int read_geometry(const json& g, const std::vector<Vec3>& vertices, CityJsonBuilding& b, int first_source = 0) {
    const std::string type = g["type"].get<std::string>();
    int depth = 0;  // array levels above a surface: 1 MultiSurface, 2 Solid, 3 MultiSolid
    if (type == "MultiSurface" || type == "CompositeSurface") depth = 1;
    else if (type == "Solid") depth = 2;
    else if (type == "MultiSolid" || type == "CompositeSolid") depth = 3;
    else fail("LoD " + b.lod + " geometry type \"" + one_line(type, 30) + "\" is not a surface or solid type");
    const json& boundaries = member(g, "boundaries");
    if (!boundaries.is_array()) fail(type + " has no \"boundaries\" array");

    // Semantics: surfaces[] and values nested like the boundaries minus the ring levels.
    std::vector<Semantic> surface_sem;
    const json* values = nullptr;
    if (g.contains("semantics") && !g["semantics"].is_null()) {
      const json& sem = g["semantics"];
      if (!sem.is_object()) fail("\"semantics\" is not an object");
      const json& surfaces = member(sem, "surfaces");
      if (!surfaces.is_array()) fail("semantics has no \"surfaces\" array");
      for (const json& s : surfaces) {
        if (!s.is_object() || !member(s, "type").is_string()) fail("a semantic surface has no \"type\"");
        surface_sem.push_back(semantic_from_cityjson(s["type"].get<std::string>()));
      }
      if (sem.contains("values") && !sem["values"].is_null()) values = &sem["values"];
    }

    int source = first_source;
    // Walks one shell (array of surfaces) with its semantic values (or null).
    auto read_shell = [&](const json& shell, const json* shell_values) {
      if (!shell.is_array()) fail(type + " boundaries are not nested as the type needs");
      if (shell_values != nullptr && (!shell_values->is_array() || shell_values->size() != shell.size()))
        fail("semantics values do not match the " + type + " boundaries");
      for (std::size_t s = 0; s < shell.size(); ++s, ++source) {
        Semantic sem = Semantic::Other;
        if (shell_values != nullptr) {
          const json& v = (*shell_values)[s];
          if (v.is_number_integer() || v.is_number_unsigned()) {
            const long long k = v.get<long long>();
            if (k < 0 || k >= static_cast<long long>(surface_sem.size()))
              fail("semantics value " + v.dump() + " has no semantic surface");  // as written: 2^63 is no -2^63
            sem = surface_sem[k];
          } else if (!v.is_null()) {
            fail("semantics values do not match the " + type + " boundaries");
          }
        }
        read_surface(shell[s], vertices, sem, source, type, b);
      }
    };
    if (depth == 1) {
      read_shell(boundaries, values);
      return source;
    }
    auto read_solid = [&](const json& solid, const json* solid_values) {
      if (!solid.is_array() || solid.empty()) fail(type + " boundaries are not nested as the type needs");
      if (solid_values != nullptr && (!solid_values->is_array() || solid_values->size() != solid.size()))
        fail("semantics values do not match the " + type + " boundaries");
      read_shell(solid[0], solid_values ? &(*solid_values)[0] : nullptr);
      b.skipped_shells += int(solid.size()) - 1;  // voids are no part of an exterior LoD2 model
    };
    if (depth == 2) {
      read_solid(boundaries, values);
      return source;
    }
    if (values != nullptr && (!values->is_array() || values->size() != boundaries.size()))
      fail("semantics values do not match the " + type + " boundaries");
    for (std::size_t k = 0; k < boundaries.size(); ++k) read_solid(boundaries[k], values ? &(*values)[k] : nullptr);
    return source;
  }

  // One surface: its outer ring becomes a face; inner rings are counted and dropped. An outer
  // ring that revisits a vertex is split into simple loops first (see split_ring): loops inside
  // the largest one are holes written the keyhole way (dropped), others become faces of their own.
  void read_surface(const json& surface, const std::vector<Vec3>& vertices, Semantic sem, int source,
                    const std::string& type, CityJsonBuilding& b) {
    if (!surface.is_array() || surface.empty()) fail(type + " boundaries are not nested as the type needs");
    std::vector<int> ring;
    for (std::size_t r = 0; r < surface.size(); ++r) {
      const json& jr = surface[r];
      if (!jr.is_array()) fail(type + " boundaries are not nested as the type needs");
      for (const json& ji : jr) {
        if (!ji.is_number_integer() && !ji.is_number_unsigned())
          fail(type + " boundaries are not nested as the type needs");
        const long long i = ji.get<long long>();
        if (i < 0 || i >= static_cast<long long>(vertices.size()))
          fail("vertex index " + ji.dump() + " is out of range (" + std::to_string(vertices.size()) + " vertices)");
        if (r == 0) ring.push_back(int(i));
      }
    }
    b.skipped_holes += int(surface.size()) - 1;
    std::vector<std::vector<int>> loops;
    split_ring(ring, loops);
    if (loops.empty()) {
      ++b.skipped_rings;
      return;
    }
    std::size_t outer = 0;
    std::vector<Vec3> normals;
    for (const auto& loop : loops) {
      normals.push_back(newell_normal(points_of(loop, vertices)));
      if (normals.back().norm() > normals[outer].norm()) outer = normals.size() - 1;
    }
    const std::vector<Vec3> outer_pts = points_of(loops[outer], vertices);
    const Plane plane = Plane::through(outer_pts.front(), normals[outer].normalized());
    const auto [u, v] = plane.basis();
    std::vector<Vec2> outer2;
    for (const auto& p : outer_pts) outer2.emplace_back(u.dot(p), v.dot(p));
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const std::vector<Vec3> pts = points_of(loops[k], vertices);
      if (k != outer && normals[k].dot(normals[outer]) < 0) {
        const Vec3 c = polygon_centroid(pts);
        if (point_in_polygon_2d(Vec2(u.dot(c), v.dot(c)), outer2)) {
          ++b.skipped_holes;
          continue;
        }
      }
      Face f;
      f.sem = sem;
      f.source = source;
      for (const auto& p : pts) {
        f.v.push_back(int(b.mesh.vertices.size()));
        b.mesh.vertices.push_back(p);
      }
      b.mesh.faces.push_back(std::move(f));
    }
  }

  static std::vector<Vec3> points_of(const std::vector<int>& loop, const std::vector<Vec3>& vertices) {
    std::vector<Vec3> pts;
    for (int i : loop) pts.push_back(vertices[i]);
    return pts;
  }

  // Splits a ring into simple loops of >= 3 distinct vertices (none when it is degenerate), in
  // one walk (linear: a ring pinched at one vertex thousands of times is common in broken
  // exports). Repeated consecutive vertices and the closing repeat are dropped; a vertex met
  // again closes the loop walked since its first visit: a pinch's petal, a keyhole's hole (its
  // bridge u->v ... v->u leaves a loop of two vertices, dropped, as is a spike u,v,u).
  static void split_ring(const std::vector<int>& ring, std::vector<std::vector<int>>& loops) {
    std::vector<int> r;
    for (int i : ring)
      if (r.empty() || r.back() != i) r.push_back(i);
    while (r.size() > 1 && r.front() == r.back()) r.pop_back();
    std::vector<int> walk;                    // the open part of the walk: distinct vertices
    std::unordered_map<int, std::size_t> at;  // vertex -> its position in walk
    for (int v : r) {
      const auto it = at.find(v);
      if (it == at.end()) {
        at.emplace(v, walk.size());
        walk.push_back(v);
        continue;
      }
      const std::size_t from = it->second;  // walk[from..] is a closed loop; v stays open
      if (walk.size() - from >= 3) loops.emplace_back(walk.begin() + std::ptrdiff_t(from), walk.end());
      for (std::size_t k = from + 1; k < walk.size(); ++k) at.erase(walk[k]);
      walk.resize(from + 1);
    }
    if (walk.size() >= 3) loops.push_back(std::move(walk));  // closed by the ring's last edge
  }
};

// Refuses nesting deeper than kMaxJsonDepth at an object's or array's start (every untrusted
// JSON file: copying, writing or freeing deeper values recurses past the stack).
void check_depth(int depth, nlohmann::detail::parse_event_t event, const std::string& name) {
  using E = nlohmann::detail::parse_event_t;
  if ((event == E::object_start || event == E::array_start) && depth >= kMaxJsonDepth)
    throw InputError(name + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
}

// Refuses what the DOM parser would take silently or with a raw message: nesting deeper than
// kMaxJsonDepth, and a key given twice in one object (the parser keeps the last one: a second
// "CityObjects" or "vertices" would replace the first without a word, a CityObjects id given
// twice would lose a building, and other readers may keep the first). Free-form data
// (attributes, metadata, addresses, extension members) keeps JSON's last-one-wins rule.
class ParseGuard {
 public:
  explicit ParseGuard(const std::string& name) : name_(name) {}
  bool operator()(int depth, nlohmann::detail::parse_event_t event, json& parsed) {
    using E = nlohmann::detail::parse_event_t;
    check_depth(depth, event, name_);
    if (event == E::object_start || event == E::array_start) open(event == E::object_start);
    else if ((event == E::object_end || event == E::array_end) && !frames_.empty()) frames_.pop_back();
    else if (event == E::key && !frames_.empty()) key(parsed.get<std::string>());
    return true;
  }

 private:
  struct Frame {
    bool free = false;          // free-form data: keys may repeat
    bool city_objects = false;  // the root's "CityObjects": its keys are ids
    std::string last_key;       // the member whose value opens next (objects)
    std::unordered_set<std::string> keys;
  };

  static bool free_form(const std::string& key) {
    return key == "attributes" || key == "metadata" || key == "address" || (!key.empty() && key[0] == '+');
  }

  void open(bool object) {
    Frame f;
    if (!frames_.empty()) {
      const Frame& parent = frames_.back();
      f.free = parent.free || free_form(parent.last_key);
      f.city_objects = object && frames_.size() == 1 && parent.last_key == "CityObjects";
    }
    frames_.push_back(std::move(f));
  }

  void key(const std::string& k) {
    Frame& f = frames_.back();
    f.last_key = k;
    if (f.free || f.keys.insert(k).second) return;
    if (f.city_objects)
      throw InputError(name_ + ": CityObjects id " + shown_id(k) +
                       " appears twice (two objects under one id; one would be lost)");
    throw InputError(name_ + ": key \"" + one_line(k, 60) +
                     "\" appears twice in one object (JSON keeps only one of them; readers differ on which)");
  }

  const std::string& name_;
  std::vector<Frame> frames_;
};

}  // namespace

bool is_cityjson_sequence(const std::string& text) {
  // CityJSONSeq: the first line is a complete "CityJSON" object and more lines follow.
  const auto eol = text.find('\n');
  if (eol == std::string::npos || text.find_first_not_of(" \t\r\n", eol) == std::string::npos) return false;
  try {
    const json first = parse_city_json(std::string_view(text).substr(0, eol), "");
    return first.is_object() && member(first, "type") == "CityJSON";
  } catch (const InputError&) {
    return false;  // the whole text is then parsed, and refused with the reason
  }
}

// nlohmann's message without its tag ("[json.exception.parse_error.101] parse error at ...").
[[noreturn]] void refuse_json(const nlohmann::json::exception& e, const std::string& name) {
  std::string msg = e.what();
  const auto p = msg.find("] ");
  if (p != std::string::npos) msg = msg.substr(p + 2);
  throw InputError(name + ": not valid JSON: " + one_line(msg));
}

nlohmann::ordered_json parse_city_json(std::string_view text, const std::string& name) {
  ParseGuard guard(name);
  try {
    return json::parse(text, std::ref(guard));
  } catch (const json::exception& e) {
    refuse_json(e, name);
  }
}

nlohmann::json parse_json(std::string_view text, const std::string& name) {
  try {
    return nlohmann::json::parse(text, [&](int depth, nlohmann::detail::parse_event_t event, nlohmann::json&) {
      check_depth(depth, event, name);
      return true;
    });
  } catch (const nlohmann::json::exception& e) {
    refuse_json(e, name);
  }
}

Mesh solid_soup(const CityJsonBuilding& b) {
  Mesh solid = b.mesh;
  solid.faces.resize(solid.faces.size() - std::min(solid.faces.size(), std::size_t(std::max(b.fin_faces, 0))));
  return solid;
}

Semantic semantic_from_cityjson(const std::string& type) {
  if (type == "WallSurface") return Semantic::Wall;
  if (type == "RoofSurface") return Semantic::Roof;
  if (type == "GroundSurface") return Semantic::Ground;
  return Semantic::Other;
}

CityJsonFile parse_cityjson(const std::string& text, const std::string& name, const std::string& lod) {
  return Reader(name, lod).read(text);
}

CityJsonFile read_cityjson_document(const nlohmann::ordered_json& doc, const std::string& name,
                                    const std::string& lod) {
  return Reader(name, lod).read_document(doc);
}

CityJsonFile read_cityjson(const std::string& path, const std::string& lod) {
  require_regular_file(path);  // a FIFO would block, /dev/zero be read without end
  const FileKind kind = sniff_file(path);
  if (kind != FileKind::Json && kind != FileKind::Other)
    throw InputError(path + ": not a CityJSON file: the file is " + file_kind_text(kind));
  return read_naming_memory(path, [&] {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open the file");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(path + ": cannot read the file");
    return parse_cityjson(ss.str(), path, lod);
  });
}

}  // namespace lodrefine
