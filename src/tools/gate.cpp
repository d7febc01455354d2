#include "lodrefine/tools/gate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"
#include "lodrefine/formats/cityjson.h"

namespace lodrefine {
namespace {

using nlohmann::json;
using Figure = std::optional<double> BuildingFigures::*;
using PooledFigure = std::optional<double> RunFigures::*;

constexpr int kBaselineVersion = 1;

// The distances compared per building and pooled, as named in the baseline and the lines.
const std::pair<const char*, Figure> kBuildingDistances[] = {{"c2m_rmse", &BuildingFigures::c2m_rmse},
                                                             {"c2m_mae", &BuildingFigures::c2m_mae},
                                                             {"truth_facade_rmse", &BuildingFigures::truth_facade_rmse},
                                                             {"truth_roof_rmse", &BuildingFigures::truth_roof_rmse}};
const std::pair<const char*, PooledFigure> kPooledDistances[] = {{"c2m_rmse", &RunFigures::c2m_rmse},
                                                                 {"c2m_mae", &RunFigures::c2m_mae},
                                                                 {"truth_facade_rmse", &RunFigures::truth_facade_rmse},
                                                                 {"truth_roof_rmse", &RunFigures::truth_roof_rmse}};

std::string num(double v, int decimals = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string metres(const std::optional<double>& v) { return v ? num(*v) + " m" : std::string("not measured"); }

json optional_json(const std::optional<double>& v) { return v && std::isfinite(*v) ? json(*v) : json(nullptr); }

// A value of the wrong kind refuses the file, naming the key and what it holds.
[[noreturn]] void wrong_value(const std::string& where, const char* key, const char* expected, const json& v) {
  throw InputError(where + ": \"" + key + "\" must be " + expected + ", not " + shown_json(v));
}

std::optional<double> optional_number(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  if (!j[key].is_number() || !std::isfinite(j[key].get<double>())) wrong_value(where, key, "a finite number", j[key]);
  return j[key].get<double>();
}

// A text (absent or null: none): a string. Read unchecked, an outcome ["refined"] became "failed"
// and its regressions were never flagged.
std::optional<std::string> text_field(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  if (!j[key].is_string()) wrong_value(where, key, "a string", j[key]);
  return j[key].get<std::string>();
}

// A count (absent: 0): a non-negative integer. Read unchecked, -1 became 2^64 - 1.
std::size_t count_field(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) return 0;
  if (!j[key].is_number_unsigned()) wrong_value(where, key, "a non-negative integer", j[key]);
  return j[key].get<std::size_t>();
}

// --- XML ---------------------------------------------------------------------------------

// The code point of the UTF-8 sequence at s[i] and its length; -1 for bytes that are not one
// (overlong forms, surrogates, beyond U+10FFFF, truncated).
std::pair<long, std::size_t> decode_utf8(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  if (b < 0x80) return {b, 1};
  const std::size_t n = b >= 0xF0 && b <= 0xF4 ? 4 : b >= 0xE0 ? 3 : b >= 0xC2 && b < 0xE0 ? 2 : 0;
  if (n == 0 || i + n > s.size()) return {-1, 1};
  long cp = b & (0x7F >> n);
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return {-1, 1};
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  const long min[] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < min[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return {-1, 1};
  return {cp, n};
}

// XML 1.0's Char production.
bool xml_char(long cp) {
  return cp == 0x9 || cp == 0xA || cp == 0xD || (cp >= 0x20 && cp <= 0xD7FF) || (cp >= 0xE000 && cp <= 0xFFFD) ||
         (cp >= 0x10000 && cp <= 0x10FFFF);
}

std::string attribute(const char* name, const std::string& value) {
  return std::string(" ") + name + "=\"" + xml_escape(value) + "\"";
}

// --- checks ------------------------------------------------------------------------------

struct Checker {
  double tolerance;
  GateVerdict& verdict;

  // `text` quotes outcomes and reasons of the run's reports and the baseline: escaped, as a CR
  // and escape codes in them printed a "gate: … passed" line over the verdict.
  void fail(const std::string& building, const std::string& check, const std::string& figure, const std::string& text) {
    verdict.failures.push_back(
        {building, check, figure, escaped_line((building.empty() ? "pooled: " : building + ": ") + text)});
  }

  // A distance that grew beyond the tolerance, or is no longer measured.
  void distance(const std::string& building, const std::string& check, const char* figure,
                const std::optional<double>& old_value, const std::optional<double>& new_value) {
    if (!old_value) return;
    if (!new_value)
      return fail(building, check, figure, std::string(figure) + " " + metres(old_value) + " -> not measured");
    const double worse = *new_value - *old_value;
    if (worse > tolerance)
      fail(building, check, figure,
           std::string(figure) + " " + metres(old_value) + " -> " + metres(new_value) + " (worse by " + num(worse) +
               " m, tolerance " + num(tolerance) + " m)");
  }

  void building(const BuildingFigures& now, const BuildingFigures& old) {
    if (outcome_rank(now.outcome) < outcome_rank(old.outcome))
      return fail(now.id, "baseline", "outcome",
                  "outcome " + std::string(outcome_name(old.outcome)) + " -> " + outcome_name(now.outcome) +
                      (now.reason.empty() ? "" : " (" + now.reason + ")"));
    for (const auto& [name, field] : kBuildingDistances) distance(now.id, "baseline", name, old.*field, now.*field);
    if (old.watertight && !now.watertight) fail(now.id, "baseline", "watertight", "watertight yes -> no");
  }

  void pooled(const RunFigures& now, const RunFigures& old) {
    for (const auto& [name, field] : kPooledDistances) distance("", "baseline", name, old.*field, now.*field);
    if (now.failed > old.failed)
      fail("", "baseline", "failed", "failed " + std::to_string(old.failed) + " -> " + std::to_string(now.failed));
    if (now.watertight_rate < old.watertight_rate - 1e-9)
      fail("", "baseline", "watertight_rate",
           "watertight_rate " + num(old.watertight_rate, 3) + " -> " + num(now.watertight_rate, 3));
  }
};

// A gate's value in a run (nullopt: not measured) and whether it is per building.
struct GateFigure {
  bool per_building = false;
  Figure building = nullptr;
  std::optional<double> pooled;
};

GateFigure gate_figure(const std::string& name, const RunFigures& run) {
  const std::string figure = name.substr(4);  // without "max_" / "min_"
  if (figure.rfind("building_", 0) == 0) {
    for (const auto& [key, field] : kBuildingDistances)
      if (figure == "building_" + std::string(key) + "_refined") return {true, field, std::nullopt};
  }
  if (figure == "failed_buildings") return {false, nullptr, double(run.failed)};
  if (figure == "refined_buildings") return {false, nullptr, double(run.refined)};
  if (figure == "watertight_rate") return {false, nullptr, run.watertight_rate};
  if (figure == "c2m_rmse_ratio")
    return {false, nullptr,
            run.c2m_rmse && run.c2m_rmse_original && *run.c2m_rmse_original > 0
                ? std::optional<double>(*run.c2m_rmse / *run.c2m_rmse_original)
                : std::nullopt};
  for (const auto& [key, field] : kPooledDistances)
    if (figure == std::string(key) + "_refined") return {false, nullptr, run.*field};
  return {};
}

bool breaches(const std::string& gate, double value, double limit) {
  return gate.rfind("max_", 0) == 0 ? value > limit : value < limit;
}

// Counts without decimals, distances and rates with four.
std::string value_text(double v) { return v == std::floor(v) && std::abs(v) < 1e15 ? num(v, 0) : num(v); }

std::string limit_text(const std::string& gate, double value, double limit) {
  return gate + " " + value_text(value) + (gate.rfind("max_", 0) == 0 ? " > " : " < ") + value_text(limit);
}

void check_gates(const RunFigures& run, const Gates& gates, Checker& c) {
  for (const auto& [gate, limit] : gates) {
    const GateFigure g = gate_figure(gate, run);
    if (!g.per_building) {
      c.verdict.pooled_checks.push_back(gate);
      if (!g.pooled) c.fail("", gate, gate, gate + " not measured in this run");
      else if (breaches(gate, *g.pooled, limit)) c.fail("", gate, gate, limit_text(gate, *g.pooled, limit));
      continue;
    }
    for (const BuildingFigures& b : run.buildings) {
      const std::optional<double>& v = b.*g.building;
      if (v && breaches(gate, *v, limit)) c.fail(b.id, gate, gate, limit_text(gate, *v, limit));
    }
  }
}

void add_missing(const RunFigures& run, const RunFigures& baseline, Checker& c) {
  std::set<std::string> ids;
  for (const auto& b : run.buildings) ids.insert(b.id);
  for (const auto& b : baseline.buildings)
    if (!ids.count(b.id)) {
      c.verdict.buildings.push_back(b.id);
      c.fail(b.id, "baseline", "missing",
             "missing from the run (baseline outcome " + std::string(outcome_name(b.outcome)) + ")");
    }
}

std::string testcase(const std::string& classname, const std::string& name, const std::vector<const GateLine*>& lines,
                     const std::string& note) {
  std::string x = "    <testcase" + attribute("classname", classname) + attribute("name", name);
  if (lines.empty() && note.empty()) return x + "/>\n";
  x += ">\n";
  if (!lines.empty()) {
    std::string all;
    for (const GateLine* l : lines) all += l->text + "\n";
    x += "      <failure" + attribute("message", lines.front()->text) + attribute("type", lines.front()->check) + ">" +
         xml_escape(all) + "</failure>\n";
  }
  if (!note.empty()) x += "      <system-out>" + xml_escape(note) + "</system-out>\n";
  return x + "    </testcase>\n";
}

RunFigures parse_baseline(const std::string& text, const std::string& source);

}  // namespace

int outcome_rank(Outcome outcome) {
  switch (outcome) {
    case Outcome::Refined: return 3;
    case Outcome::Kept:
    case Outcome::Repaired: return 2;
    case Outcome::KeptInvalid: return 1;
    case Outcome::Untouched:
    case Outcome::Failed: return 0;
  }
  return 0;
}

std::string baseline_json(const RunFigures& run) {
  json pooled = {{"buildings", run.buildings.size()},
                 {"failed", run.failed},
                 {"refined", run.refined},
                 {"watertight_rate", run.watertight_rate},
                 {"c2m_rmse_original", optional_json(run.c2m_rmse_original)}};
  for (const auto& [name, field] : kPooledDistances) pooled[name] = optional_json(run.*field);
  json buildings = json::array();
  for (const BuildingFigures& b : run.buildings) {
    json j = {{"id", b.id},
              {"outcome", outcome_name(b.outcome)},
              {"reason", b.reason},
              {"watertight", b.watertight},
              {"facades_moved", b.facades_moved},
              {"moved_max", optional_json(b.moved_max)}};
    for (const auto& [name, field] : kBuildingDistances) j[name] = optional_json(b.*field);
    buildings.push_back(std::move(j));
  }
  const json doc = {
      {"format", "lodrefine-baseline"}, {"version", kBaselineVersion}, {"pooled", pooled}, {"buildings", buildings}};
  return doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

RunFigures read_baseline(const std::string& text, const std::string& source) {
  try {
    return parse_baseline(text, source);
  } catch (const json::exception&) {  // every value is checked by kind; this is a last net
    throw InputError(source + ": not a baseline this lodrefine reads (a value of the wrong kind)");
  }
}

namespace {
RunFigures parse_baseline(const std::string& text, const std::string& source) {
  const json doc = parse_json(text, source);  // nesting bounded: 100,000 levels crashed eval
  if (!doc.is_object() || doc.value("format", json()) != "lodrefine-baseline")
    throw InputError(source + ": not a lodrefine baseline (write one with eval --dir RUN --write-baseline FILE)");
  if (doc.value("version", json()) != kBaselineVersion)
    throw InputError(source + ": baseline version " + shown_json(doc.value("version", json())) +
                     ", this lodrefine reads " + std::to_string(kBaselineVersion) + "; write it again");
  RunFigures run;
  const json pooled = doc.value("pooled", json::object());
  if (!pooled.is_object()) throw InputError(source + ": \"pooled\" is not an object");
  run.failed = count_field(pooled, "failed", source);
  run.refined = count_field(pooled, "refined", source);
  run.watertight_rate = optional_number(pooled, "watertight_rate", source).value_or(0.0);
  if (run.watertight_rate < 0 || run.watertight_rate > 1)
    wrong_value(source, "watertight_rate", "a share from 0 to 1", pooled["watertight_rate"]);
  run.c2m_rmse_original = optional_number(pooled, "c2m_rmse_original", source);
  for (const auto& [name, field] : kPooledDistances) run.*field = optional_number(pooled, name, source);
  const json buildings = doc.value("buildings", json::array());
  if (!buildings.is_array()) throw InputError(source + ": \"buildings\" is not an array");
  std::set<std::string> ids;
  for (const json& j : buildings) {
    if (!j.is_object() || !j.value("id", json()).is_string()) throw InputError(source + ": a building without an id");
    BuildingFigures b;
    b.id = j["id"].get<std::string>();
    if (!ids.insert(b.id).second) throw InputError(source + ": building " + shown_id(b.id) + " listed twice");
    const std::string where = source + ": building " + shown_id(b.id);
    // Absent, or a text no lodrefine writes: failed (ranked last, as any other text was).
    b.outcome = parse_outcome(text_field(j, "outcome", where).value_or("failed")).value_or(Outcome::Failed);
    b.reason = text_field(j, "reason", where).value_or("");
    if (j.contains("watertight") && !j["watertight"].is_boolean())
      wrong_value(where, "watertight", "true or false", j["watertight"]);
    b.watertight = j.value("watertight", false);
    b.facades_moved = count_field(j, "facades_moved", where);
    b.moved_max = optional_number(j, "moved_max", where);
    for (const auto& [name, field] : kBuildingDistances) b.*field = optional_number(j, name, where);
    run.buildings.push_back(std::move(b));
  }
  return run;
}
}  // namespace

const std::map<std::string, std::string>& gate_names() {
  static const std::map<std::string, std::string> names = {
      {"max_failed_buildings", "buildings whose refinement or evaluation failed"},
      {"min_refined_buildings", "buildings refined"},
      {"min_watertight_rate", "share of watertight refined models (0..1)"},
      {"max_c2m_rmse_refined", "pooled C2M RMSE of the facade points to the refined models (m)"},
      {"max_c2m_mae_refined", "pooled C2M MAE of the facade points to the refined models (m)"},
      {"max_c2m_rmse_ratio", "pooled C2M RMSE refined / original (below 1: the run improves the fit)"},
      {"max_truth_facade_rmse_refined", "pooled truth facade RMSE of the refined models (m)"},
      {"max_truth_roof_rmse_refined", "pooled truth roof RMSE of the refined models (m)"},
      {"max_building_c2m_rmse_refined", "each building's C2M RMSE (m)"},
      {"max_building_c2m_mae_refined", "each building's C2M MAE (m)"},
      {"max_building_truth_facade_rmse_refined", "each building's truth facade RMSE (m)"},
      {"max_building_truth_roof_rmse_refined", "each building's truth roof RMSE (m)"}};
  return names;
}

Gates read_gates(const std::string& text, const std::string& source) {
  const json doc = parse_json(text, source);  // nesting bounded: 100,000 levels crashed eval
  if (!doc.is_object()) throw InputError(source + ": gates must be a JSON object of gate name -> limit");
  Gates gates;
  for (const auto& [key, value] : doc.items()) {
    if (key.rfind('_', 0) == 0) continue;  // a comment
    if (!gate_names().count(key)) {
      std::string known;
      for (const auto& [name, what] : gate_names()) known += (known.empty() ? "" : ", ") + name;
      throw InputError(source + ": unknown gate " + shown_id(key) + " (known: " + known + ")");
    }
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      throw InputError(source + ": gate " + shown_id(key) + " is not a finite number");
    gates[key] = value.get<double>();
  }
  return gates;
}

namespace {
// Ids as a baseline stores them (JSON holds UTF-8 only): bytes that are not UTF-8 as U+FFFD, so
// a run matches the baseline it wrote.
RunFigures with_utf8_ids(RunFigures run) {
  for (auto& b : run.buildings) {
    std::string id;
    for (std::size_t i = 0; i < b.id.size();) {
      const auto [cp, len] = decode_utf8(b.id, i);
      id += cp < 0 ? std::string("\xEF\xBF\xBD") : b.id.substr(i, len);
      i += len;
    }
    b.id = std::move(id);
  }
  return run;
}
}  // namespace

GateVerdict check_run(const RunFigures& run_as_read, const RunFigures* baseline_as_read, const Gates* gates,
                      double tolerance) {
  const RunFigures run = with_utf8_ids(run_as_read);
  const std::optional<RunFigures> baseline_ids =
      baseline_as_read ? std::optional(with_utf8_ids(*baseline_as_read)) : std::nullopt;
  const RunFigures* baseline = baseline_ids ? &*baseline_ids : nullptr;
  GateVerdict verdict;
  Checker c{tolerance, verdict};
  for (const auto& b : run.buildings) verdict.buildings.push_back(b.id);
  if (baseline) {
    std::map<std::string, const BuildingFigures*> old;
    for (const auto& b : baseline->buildings) old[b.id] = &b;
    for (const auto& b : run.buildings) {
      const auto it = old.find(b.id);
      if (it == old.end()) verdict.new_buildings.push_back(b.id);
      else c.building(b, *it->second);
    }
    add_missing(run, *baseline, c);
    verdict.pooled_checks.push_back("baseline");
    c.pooled(run, *baseline);
  }
  if (gates) check_gates(run, *gates, c);
  std::sort(verdict.buildings.begin(), verdict.buildings.end());
  std::sort(verdict.new_buildings.begin(), verdict.new_buildings.end());
  return verdict;
}

std::string junit_xml(const GateVerdict& v, const std::string& name) {
  auto lines_of = [&](bool pooled, const std::string& key) {
    std::vector<const GateLine*> out;
    for (const GateLine& l : v.failures)
      if (pooled ? (l.building.empty() && l.check == key) : (!l.building.empty() && l.building == key))
        out.push_back(&l);
    return out;
  };
  std::string buildings, pooled;
  std::size_t building_failures = 0, pooled_failures = 0;
  for (const std::string& id : v.buildings) {
    const auto lines = lines_of(false, id);
    building_failures += !lines.empty();
    const bool is_new = std::binary_search(v.new_buildings.begin(), v.new_buildings.end(), id);
    buildings += testcase("lodrefine.building", id, lines, is_new ? "new building: not in the baseline" : "");
  }
  for (const std::string& check : v.pooled_checks) {
    const auto lines = lines_of(true, check);
    pooled_failures += !lines.empty();
    pooled += testcase("lodrefine.pooled", check, lines, "");
  }
  auto suite = [](const char* suite_name, std::size_t tests, std::size_t failures, const std::string& cases) {
    return std::string("  <testsuite") + attribute("name", suite_name) + attribute("tests", std::to_string(tests)) +
           attribute("failures", std::to_string(failures)) + " errors=\"0\">\n" + cases + "  </testsuite>\n";
  };
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites" + attribute("name", name) +
         attribute("tests", std::to_string(v.buildings.size() + v.pooled_checks.size())) +
         attribute("failures", std::to_string(building_failures + pooled_failures)) + ">\n" +
         suite("buildings", v.buildings.size(), building_failures, buildings) +
         suite("pooled", v.pooled_checks.size(), pooled_failures, pooled) + "</testsuites>\n";
}

std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto [cp, len] = decode_utf8(s, i);
    switch (cp) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      case '\t': out += "&#9;"; break;
      case '\n': out += "&#10;"; break;
      case '\r': out += "&#13;"; break;
      default: out += xml_char(cp) ? s.substr(i, len) : std::string("\xEF\xBF\xBD");  // U+FFFD
    }
    i += len;
  }
  return out;
}

}  // namespace lodrefine
