// The libcitygml part of the CityGML reader, built as the module lodrefine_citygml.so and loaded
// by src/formats/citygml_module.cpp only when a CityGML file is read (citygml_module.h). The buildings
// are turned into a CityJSON document that the CityJSON reader reads, so both formats give the
// same meshes (ring splitting, degenerate and inner rings, semantics) and the city-file writer
// can treat a CityGML input like a CityJSON one.
#include <citygml/citygml.h>
#include <citygml/citygmllogger.h>
#include <citygml/citymodel.h>
#include <citygml/geometry.h>
#include <citygml/linearring.h>
#include <citygml/polygon.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>
#include <set>
#include <streambuf>
#include <unordered_map>

#include "../citygml_module.h"
#include "lodrefine/base/files.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/formats/cityjson_write.h"

namespace lodrefine {
namespace {

using json = nlohmann::ordered_json;
using citygml::CityObject;
using Type = CityObject::CityObjectsType;
using io_citygml::RenamedIds;

// libcitygml gives objects and surfaces without a gml:id ids that embed the file path
// ("genID_/path/file.gml_12_34"): never written out as ids.
bool generated_id(const std::string& id) { return id.rfind("genID_", 0) == 0; }

// Keeps the first error libcitygml reports, for a one-line message.
class Logger : public citygml::CityGMLLogger {
 public:
  Logger() : CityGMLLogger(LOGLEVEL::LL_ERROR) {}
  void log(LOGLEVEL, const std::string& message, const char*, int) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (first_.empty()) first_ = message;
  }
  std::string first() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return first_;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::string first_;
};

// libcitygml reads a std::istream: this one reads the checked text in place (no copy).
// It also holds memory in reserve until the text is all read: libcitygml's endDocument then
// calls gluNewTess and uses its result unchecked (null when malloc fails under a memory limit:
// a segfault), so the reserve is freed for it.
class TextBuffer : public std::streambuf {
 public:
  explicit TextBuffer(std::string& text) : reserve_(new char[kEndReserve]) {
    setg(text.data(), text.data(), text.data() + text.size());
  }

 protected:
  int_type underflow() override {
    reserve_.reset();
    return traits_type::eof();
  }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    if (off != 0 || dir != std::ios_base::cur) return pos_type(off_type(-1));
    return pos_type(gptr() - eback());  // tellg(), which Xerces asks for its position
  }

 private:
  static constexpr std::size_t kEndReserve = std::size_t(1) << 20;  // gluNewTess takes a few KB
  std::unique_ptr<char[]> reserve_;
};

const char* semantic_type(Type t) {
  switch (t) {
    case Type::COT_WallSurface: return "WallSurface";
    case Type::COT_RoofSurface: return "RoofSurface";
    case Type::COT_GroundSurface: return "GroundSurface";
    case Type::COT_ClosureSurface: return "ClosureSurface";
    case Type::COT_OuterCeilingSurface: return "OuterCeilingSurface";
    case Type::COT_OuterFloorSurface: return "OuterFloorSurface";
    default: return nullptr;
  }
}

json attributes_json(const citygml::Object& o) {
  json a = json::object();
  for (const auto& [key, value] : o.getAttributes()) {
    const std::string s = value.asString();
    const auto t = value.getType();
    if (t == citygml::AttributeType::Double || t == citygml::AttributeType::Integer) {
      char* end = nullptr;
      const double d = std::strtod(s.c_str(), &end);
      if (!s.empty() && *end == '\0' && std::isfinite(d)) {
        if (t == citygml::AttributeType::Integer && d == std::floor(d) && std::abs(d) < 9e15) a[key] = (long long)d;
        else a[key] = d;
        continue;
      }
    }
    a[key] = s;
  }
  return a;
}

// Builds the CityJSON document: vertices shared through a map of quantised coordinates.
class Converter {
 public:
  Converter(std::string path, const CityJsonTransform& transform) : path_(std::move(path)), transform_(transform) {}

