#include "lodrefine/tools/report.h"

#include <algorithm>
#include <cmath>

#include "lodrefine/base/geometry.h"

namespace lodrefine {

namespace {

using nlohmann::json;

// The faces as triangles (x, y, z per corner); with `sources`, each triangle's face's provenance.
std::vector<float> triangles(const Mesh& mesh, std::vector<unsigned char>* sources = nullptr) {
  std::vector<float> out;
  for (const Face& f : mesh.faces) {
    const auto poly = face_points(mesh, f);
    for (const auto& t : triangulate_polygon(poly)) {
      if (sources) sources->push_back(static_cast<unsigned char>(f.provenance));
      for (int k : t)
        for (int c = 0; c < 3; ++c) out.push_back(float(poly[std::size_t(k)][c]));
    }
  }
  return out;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// Text inside <script>: "</" could end the element early and "<!--" changes how the parser
// reads it; U+2028/9 end a line in older JS parsers. All can only occur inside JSON strings or JS
// string literals, where "\u003c" is "<" and "\u2028" the separator.
std::string script_safe(std::string s) {
  for (const std::string from : {"</", "<!--"})
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + 6)) s.replace(at, 1, "\\u003c");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"\xE2\x80\xA8", "\\u2028"}, {"\xE2\x80\xA9", "\\u2029"}})
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
      s.replace(at, from.size(), to);
  return s;
}

std::string cell_text(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", v.get<double>());
    return buf;
  }
  return v.dump(-1, ' ', false, json::error_handler_t::replace);
}

