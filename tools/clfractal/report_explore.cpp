#include "report_explore.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "clfractal/local.hpp"
#include "clfractal/mesh_cluster.hpp"
#include "report_html.hpp"

using json = nlohmann::json;

namespace cli::explore {
namespace {

template <class T>
void put(std::string& out, T x) {
    for (std::size_t i = 0; i < sizeof(T); ++i) out += char((std::uint64_t(x) >> (8 * i)) & 0xff);
}

WebMesh encode(const std::vector<std::array<float, 3>>& positions, const std::vector<float>& ld,
               const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::array<double, 3>& lo,
               const std::array<double, 3>& hi) {
    WebMesh w;
    w.lo = lo, w.hi = hi;
    w.vertices = positions.size();
    w.triangles = triangles.size();
    w.wide_indices = positions.size() > 65535;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            const double extent = hi[k] - lo[k];
            const double q = extent > 0 ? std::round((positions[i][k] - lo[k]) / extent * 65535) : 0;
            put(w.positions, std::uint16_t(std::clamp(q, 0.0, 65535.0)));
        }
        const clfractal::Rgb c = clfractal::ld_colour(ld.empty() ? NAN : ld[i]);
        w.colours += char(c.r), w.colours += char(c.g), w.colours += char(c.b);
    }
    for (const auto& t : triangles)
        for (std::uint32_t i : t) w.wide_indices ? put(w.indices, i) : put(w.indices, std::uint16_t(i));
    return w;
}

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return "";
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Text for inside a <script> element: "</" cannot close it early.
std::string script_safe_json(const json& j) {
    std::string s = j.dump();
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        out += s[i];
        if (s[i] == '<' && i + 1 < s.size() && s[i + 1] == '/') out += '\\';
    }
    return out;
}

}  // namespace

WebMesh web_mesh(const clfractal::Mesh& mesh, std::size_t triangles) {
    if (triangles < 1 || triangles > max_triangles)
        throw std::invalid_argument("web_mesh: the triangle budget must be 1 .. " + std::to_string(max_triangles));
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
    if (!mesh.positions.empty()) {
        lo = hi = {mesh.positions[0][0], mesh.positions[0][1], mesh.positions[0][2]};
        for (const auto& p : mesh.positions)
            for (int k = 0; k < 3; ++k) lo[k] = std::min<double>(lo[k], p[k]), hi[k] = std::max<double>(hi[k], p[k]);
    }
    if (mesh.triangles.size() <= triangles) {
        WebMesh w = encode(mesh.positions, mesh.ld, mesh.triangles, lo, hi);
        w.triangles_full = mesh.triangles.size();
        return w;
    }
    // The triangle count falls about as the square of the cell: start there, grow by 15%.
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30});
    double edge = 0;
    for (const auto& t : mesh.triangles) {
        const auto& a = mesh.positions[t[0]];
        const auto& b = mesh.positions[t[1]];
        edge += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
    edge /= double(mesh.triangles.size());
    double cell = std::max(extent / double(1u << 20), edge * std::sqrt(double(mesh.triangles.size()) / double(triangles)));
    for (;;) {
        clfractal::MeshClusters clusters(cell);
        clusters.add(mesh);
        if (clusters.triangles() <= triangles) {
            const clfractal::Mesh c = clusters.mesh();
            WebMesh w = encode(c.positions, c.ld, c.triangles, lo, hi);
            w.triangles_full = mesh.triangles.size();
            w.cell = cell;
            return w;
        }
        cell *= 1.15;
    }
}

std::optional<Three> load_three(std::string& why) {
    const char* env = std::getenv("CLFRACTAL_THREE_DIR");
    Three t;
    t.dir = env && *env ? env : "/usr/share/javascript/three";
    const std::string three = read_text(t.dir + "/three.min.js");
    const std::string orbit = read_text(t.dir + "/examples/js/controls/OrbitControls.js");
    if (three.empty() || orbit.empty()) {
        why = "three.js (Debian's libjs-three: three.min.js, examples/js/controls/OrbitControls.js) is not in " + t.dir;
        return std::nullopt;
    }
    for (const std::string* s : {&three, &orbit}) {
        std::string lower(*s);
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (lower.find("</script") != std::string::npos || lower.find("<!--") != std::string::npos) {
            why = "three.js in " + t.dir + " holds '</script' or '<!--' and cannot be inlined";
            return std::nullopt;
        }
    }
    t.js = "<script>\n" + three + "\n</script>\n<script>\n" + orbit + "\n</script>\n";
    return t;
}