  void building(const CityObject& o, const std::string& parent_id, json& objects) {
    const std::string id = object_id(o);
    json obj = json::object();
    obj["type"] = o.getType() == Type::COT_BuildingPart ? "BuildingPart" : "Building";
    json attrs = attributes_json(o);
    if (!attrs.empty()) obj["attributes"] = std::move(attrs);
    json geometry = lod2_geometry(o);
    if (!geometry.is_null()) obj["geometry"] = json::array({std::move(geometry)});
    if (!parent_id.empty()) obj["parents"] = json::array({parent_id});
    json children = json::array();
    std::vector<const CityObject*> parts;
    for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) {
      const CityObject& c = o.getChildCityObject(i);
      if (c.getType() == Type::COT_BuildingPart) parts.push_back(&c), children.push_back(object_id(c));
    }
    if (!children.empty()) obj["children"] = std::move(children);
    // ids are unique (object_id): appended, not looked up (ordered_json searches its keys in
    // order, quadratic over a file of many buildings: 100,000 took 10 s).
    objects.get_ref<json::object_t&>().emplace_back(id, std::move(obj));
    for (const CityObject* c : parts) building(*c, id, objects);
  }

  // The gml:ids of a building and its parts, so that no name made up later takes one.
  void reserve_ids(const CityObject& o) {
    if (!generated_id(o.getId())) file_ids_.insert(o.getId());
    for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i)
      if (o.getChildCityObject(i).getType() == Type::COT_BuildingPart) reserve_ids(o.getChildCityObject(i));
  }

  const RenamedIds& renamed() const { return renamed_; }

  json vertices() const {
    json v = json::array();
    for (const auto& q : vertices_) v.push_back(json::array({q[0], q[1], q[2]}));
    return v;
  }

 private:
  // Every building keeps a name of its own: a gml:id met again becomes "<id>~2" (with a note),
  // an object without one "building-<n>", neither taking an id the file gives another object.
  std::string object_id(const CityObject& o) {
    auto it = ids_.find(&o);
    if (it != ids_.end()) return it->second;
    const std::string given = o.getId();
    const bool generated = generated_id(given);
    std::string id = given;
    if (generated || taken_.count(given)) {
      // The search for a free "<given>~<k>" / "building-<k>" resumes where the last one for the
      // same name ended (names only get taken, so a skipped one stays taken): from the start, a
      // file giving one gml:id to 20,000 buildings took 27 s, quadratic.
      std::size_t& k = generated ? next_generated_ : next_suffix_[given];
      k = std::max(k, generated ? ids_.size() + 1 : 2);
      for (;; ++k) {
        id = generated ? "building-" + std::to_string(k) : given + "~" + std::to_string(k);
        if (!taken_.count(id) && !file_ids_.count(id)) break;
      }
    }
    if (!generated && id != given) renamed_.emplace_back(given, id);
    taken_.insert(id);
    return ids_[&o] = id;
  }

  // The LoD2 surfaces of a building: its boundary surfaces if it has any, else its own geometry.
  json lod2_geometry(const CityObject& o) {
    json boundaries = json::array(), surfaces = json::array(), values = json::array();
    std::set<const citygml::Polygon*> seen;
    for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) {
      const CityObject& c = o.getChildCityObject(i);
      const char* sem = semantic_type(c.getType());
      if (sem == nullptr) continue;
      const std::size_t before = boundaries.size();
      for (unsigned g = 0; g < c.getGeometriesCount(); ++g) add_polygons(c.getGeometry(g), seen, boundaries);
      if (boundaries.size() == before) continue;
      json s = {{"type", sem}};
      json attrs = attributes_json(c);
      if (!attrs.empty()) s["attributes"] = std::move(attrs);
      surfaces.push_back(std::move(s));
      for (std::size_t k = before; k < boundaries.size(); ++k) values.push_back(surfaces.size() - 1);
    }
    if (boundaries.empty()) {
      for (unsigned g = 0; g < o.getGeometriesCount(); ++g) add_polygons(o.getGeometry(g), seen, boundaries);
      values = json::array();
      for (std::size_t k = 0; k < boundaries.size(); ++k) values.push_back(nullptr);
    }
    if (boundaries.empty()) return nullptr;
    json g = {{"type", "MultiSurface"}, {"lod", "2"}, {"boundaries", std::move(boundaries)}};
    if (!surfaces.empty()) g["semantics"] = {{"surfaces", std::move(surfaces)}, {"values", std::move(values)}};
    return g;
  }

  void add_polygons(const citygml::Geometry& g, std::set<const citygml::Polygon*>& seen, json& boundaries) {
    if (g.getLOD() != 2) return;
    for (unsigned i = 0; i < g.getPolygonsCount(); ++i) {
      const auto p = g.getPolygon(i);
      // Rings libcitygml could not read (bad posList) come back empty: no surface.
      if (!p || !p->exteriorRing() || p->exteriorRing()->getVertices().size() < 3 || !seen.insert(p.get()).second)
        continue;
      json surface = json::array({ring(*p->exteriorRing())});
      for (const auto& hole : p->interiorRings())
        if (hole) surface.push_back(ring(*hole));
      boundaries.push_back(std::move(surface));
    }
    for (unsigned i = 0; i < g.getGeometriesCount(); ++i) add_polygons(g.getGeometry(i), seen, boundaries);
  }

  json ring(const citygml::LinearRing& r) {
    json out = json::array();
    for (const auto& v : r.getVertices()) {
      const Vec3 p(v.x, v.y, v.z);
      if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxCoordinate)
        throw InputError(path_ + ": a vertex of ring " +
                         (generated_id(r.getId()) ? std::string("(no id)") : r.getId()) +
                         " is not finite or beyond 1e9 m");
      const auto q = transform_.quantise(p);
      auto [it, added] = index_.emplace(q, int(vertices_.size()));
      if (added) vertices_.push_back(q);
      out.push_back(it->second);
    }
    // GML closes a ring by repeating its first position; a CityJSON ring does not repeat it.
    while (out.size() > 1 && out.back() == out.front()) out.erase(out.size() - 1);
    return out;
  }

  std::string path_;
  CityJsonTransform transform_;
  std::unordered_map<const CityObject*, std::string> ids_;
  std::set<std::string> file_ids_, taken_;
  std::unordered_map<std::string, std::size_t> next_suffix_;  // per gml:id met again
  std::size_t next_generated_ = 0;
  RenamedIds renamed_;
  std::unordered_map<GridKey, int, GridKeyHash> index_;  // quantised coordinates reach 1e13 units
  std::vector<std::array<long long, 3>> vertices_;
};