const char* kStyle = R"css(
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; } h3 { font-size: 1em; }
pre { background: #f6f6f6; padding: .8em; overflow-x: auto; }
.plots { display: flex; flex-wrap: wrap; gap: 1em; } .plots svg { max-width: 48%; height: auto; }
table.buildings { border-collapse: collapse; font-size: 12px; }
table.buildings th, table.buildings td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
table.buildings td:nth-child(-n+3) { text-align: left; }
tr.failed { background: #fdd; } tr.kept { background: #ffd; }
.view { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; margin-bottom: 2em; }
.view .footprint svg { width: 560px; height: auto; }
canvas.view3d { border: 1px solid #ccc; cursor: grab; }
.legend { font-size: 12px; }
.map svg { max-width: 100%; height: auto; border: 1px solid #ccc; }
.filter { margin: .5em 0; } .filter label { margin-right: 1em; }
)css";

// Renders every view with one WebGL renderer into its own 2D canvas (browsers allow only a few
// WebGL contexts per page); drag rotates, the wheel zooms, the boxes toggle the layers.
const char* kViewer = R"js(
const data = JSON.parse(document.getElementById('lodrefine-views').textContent);
const src = document.getElementById('three-module').textContent;
const THREE = await import(URL.createObjectURL(new Blob([src], {type: 'text/javascript'})));
const W = 560, H = 420, RANGE = 0.3;  // C2M colour scale: blue -RANGE .. green 0 .. red +RANGE (m)
const renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
renderer.setSize(W, H, false);
renderer.setClearColor(0xffffff, 1);
function c2mColor(d) {
  const t = Math.max(-1, Math.min(1, d / RANGE)), a = Math.abs(t), end = t < 0 ? [0.1, 0.25, 1] : [0.9, 0.05, 0.05];
  return [0.1, 0.7, 0.2].map((g, k) => g + a * (end[k] - g));
}
// Refined faces by provenance (Face::provenance): none and scan orange, model grey, added purple.
const SOURCE_COLORS = [0xe8871e, 0x9a9a9a, 0xe8871e, 0x8e44ad].map(hex => new THREE.Color(hex).toArray());
function meshLayer(tris, color, opacity, sources) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(tris, 3));
  g.computeVertexNormals();
  const bySource = sources && sources.length > 0;
  if (bySource)
    g.setAttribute('color', new THREE.Float32BufferAttribute(
        sources.flatMap(s => { const c = SOURCE_COLORS[s] || SOURCE_COLORS[0]; return [...c, ...c, ...c]; }), 3));
  const group = new THREE.Group();
  group.add(new THREE.Mesh(g, new THREE.MeshLambertMaterial({color: bySource ? 0xffffff : color,
      vertexColors: bySource, transparent: opacity < 1, opacity, side: THREE.DoubleSide, depthWrite: opacity >= 1})));
  group.add(new THREE.LineSegments(new THREE.EdgesGeometry(g, 10),
      new THREE.LineBasicMaterial({color: bySource ? 0x444444 : color})));
  return group;
}
function setup(view, canvas) {
  const scene = new THREE.Scene();
  scene.add(new THREE.AmbientLight(0xffffff, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(0.4, -0.6, 1);
  scene.add(sun);
  const layers = {
    original: meshLayer(view.original, 0x3b6fd6, 0.25),
    refined: view.refined.length ? meshLayer(view.refined, 0xe8871e, 1.0, view.sources) : new THREE.Group(),
  };
  const pg = new THREE.BufferGeometry();
  pg.setAttribute('position', new THREE.Float32BufferAttribute(view.points, 3));
  pg.setAttribute('color', new THREE.Float32BufferAttribute(view.c2m.flatMap(c2mColor), 3));
  layers.points = new THREE.Points(pg, new THREE.PointsMaterial({size: 2.5, sizeAttenuation: false, vertexColors: true}));
  for (const l of Object.values(layers)) scene.add(l);
  const box = new THREE.Box3().setFromArray(view.original);
  const center = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, W / H, size / 100, size * 20);
  camera.up.set(0, 0, 1);
  const orbit = {theta: -Math.PI / 3, phi: 1.0, radius: 1.15 * size};
  const ctx = canvas.getContext('2d');
  function draw() {
    const s = Math.sin(orbit.phi);
    camera.position.set(center.x + orbit.radius * s * Math.cos(orbit.theta),
                        center.y + orbit.radius * s * Math.sin(orbit.theta), center.z + orbit.radius * Math.cos(orbit.phi));
    camera.lookAt(center);
    renderer.render(scene, camera);
    ctx.drawImage(renderer.domElement, 0, 0, canvas.width, canvas.height);
  }
  let drag = null;
  canvas.addEventListener('pointerdown', e => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointermove', e => {
    if (!drag) return;
    orbit.theta -= (e.clientX - drag[0]) * 0.01;
    orbit.phi = Math.max(0.05, Math.min(Math.PI - 0.05, orbit.phi - (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY];
    draw();
  });
  canvas.addEventListener('wheel', e => { e.preventDefault(); orbit.radius *= Math.exp(e.deltaY * 0.001); draw(); });
  for (const box of canvas.parentElement.querySelectorAll('input[data-layer]'))
    box.addEventListener('change', () => { layers[box.dataset.layer].visible = box.checked; draw(); });
  draw();
}
const canvases = document.querySelectorAll('canvas.view3d');
data.forEach((view, i) => {
  setup(view, canvases[i]);
  const r = canvases[i].getBoundingClientRect();
  canvases[i].dataset.rect = [r.left + scrollX, r.top + scrollY, r.width, r.height].map(Math.round).join(',');
});
document.documentElement.dataset.rendered = String(data.length);
)js";

// The filter by outcome (HtmlReport::filter): a box unticked hides its rows and views; a link to
// a hidden view (the district map's) ticks its outcome again and shows it.
const char* kFilter = R"js(
(() => {
  const boxes = [...document.querySelectorAll('.filter input[data-outcome]')];
  const apply = () => {
    const on = new Set(boxes.filter(b => b.checked).map(b => b.dataset.outcome));
    for (const el of document.querySelectorAll('tr[data-outcome], section[data-outcome]'))
      el.hidden = !on.has(el.dataset.outcome);
  };
  for (const b of boxes) b.addEventListener('change', apply);
  const reveal = () => {
    const el = location.hash.length > 1 ? document.getElementById(location.hash.slice(1)) : null;
    if (!el || !el.hidden) return;
    const box = boxes.find(b => b.dataset.outcome === el.dataset.outcome);
    if (box) box.checked = true;
    apply();
    el.scrollIntoView();
  };
  addEventListener('hashchange', reveal);
  reveal();
})();
)js";

// First in <head>: records script errors (and console.error) where a headless test sees them.
const char* kErrorTrap = R"js(
(() => {
  const note = m => { const el = document.documentElement;
    el.dataset.errors = (el.dataset.errors ? el.dataset.errors + ' | ' : '') + m; };
  addEventListener('error', e => note(e.message));
  addEventListener('unhandledrejection', e => note(String(e.reason)));
  const err = console.error.bind(console);
  console.error = (...a) => { note(a.join(' ')); err(...a); };
})();
)js";

// The attributes of a filtered element (a row, a view) of `outcome`: its data-outcome, and
// hidden when its box starts unticked. Nothing without a filter.
std::string filtered(const HtmlReport& r, const std::string& outcome) {
  if (r.filter.empty() || outcome.empty()) return "";
  const bool off = std::find(r.filter_off.begin(), r.filter_off.end(), outcome) != r.filter_off.end();
  return " data-outcome=\"" + html_escape(outcome) + "\"" + (off ? " hidden" : "");
}

// The filter's boxes, each with its outcome's count of rows.
std::string filter_html(const HtmlReport& r) {
  if (r.filter.empty()) return "";
  std::string h = "<div class=\"filter\">Show:";
  for (const std::string& outcome : r.filter) {
    const auto n = std::count_if(r.rows.begin(), r.rows.end(),
                                 [&](const json& row) { return row.value("outcome", std::string()) == outcome; });
    const bool off = std::find(r.filter_off.begin(), r.filter_off.end(), outcome) != r.filter_off.end();
    h += " <label><input type=\"checkbox\" data-outcome=\"" + html_escape(outcome) + "\"" + (off ? "" : " checked") +
         "> " + html_escape(outcome) + " (" + std::to_string(n) + ")</label>";
  }
  return h + "</div>\n";
}

}  // namespace