json facts(const Choice& c) {
    return {{"role", c.role},          {"isovalue", c.isovalue},          {"slice_z", c.slice_z},
            {"triangles", c.mesh.triangles}, {"triangles_full", c.mesh.triangles_full},
            {"vertices", c.mesh.vertices},   {"cell", c.mesh.cell}};
}

namespace {

// The page's own script: the 3D view (three.js, OrbitControls), the switch, the slice, the
// curves as SVG drawn here (two line plots with hover: a few dozen lines, no chart library).
const char* const script = R"JS(
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("report-plot").textContent);
  var choices = JSON.parse(document.getElementById("report-choices").textContent);
  var section = document.getElementById("explore");
  section.hidden = false;
  function bytes(b64) {
    var s = atob(b64), a = new Uint8Array(s.length);
    for (var i = 0; i < s.length; ++i) a[i] = s.charCodeAt(i);
    return a;
  }
  // The 3D views: "where the noise is" (the switch sets its isovalue) and, beside it, the
  // recommended surface; one scene, one camera, so turning either turns both.
  var holders = [document.getElementById("view3d"), document.getElementById("view3d-ref")];
  var fixed = holders[1] ? +holders[1].dataset.choice : -1;
  if (fixed < 0 && holders[1]) holders[1].parentNode.hidden = true;
  var scene = new THREE.Scene();
  var camera = new THREE.PerspectiveCamera(35, holders[0].clientWidth / holders[0].clientHeight, 0.01, 1000);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.AmbientLight(0xffffff, 0.5));
  var light = new THREE.DirectionalLight(0xffffff, 0.6);
  camera.add(light);
  scene.add(camera);
  var views = [], meshes = [null, null], shown = [null, fixed];
  holders.forEach(function (holder, k) {
    if (!holder || (k === 1 && fixed < 0)) return;
    var renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(1);
    renderer.setSize(holder.clientWidth, holder.clientHeight);
    renderer.setClearColor(0xffffff);
    holder.appendChild(renderer.domElement);
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    if (views.length) controls.target = views[0].controls.target;
    views.push({k: k, holder: holder, renderer: renderer, controls: controls});
  });
  function render() {
    views.forEach(function (v) {
      meshes.forEach(function (m, j) { if (m) m.visible = j === v.k; });
      v.renderer.render(scene, camera);
      v.holder.dataset.rendered = shown[v.k] === null ? "" : choices[shown[v.k]].text;
    });
  }
  views.forEach(function (v) { v.controls.addEventListener("change", render); });
  function geometry(c) {
    var q = new Uint16Array(bytes(c.positions).buffer), n = q.length / 3, p = new Float32Array(q.length);
    for (var i = 0; i < n; ++i)
      for (var k = 0; k < 3; ++k) p[3 * i + k] = c.lo[k] + (q[3 * i + k] / 65535) * (c.hi[k] - c.lo[k]);
    var g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(p, 3));
    g.setAttribute("color", new THREE.BufferAttribute(bytes(c.colours), 3, true));
    var ib = bytes(c.indices).buffer;
    g.setIndex(new THREE.BufferAttribute(c.wide ? new Uint32Array(ib) : new Uint16Array(ib), 1));
    g.computeVertexNormals();
    return g;
  }
  var material = new THREE.MeshLambertMaterial({vertexColors: THREE.VertexColors, side: THREE.DoubleSide});
  function frame(shown) {  // the camera on the box of the surfaces shown, once
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    shown.forEach(function (c) {
      if (c.triangles > 0)
        for (var k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], c.lo[k]); hi[k] = Math.max(hi[k], c.hi[k]); }
    });
    if (!(lo[0] <= hi[0])) return;
    var centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
    var r = Math.max(1e-6, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    camera.near = r / 100; camera.far = r * 100; camera.updateProjectionMatrix();
    camera.position.copy(centre).add(new THREE.Vector3(0.9, -2.6, 1.1).normalize().multiplyScalar(3.2 * r));
    views[0].controls.target.copy(centre);
    views.forEach(function (v) { v.controls.update(); v.controls.saveState(); });
  }
  function place(k, i) {  // choice i into view k
    var c = choices[i];
    if (meshes[k]) { scene.remove(meshes[k]); meshes[k].geometry.dispose(); meshes[k] = null; }
    shown[k] = i;
    if (c.triangles > 0) {
      meshes[k] = new THREE.Mesh(geometry(c), material);
      scene.add(meshes[k]);
    }
    document.getElementById(k ? "view3d-ref-caption" : "view3d-caption").textContent = c.role + ": isovalue " +
      c.text + ", " + c.triangles + " triangles" + (c.cell > 0 ? " (clustered from " + c.triangles_full + ")" : "");
  }
  // The slice and the curves' marker follow the switched view.
  var slice = document.getElementById("slice"), caption = document.getElementById("slice-caption");
  var buttons = section.querySelectorAll("[data-isovalue]");
  var markers = [];
  function show(i) {
    var c = choices[i];
    place(0, i);
    slice.src = "data:image/png;base64," + c.slice;
    caption.textContent = "axial slice z = " + c.slice_z + " at isovalue " + c.text +
      ", the contour in yellow, LD blended where defined";
    for (var b = 0; b < buttons.length; ++b) buttons[b].classList.toggle("on", b === i);
    markers.forEach(function (m) { m(c.isovalue); });
    render();
  }
  for (var b = 0; b < buttons.length; ++b)
    buttons[b].addEventListener("click", (function (i) { return function () { show(i); }; })(b));
  document.getElementById("reset").addEventListener("click", function () { views[0].controls.reset(); render(); });
  window.addEventListener("resize", function () {
    views.forEach(function (v) { v.renderer.setSize(v.holder.clientWidth, v.holder.clientHeight); });
    camera.aspect = holders[0].clientWidth / holders[0].clientHeight; camera.updateProjectionMatrix(); render();
  });

  // The curves.
  var curve = data.isovalue.map(function (s, i) {
    return {isovalue: s, fd: data.fd[i], count: data.count[i], components: data.components[i],
            verdict: data.verdicts[data.verdict[i]], ratio: data.ratio[i]};
  });
  var tip = document.getElementById("tip");
  var NS = "http://www.w3.org/2000/svg";
  function el(name, attrs, parent) {
    var e = document.createElementNS(NS, name);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function ticks(lo, hi, n) {
    var step = Math.pow(10, Math.floor(Math.log10((hi - lo) / n || 1)));
    [1, 2, 5, 10].some(function (m) { if ((hi - lo) / (step * m) <= n) { step *= m; return true; } return false; });
    var t = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) t.push(+v.toPrecision(12));
    return t;
  }
  function fmt(x, d) { return x === null || x === undefined || !isFinite(x) ? "n/a" : (+x.toPrecision(d)).toString(); }
  function plot(id, value, label, log) {
    var svg = document.getElementById(id), W = 520, H = 300, L = 62, R = 12, T = 14, B = 40;
    svg.setAttribute("viewBox", "0 0 " + W + " " + H);
    var xs = curve.map(function (e) { return e.isovalue; });
    var x0 = Math.min.apply(null, xs), x1 = Math.max.apply(null, xs);
    if (x1 === x0) { x0 -= 0.5; x1 += 0.5; }
    var ys = curve.map(value).filter(function (y) { return y !== null && isFinite(y); });
    var y0 = ys.length ? Math.min.apply(null, ys) : 0, y1 = ys.length ? Math.max.apply(null, ys) : 1;
    if (!log && id === "plot-fd") { y0 = Math.min(y0, data.clean_fd); y1 = Math.max(y1, data.clean_fd); }
    if (y1 === y0) { y0 -= 0.5; y1 += 0.5; }
    var pad = 0.05 * (y1 - y0); y0 -= pad; y1 += pad;
    function X(x) { return L + (x - x0) / (x1 - x0) * (W - L - R); }
    function Y(y) { return H - B - (y - y0) / (y1 - y0) * (H - T - B); }
    data.clean_bands.forEach(function (b) {
      el("rect", {x: X(b[0]), y: T, width: Math.max(1, X(b[1]) - X(b[0])), height: H - T - B,
                  fill: "#d8f0d8"}, svg);
    });
    if (id === "plot-fd")
      el("line", {x1: L, x2: W - R, y1: Y(data.clean_fd), y2: Y(data.clean_fd),
                  stroke: "#2a8a2a", "stroke-dasharray": "4 3"}, svg);
    el("rect", {x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#888"}, svg);
    ticks(x0, x1, 6).forEach(function (t) {
      el("line", {x1: X(t), x2: X(t), y1: H - B, y2: H - B + 4, stroke: "#444"}, svg);
      el("text", {x: X(t), y: H - B + 16, "text-anchor": "middle", "font-size": 11}, svg).textContent = t;
    });
    ticks(y0, y1, 5).forEach(function (t) {
      el("line", {x1: L - 4, x2: L, y1: Y(t), y2: Y(t), stroke: "#444"}, svg);
      el("text", {x: L - 6, y: Y(t) + 4, "text-anchor": "end", "font-size": 11}, svg).textContent =
        log ? fmt(Math.pow(10, t), 3) : t;
    });
    el("text", {x: (L + W - R) / 2, y: H - 6, "text-anchor": "middle", "font-size": 12}, svg).textContent = "isovalue s";
    el("text", {x: 14, y: (T + H - B) / 2, "text-anchor": "middle", "font-size": 12,
                transform: "rotate(-90 14 " + (T + H - B) / 2 + ")"}, svg).textContent = label;
    var d = "", up = false;
    curve.forEach(function (e) {
      var y = value(e);
      if (y === null || !isFinite(y)) { up = false; return; }
      d += (up ? "L" : "M") + X(e.isovalue).toFixed(1) + " " + Y(y).toFixed(1);
      up = true;
    });
    el("path", {d: d, fill: "none", stroke: "#1f5fa8", "stroke-width": 1.5}, svg);
    data.recommended.forEach(function (r) {
      el("line", {x1: X(r), x2: X(r), y1: T, y2: H - B, stroke: "#2a8a2a", "stroke-width": 1.5},
         svg);
    });
    if (data.noisiest !== null)
      el("line", {x1: X(data.noisiest), x2: X(data.noisiest), y1: T, y2: H - B,
                  stroke: "#c62828", "stroke-width": 1.5, "stroke-dasharray": "5 3"}, svg);
    var mark = el("line", {y1: T, y2: H - B, stroke: "#222", "stroke-width": 2.5, opacity: 0.7}, svg);
    markers.push(function (s) { mark.setAttribute("x1", X(s)); mark.setAttribute("x2", X(s)); });
    var hover = el("line", {y1: T, y2: H - B, stroke: "#888", visibility: "hidden"}, svg);
    svg.addEventListener("mousemove", function (ev) {
      var box = svg.getBoundingClientRect(), sx = (ev.clientX - box.left) / box.width * W;
      var s = x0 + (sx - L) / (W - L - R) * (x1 - x0), best = 0;
      for (var i = 1; i < curve.length; ++i)
        if (Math.abs(curve[i].isovalue - s) < Math.abs(curve[best].isovalue - s)) best = i;
      var e = curve[best];
      hover.setAttribute("x1", X(e.isovalue)); hover.setAttribute("x2", X(e.isovalue));
      hover.setAttribute("visibility", "visible");
      tip.textContent = "isovalue " + fmt(e.isovalue, 8) + "  D = " + fmt(e.fd, 4) + "  count I(s) = " + e.count +
        "  components = " + e.components + "  verdict: " + e.verdict + "  r(s) = " + fmt(e.ratio, 3);
      tip.style.left = (ev.pageX + 14) + "px"; tip.style.top = (ev.pageY + 14) + "px";
      tip.hidden = false;
    });
    svg.addEventListener("mouseleave", function () { tip.hidden = true; hover.setAttribute("visibility", "hidden"); });
  }
  if (curve.length) {
    plot("plot-fd", function (e) { return e.fd; }, "D(s)", false);
    plot("plot-components", function (e) { return e.components > 0 ? Math.log10(e.components) : null; },
         "components (log scale)", true);
  }
  frame(fixed >= 0 ? [choices[0], choices[fixed]] : [choices[0]]);
  if (fixed >= 0) place(1, fixed);
  show(0);
})();
)JS";