void collect_buildings(const CityObject& o, std::vector<const CityObject*>& out) {
  if (o.getType() == Type::COT_Building) {
    out.push_back(&o);
    return;  // its parts are written with it
  }
  for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) collect_buildings(o.getChildCityObject(i), out);
}

// The bounding box of every vertex libcitygml read (for the transform's translate).
void extend_box(const citygml::Geometry& g, Eigen::AlignedBox3d& box) {
  for (unsigned i = 0; i < g.getPolygonsCount(); ++i) {
    const auto p = g.getPolygon(i);
    if (!p || !p->exteriorRing()) continue;
    for (const auto& v : p->exteriorRing()->getVertices())
      if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) box.extend(Vec3(v.x, v.y, v.z));
  }
  for (unsigned i = 0; i < g.getGeometriesCount(); ++i) extend_box(g.getGeometry(i), box);
}

void extend_box(const CityObject& o, Eigen::AlignedBox3d& box) {
  for (unsigned i = 0; i < o.getGeometriesCount(); ++i) extend_box(o.getGeometry(i), box);
  for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) extend_box(o.getChildCityObject(i), box);
}

// What lodrefine_citygml_to_cityjson does, throwing.
json to_cityjson(const std::string& path, std::string& text, const std::string& crs_url, RenamedIds& renamed) {
  citygml::ParserParams params;
  params.tesselate = false;    // keep polygons as written (rings, not triangles)
  params.keepVertices = true;  // rings keep their vertices after finishing
  const auto logger = std::make_shared<Logger>();
  std::shared_ptr<const citygml::CityModel> model;
  std::string why;
  try {
    TextBuffer buffer(text);
    std::istream in(&buffer);
    model = citygml::load(in, params, logger);
  } catch (const std::exception& e) {
    why = e.what();
  } catch (...) {  // xerces throws its own exception types (malformed XML)
    why = "malformed XML";
  }
  std::string().swap(text);  // the model holds what is needed now
  if (!model) {
    if (!logger->first().empty()) why = logger->first();
    for (char& c : why)
      if (c == '\n' || c == '\r') c = ' ';
    throw InputError(path + ": CityGML parse error" + (why.empty() ? std::string() : ": " + why.substr(0, 300)));
  }
  std::vector<const CityObject*> buildings;
  Eigen::AlignedBox3d box;
  for (unsigned i = 0; i < model->getNumRootCityObjects(); ++i) {
    collect_buildings(model->getRootCityObject(int(i)), buildings);
    extend_box(model->getRootCityObject(int(i)), box);
  }
  CityJsonTransform transform;
  transform.scale = Vec3::Constant(kCityGmlResolution);
  transform.translate = box.isEmpty() ? Vec3::Zero() : Vec3(box.min().array().floor());
  Converter conv(path, transform);
  json objects = json::object();
  for (const CityObject* b : buildings) conv.reserve_ids(*b);
  for (const CityObject* b : buildings) conv.building(*b, "", objects);
  renamed = conv.renamed();

  json doc = json::object();
  doc["type"] = "CityJSON";
  doc["version"] = "2.0";
  doc["transform"] = {{"scale", {transform.scale.x(), transform.scale.y(), transform.scale.z()}},
                      {"translate", {transform.translate.x(), transform.translate.y(), transform.translate.z()}}};
  if (!crs_url.empty()) doc["metadata"] = {{"referenceSystem", crs_url}};
  doc["CityObjects"] = std::move(objects);
  doc["vertices"] = conv.vertices();
  return doc;
}

}  // namespace
}  // namespace lodrefine