std::string view_anchor(const std::string& id) {
  static const char* hex = "0123456789abcdef";
  std::string out = "view-";
  for (char c : id) {
    const auto u = static_cast<unsigned char>(c);
    const bool plain =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-';
    if (plain) out += c;
    else out += {'_', hex[u >> 4], hex[u & 15]};
  }
  return out;
}

BuildingView make_building_view(const std::string& id, const Mesh& original, const Mesh& refined,
                                const std::vector<Vec3>& points, const std::vector<double>& c2m,
                                std::size_t max_points) {
  BuildingView v;
  v.id = id;
  v.original = triangles(original);
  v.refined = triangles(refined, &v.sources);
  if (std::all_of(v.sources.begin(), v.sources.end(), [](unsigned char p) { return p == 0; })) v.sources.clear();
  const std::size_t n = std::min(points.size(), c2m.size());
  const std::size_t step = max_points == 0 ? n + 1 : std::max<std::size_t>(1, (n + max_points - 1) / max_points);
  for (std::size_t i = 0; i < n; i += step) {
    for (int c = 0; c < 3; ++c) v.points.push_back(float(points[i][c]));
    v.c2m.push_back(float(c2m[i]));
  }
  return v;
}

std::string html_report(const HtmlReport& r) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" + html_escape(r.title) +
                  "</title>\n<script>" + kErrorTrap + "</script>\n<style>" + kStyle + "</style></head>\n<body>\n";
  h += "<h1>" + html_escape(r.title) + "</h1>\n<h2>" + html_escape(r.summary_heading) + "</h2>\n<pre>" +
       html_escape(r.table1) + "</pre>\n<div class=\"plots\">" + r.histogram_svg + r.boxplot_svg + "</div>\n";
  if (!r.map_svg.empty()) h += "<div class=\"map\">" + r.map_svg + "</div>\n";

  h += "<h2>" + html_escape(r.table_heading) + "</h2>\n" + filter_html(r) + "<table class=\"buildings\"><thead><tr>";
  for (const auto& c : r.columns) h += "<th>" + html_escape(c[1].get<std::string>()) + "</th>";
  h += "</tr></thead><tbody>\n";
  std::vector<std::string> shown;
  for (const auto& v : r.views) shown.push_back(v.id);
  for (const auto& row : r.rows) {
    const std::string id = row.value("id", std::string()), outcome = row.value("outcome", std::string());
    h += "<tr class=\"" + html_escape(outcome) + "\"" + filtered(r, outcome) + ">";
    for (const auto& c : r.columns) {
      const std::string text = html_escape(cell_text(row.value(c[0].get<std::string>(), json())));
      const bool link = c[0] == "id" && std::find(shown.begin(), shown.end(), id) != shown.end();
      h += "<td>" + (link ? "<a href=\"#" + view_anchor(id) + "\">" + text + "</a>" : text) + "</td>";
    }
    h += "</tr>\n";
  }
  h += "</tbody></table>\n";

  if (!r.views.empty()) {
    h += "<h2>Before / after</h2>\n<p class=\"legend\">" + html_escape(r.views_legend) + "</p>\n";
    json views = json::array();
    for (const auto& v : r.views) {
      h += "<section id=\"" + view_anchor(v.id) + "\"" + filtered(r, v.outcome) + "><h3>" + html_escape(v.id) +
           " &mdash; " + html_escape(v.caption) + "</h3>\n<div class=\"view\"><div class=\"footprint\">" +
           v.footprint_svg +
           "</div><div><canvas class=\"view3d\" width=\"560\" height=\"420\"></canvas><div class=\"legend\">";
      for (const char* layer : {"original", "refined", "points"})
        h +=
            std::string("<label><input type=\"checkbox\" checked data-layer=\"") + layer + "\"> " + layer + "</label> ";
      h += "</div></div></div></section>\n";
      views.push_back({{"id", v.id},
                       {"original", v.original},
                       {"refined", v.refined},
                       {"sources", v.sources},
                       {"points", v.points},
                       {"c2m", v.c2m}});
    }
    h += "<script type=\"application/json\" id=\"lodrefine-views\">" +
         script_safe(views.dump(-1, ' ', false, json::error_handler_t::replace)) + "</script>\n";
    h += "<script type=\"text/plain\" id=\"three-module\">" + script_safe(three_module_js()) + "</script>\n";
    h += std::string("<script type=\"module\">") + kViewer + "</script>\n";
  } else {
    h += "<script>document.documentElement.dataset.rendered = '0';</script>\n";
  }
  if (!r.filter.empty()) h += std::string("<script>") + kFilter + "</script>\n";
  return h + "</body></html>\n";
}

}  // namespace lodrefine