// A double with `digits` significant digits (what the plots need, a third of the JSON's text).
json rounded(const json& x, int digits) {
    if (!x.is_number()) return nullptr;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, x.get<double>());
    return std::stod(buf);
}

}  // namespace

json plot_data(const json& report) {
    json p = {{"isovalue", json::array()}, {"fd", json::array()},      {"count", json::array()},
              {"components", json::array()}, {"verdict", json::array()}, {"verdicts", json::array()},
              {"ratio", json::array()}};
    std::map<double, json> ratio;
    const json surface = report.at("noise").value("surface", json::object());
    if (surface.is_object())
        for (const json& e : surface.value("per_isovalue", json::array()))
            ratio[e.at("isovalue").get<double>()] = e.at("ratio");
    std::map<std::string, int> code;
    for (const json& e : report["curve"]) {
        const double s = e["isovalue"].get<double>();
        p["isovalue"].push_back(s);
        p["fd"].push_back(rounded(e["fd"], 6));
        p["count"].push_back(e["counts"].empty() ? json(nullptr) : e["counts"][0]);
        p["components"].push_back(e["components"]);
        const std::string v = e["verdict"].get<std::string>();
        const auto [it, added] = code.emplace(v, int(code.size()));
        if (added) p["verdicts"].push_back(v);
        p["verdict"].push_back(it->second);
        const auto r = ratio.find(s);
        p["ratio"].push_back(r == ratio.end() ? json(nullptr) : rounded(r->second, 4));
    }
    p["clean_fd"] = report["advice"]["clean_fd"];
    p["clean_bands"] = json::array();
    for (const json& b : report["clean_bands"]) p["clean_bands"].push_back({b["first"], b["last"]});
    p["recommended"] = json::array();
    for (const json& r : report["recommended"]) p["recommended"].push_back(r["isovalue"]);
    p["noisiest"] = report["noisiest"].is_null() ? json(nullptr) : report["noisiest"]["isovalue"];
    return p;
}