extern "C" __attribute__((visibility("default"))) const char* lodrefine_citygml_abi() {
  return lodrefine::io_citygml::kAbiTag;
}

namespace {

// Set when operator new fails during a conversion. libcitygml catches std::exception around
// its parse (logging "Unexpected Exception" and returning what it has) and Xerces turns
// bad_alloc into its own OutOfMemoryException (caught below as "malformed XML"): without this
// flag memory running out would read as a bad file, or as a model missing buildings.
std::atomic<bool> out_of_memory{false};

void note_out_of_memory() {
  out_of_memory = true;
  throw std::bad_alloc();
}

// Installs note_out_of_memory for one conversion.
class OutOfMemoryWatch {
 public:
  OutOfMemoryWatch() : before_(std::set_new_handler(note_out_of_memory)) { out_of_memory = false; }
  ~OutOfMemoryWatch() { std::set_new_handler(before_); }
  OutOfMemoryWatch(const OutOfMemoryWatch&) = delete;
  OutOfMemoryWatch& operator=(const OutOfMemoryWatch&) = delete;

 private:
  std::new_handler before_;
};

}  // namespace

extern "C" __attribute__((visibility("default"))) int lodrefine_citygml_to_cityjson(
    const char* path, std::string* text, const char* crs_url, nlohmann::ordered_json* doc,
    lodrefine::io_citygml::RenamedIds* renamed, std::string* error) {
  using namespace lodrefine::io_citygml;
  const OutOfMemoryWatch watch;
  int status = kOk;
  try {
    *doc = lodrefine::to_cityjson(path, *text, crs_url, *renamed);
  } catch (const lodrefine::InputError& e) {
    *error = e.what();
    status = kInputError;
  } catch (const std::bad_alloc&) {
    out_of_memory = true;
  } catch (const std::exception& e) {
    *error = e.what();
    status = kFailure;
  } catch (...) {
    *error = "unknown failure in the CityGML module";
    status = kFailure;
  }
  if (!out_of_memory) return status;
  try {
    *doc = nlohmann::ordered_json();
    *error = std::string(path) + ": out of memory reading the CityGML file";
  } catch (...) {  // no room even for the message: the caller names the file
    error->clear();
  }
  return kOutOfMemory;
}