std::string section(const json& report, const std::vector<Choice>& choices, const Three& three) {
    std::ostringstream o;
    o << "<section id=\"explore\" hidden><h2>Explore</h2>\n<div class=\"switch\">";
    for (std::size_t i = 0; i < choices.size(); ++i)
        o << "<button type=\"button\" data-isovalue=\"" << html::escape(choices[i].text) << "\">"
          << html::escape(choices[i].role) << ": " << html::escape(choices[i].text) << "</button>";
    // The recommended surface beside the switched view, when the switched view opens elsewhere.
    int fixed = -1;
    if (!report["recommended"].empty())
        for (std::size_t i = 1; i < choices.size(); ++i)
            if (choices[i].isovalue == report["recommended"][0]["isovalue"].get<double>()) fixed = int(i);
    o << "</div>\n<div class=\"pair\"><figure><h3>" << (fixed > 0 ? "Where the noise is" : "The surface")
      << "</h3><div id=\"view3d\" class=\"view3d\"></div><figcaption id=\"view3d-caption\"></figcaption></figure>"
         "<figure><h3>The recommended surface, the same camera</h3><div id=\"view3d-ref\" class=\"view3d\" "
         "data-choice=\""
      << fixed
      << "\"></div><figcaption id=\"view3d-ref-caption\"></figcaption></figure></div>\n"
         "<p class=\"note\">Drag either view to turn both, wheel: zoom, right drag: move "
         "<button type=\"button\" id=\"reset\">reset view</button><br>Local dimension (LD): <span class=\"bar\">"
         "</span> 2.0 &hellip; <b>2.2</b> (blue: smooth) &hellip; <b>2.5</b> (red: rough, the noise) &hellip; 2.7, "
         "<span class=\"undefined\"></span> undefined</p>\n"
         "<div class=\"pair\"><figure><img id=\"slice\" alt=\"slice at the chosen isovalue\"><figcaption "
         "id=\"slice-caption\"></figcaption></figure><figure><svg id=\"plot-fd\" role=\"img\"></svg>"
         "<figcaption>D(s): clean bands shaded green, the clean limit dashed, recommended isovalues green, the "
         "noisiest red dashed, the one shown black; point to read a value</figcaption></figure></div>\n"
         "<div class=\"pair\"><figure class=\"half\"><svg id=\"plot-components\" role=\"img\"></svg><figcaption>"
         "isosurface components (cube connectivity), log scale, the same marks</figcaption></figure></div>\n"
         "<div id=\"tip\" hidden></div></section>\n";
    json data = json::array();
    for (const Choice& c : choices) {
        json e = facts(c);
        e["text"] = c.text;
        e["lo"] = c.mesh.lo, e["hi"] = c.mesh.hi;
        e["wide"] = c.mesh.wide_indices;
        e["positions"] = html::base64(c.mesh.positions);
        e["colours"] = html::base64(c.mesh.colours);
        e["indices"] = html::base64(c.mesh.indices);
        e["slice"] = html::base64(c.slice_png.get());
        data.push_back(std::move(e));
    }
    o << "<script type=\"application/json\" id=\"report-plot\">" << script_safe_json(plot_data(report)) << "</script>\n"
      << "<script type=\"application/json\" id=\"report-choices\">" << script_safe_json(data) << "</script>\n"
      << three.js << "<script id=\"report-script\">" << script << "</script>\n";
    return o.str();
}

}  // namespace cli::explore
