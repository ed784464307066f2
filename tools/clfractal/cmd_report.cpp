// clfractal report: one self-contained HTML page (no network, images inline) answering
// "which isovalues are clean, and how noisy is my scan?" for one volume, and the same
// numbers as JSON.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "clfractal/advice.hpp"
#include "clfractal/analysis.hpp"
#include "clfractal/components.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/mesh_cluster.hpp"
#include "clfractal/render.hpp"
#include "cli.hpp"
#include "output.hpp"
#include "plots.hpp"
#include "report_explore.hpp"
#include "report_html.hpp"
#include "report_page.hpp"

using namespace clfractal;
using json = nlohmann::json;

namespace cli {
namespace {

struct ReportArgs : ReportSettings {
    std::string volume, output, json_path;
    RawArgs raw;
};


// The pictures of one isovalue: its LD field, the LD-coloured mesh, the busiest axial slice.
struct Pictures {
    Volume ld;
    /// The static preview's mesh: the whole LD-coloured surface, or its clusters (at most
    /// preview_triangles) when the surface is large.
    Mesh mesh;
    /// The 3D view's mesh when the surface was clustered here (within the view's budget).
    std::optional<Mesh> web;
    std::uint64_t triangles_full = 0;
    double web_cell = 0;
    std::size_t z = 0;
    std::shared_future<std::string> slice_png;
};

// A figure's PNG, drawn by gnuplot (a process of its own) while the report goes on.
std::shared_future<std::string> drawn_later(Figure f, std::string what) {
    return std::async(std::launch::async, [f = std::move(f), what = std::move(what)] { return f.png(what); }).share();
}

// A surface of more cubes than this is clustered as it is extracted, never held whole (about
// 100 bytes per cube whole).
constexpr std::uint64_t whole_surface_cubes = std::uint64_t(1) << 20;
constexpr std::size_t preview_triangles = 300000;

// The LD-coloured surface of `cubes` intersected cubes: whole when small; else clustered slab
// by slab with cells that leave about 16 times the view's budget (a cube holds about 1.5 units
// of surface, a cluster about two triangles), then coarsened to the preview's and the view's
// budgets (docs/definitions.md §37).
void surface(const Volume& v, double isovalue, std::uint64_t cubes, std::size_t budget, Pictures& p) {
    if (cubes <= whole_surface_cubes) {
        p.mesh = extract_isosurface(v, isovalue);
        color_by_ld(p.mesh, p.ld);
        p.triangles_full = p.mesh.triangles.size();
        return;
    }
    const double unit = std::cbrt(v.spacing[0] * v.spacing[1] * v.spacing[2]);
    const double cell = unit * std::max(0.5, std::sqrt(double(cubes) / (12.0 * double(budget))));
    const MeshClusters fine = cluster_isosurface(v, isovalue, cell, &p.ld);
    std::uint32_t factor = 1;
    p.mesh = bounded_mesh(fine, preview_triangles);
    p.web = bounded_mesh(fine, budget, &factor);
    p.triangles_full = fine.input_triangles();
    p.web_cell = fine.cell() * factor;
}

Pictures pictures(Context& ctx, const Volume& v, const Analysis& an, std::size_t k, const std::string& role,
                  int window, std::size_t budget) {
    const double isovalue = an.isovalues.value(k);
    const std::string s = an.isovalues.text(k);
    progress(role + " isovalue " + s + ": LD field, mesh, slice");
    Pictures p;
    p.ld = local_fractal_dimension(ctx, v, isovalue, window);
    surface(v, isovalue, an.curve.counts[0][k], budget, p);
    p.z = busiest_slice(v, isovalue);
    const SliceView sv = render_slice(v, p.z, isovalue, &p.ld);
    ImageFigure sf;
    sf.image = &sv.image;
    sf.dx = v.spacing[0], sf.dy = v.spacing[1];
    sf.axes = true;
    sf.xlabel = "x", sf.ylabel = "y";
    sf.title = role + ": axial slice z = " + std::to_string(p.z) + ", LD overlaid where defined";
    sf.label = "isovalue " + s + ", z = " + std::to_string(p.z);
    sf.lines = sv.contour;
    sf.line_title = "contour f = " + s;
    p.slice_png = drawn_later(image_figure(sf), "report: slice at " + s);
    return p;
}

// One isovalue shown in static pictures: its LD-coloured mesh and an axial slice.
struct View {
    std::string role;  ///< "recommended (clean)", "noisiest well-populated"
    std::size_t index = 0;
    double isovalue = 0;
    std::shared_future<std::string> mesh_png, slice_png;
    json facts;
};

View make_view(const Pictures& p, const IsovalueSet& iso, std::size_t j, const std::string& role, int window) {
    View w;
    w.role = role;
    w.index = j;
    w.isovalue = iso.value(j);
    const std::string s = iso.text(j);
    const LocalSummary sum = summarize_local(p.ld);
    RenderOptions ro;
    ro.width = 640, ro.height = 520;
    const Image preview = render_mesh(p.mesh, ro);
    ImageFigure mf;
    mf.image = &preview;
    mf.title = role + ": LD-coloured isosurface (marching cubes, window " + std::to_string(window) + ")";
    mf.label = "isovalue " + s;
    w.mesh_png = drawn_later(image_figure(mf), "report: mesh preview at " + s);
    w.slice_png = p.slice_png;
    w.facts = {{"role", role},
               {"isovalue", w.isovalue},
               {"slice_z", p.z},
               {"ld_defined", sum.defined},
               {"ld_mean", fd_json(sum.defined ? sum.mean : NAN)},
               {"ld_above_red", sum.above_red}};
    return w;
}

// A row of numbers of the JSON: one <td> per pointer.
std::string cells(const json& data, const std::vector<std::pair<std::string, int>>& pointers) {
    std::string row;
    for (const auto& [p, digits] : pointers) row += "<td>" + html::number(data, p, digits) + "</td>";
    return row;
}

// The volume's facts as a table.
std::string volume_section(const json& j, const std::string& name) {
    using html::escape;
    using html::number;
    std::ostringstream s_volume;
    s_volume << "<section id=\"volume\"><h2>Volume</h2><table>\n"
      << "<tr><th class=\"l\">file</th><td class=\"l\">" << escape(name) << "</td></tr>\n"
      << "<tr><th class=\"l\">format</th><td class=\"l\">";
    for (const auto& line : j["volume"]["format"]) s_volume << escape(line.get<std::string>()) << "<br>";
    s_volume << "</td></tr>\n<tr><th class=\"l\">dims</th><td class=\"l\">" << number(j, "/volume/dims/0") << " &times; "
      << number(j, "/volume/dims/1") << " &times; " << number(j, "/volume/dims/2") << " ("
      << number(j, "/volume/vertices") << " vertices)</td></tr>\n"
      << "<tr><th class=\"l\">type</th><td class=\"l\">" << escape(j["volume"]["type"].get<std::string>())
      << "</td></tr>\n<tr><th class=\"l\">spacing</th><td class=\"l\">" << number(j, "/volume/spacing/0", 6) << " &times; "
      << number(j, "/volume/spacing/1", 6) << " &times; " << number(j, "/volume/spacing/2", 6) << "</td></tr>\n"
      << "<tr><th class=\"l\">values</th><td class=\"l\">" << number(j, "/volume/value_range/0", 8) << " .. "
      << number(j, "/volume/value_range/1", 8) << "</td></tr>\n"
      << "<tr><th class=\"l\">isovalues</th><td class=\"l\">" << number(j, "/isovalues/count") << " ("
      << number(j, "/isovalues/first", 8) << " .. " << number(j, "/isovalues/last", 8) << ")</td></tr>\n"
      << "</table></section>\n";
    return s_volume.str();
}

// The answer: the isovalue to use (always one), what denoising makes the scan clean when
// nothing is, the noise level and D4.
std::string answer_section(const json& j) {
    using html::escape;
    using html::number;
    std::ostringstream o;
    o << "<section id=\"answer\"><h2>Answer</h2>\n";
    if (j["recommended"].empty()) {
        o << "<p class=\"big\">No surface: no cube is intersected at any isovalue.</p></section>\n";
        return o.str();
    }
    const std::string best = "/recommended/0";
    const std::string facts = " (" + j["recommended"][0]["verdict"].get<std::string>() + ", D = " +
                              number(j, best + "/fd", 4) + ", " + number(j, best + "/count") + " cubes, " +
                              number(j, best + "/components") + " components)";
    if (j["clean"].get<bool>()) {
        o << "<p class=\"big\">Use isovalue " << number(j, best + "/isovalue", 8) << facts << ".</p>\n";
    } else {
        o << "<p class=\"big\">No isovalue is clean (D(s) &le; " << number(j, "/advice/clean_fd", 4)
          << " on a well-populated surface). The cleanest: isovalue " << number(j, best + "/isovalue", 8) << facts
          << ".</p>\n";
        const json& tried = j["denoise"]["attempts"];
        std::size_t i = 0;
        while (i < tried.size() && !tried[i]["clean"].get<bool>()) ++i;
        if (i < tried.size() && !tried[i]["recommended"].empty()) {
            const std::string p = "/denoise/attempts/" + std::to_string(i);
            o << "<p class=\"big\">After the " << escape(tried[i]["filter"].get<std::string>());
            if (tried[i]["targeted"].get<bool>())
                o << " (where LD &gt; " << number(j, p + "/threshold", 3) << " at isovalue "
                  << number(j, p + "/isovalue", 8) << ")";
            o << ", which changes a share " << number(j, p + "/changed_share", 3) << " of the vertices, isovalues "
              << number(j, p + "/recommended/0/first", 8) << " .. " << number(j, p + "/recommended/0/last", 8)
              << " are clean: use " << number(j, p + "/recommended/0/isovalue", 8) << " (D = "
              << number(j, p + "/recommended/0/fd", 4) << ").</p>\n<p><code>"
              << escape(tried[i]["command"].get<std::string>()) << "</code></p>\n";
        } else if (!tried.empty()) {
            o << "<p>None of the denoising tried (targeted median, with small components, median everywhere) leaves a clean isovalue: "
                 "the scan's surfaces are rough at every isovalue.</p>\n";
        }
    }
    o << "<p>Noise: ";
    if (j["noise"]["sigma"].is_null())
        o << "&sigma; " << number(j, "/noise/sigma") << " (no block of the volume is usable)";
    else
        o << "&sigma; = " << number(j, "/noise/sigma", 4) << " grey values, estimated on a share "
          << number(j, "/noise/flat_share", 3) << " of the voxels (second differences of flat blocks); white part "
          << number(j, "/noise/sigma_white", 4) << ", correlation widths " << number(j, "/noise/correlation/0", 3)
          << ", " << number(j, "/noise/correlation/1", 3) << ", " << number(j, "/noise/correlation/2", 3)
          << " voxels (x, y, z; 0: white); the map's percentiles 10/50/90 " << number(j, "/noise/spread/p10", 3)
          << " / " << number(j, "/noise/spread/p50", 3) << " / " << number(j, "/noise/spread/p90", 3);
    o << ". Per isovalue (Theorem 1 inverted, independent noise assumed) r = noise / gradient "
      << number(j, "/noise/surface/ratio", 4) << " (median over " << number(j, "/noise/surface/isovalues_used")
      << " isovalues). 4D dimension D4 = " << number(j, "/fd4/d4", 5) << " (3: a smooth field, towards 4: noise).</p>\n";
    for (const json& note : j["noise"].value("notes", json::array()))
        o << "<p class=\"note\">" << escape(note.get<std::string>()) << "</p>\n";
    o << "</section>\n";
    return o.str();
}

// The recommended isovalues as a table.
std::string recommended_section(const json& j) {
    std::ostringstream o;
    o << "<section id=\"recommended\"><h2>Recommended isovalues</h2>\n"
      << "<p class=\"note\">The material boundaries of each clean band (where the surfaces are steepest), best "
         "band first; when nothing is clean, those of the cleanest quarter. Verdict: clean D &le; "
      << html::number(j, "/advice/clean_fd", 3) << ", noisy D &ge; " << html::number(j, "/advice/noisy_fd", 3)
      << ", rough between. noise ratio: r = &mu;/&gamma; from the edge dimension at that isovalue (Theorem 1 "
         "inverted).</p>\n"
      << "<table><tr><th>isovalue</th><th>verdict</th><th>D(s)</th><th>cubes I(s)</th><th>components</th>"
         "<th>band</th><th>edge D</th><th>noise ratio r</th></tr>\n";
    for (std::size_t i = 0; i < j["recommended"].size(); ++i) {
        const std::string p = "/recommended/" + std::to_string(i);
        o << "<tr>" << cells(j, {{p + "/isovalue", 8}}) << "<td>"
          << html::escape(j["recommended"][i]["verdict"].get<std::string>()) << "</td>"
          << cells(j, {{p + "/fd", 4}, {p + "/count", 0}, {p + "/components", 0}}) << "<td>"
          << html::number(j, p + "/first", 8) << " .. " << html::number(j, p + "/last", 8) << "</td>"
          << cells(j, {{p + "/edge_fd", 4}, {p + "/noise_ratio", 3}}) << "</tr>\n";
    }
    o << "</table></section>\n";
    return o.str();
}

// The denoising ladder as a table (only when nothing is clean).
std::string denoise_section(const json& j) {
    const json& tried = j["denoise"]["attempts"];
    if (tried.empty()) return "";
    std::ostringstream o;
    o << "<section id=\"denoise\"><h2>Denoising tried</h2>\n<table><tr><th class=\"l\">command</th>"
         "<th>changed share</th><th>mean D after</th><th>clean after</th><th>use</th></tr>\n";
    for (std::size_t i = 0; i < tried.size(); ++i) {
        const std::string p = "/denoise/attempts/" + std::to_string(i);
        o << "<tr><td class=\"l\"><code>" << html::escape(tried[i]["command"].get<std::string>()) << "</code></td>"
          << cells(j, {{p + "/changed_share", 3}, {p + "/fd/mean", 4}}) << "<td>"
          << (tried[i]["clean"].get<bool>() ? "yes" : "no") << "</td><td>"
          << (tried[i]["recommended"].empty() ? std::string("") : html::number(j, p + "/recommended/0/isovalue", 8))
          << "</td></tr>\n";
    }
    o << "</table></section>\n";
    return o.str();
}

// The clean bands as a table.
std::string bands_section(const json& j) {
    std::ostringstream s_bands;
    s_bands << "<section id=\"bands\"><h2>Clean bands</h2>\n<table><tr><th>first</th><th>last</th><th>width</th>"
         "<th>use</th><th>mean D</th><th>max D</th><th>largest I(s)</th></tr>\n";
    for (std::size_t i = 0; i < j["clean_bands"].size(); ++i) {
        const std::string p = "/clean_bands/" + std::to_string(i);
        s_bands << "<tr>"
          << cells(j, {{p + "/first", 8}, {p + "/last", 8}, {p + "/width", 0}, {p + "/isovalue", 8}, {p + "/mean_fd", 4},
                       {p + "/max_fd", 4}, {p + "/max_count", 0}})
          << "</tr>\n";
    }
    if (j["clean_bands"].empty()) s_bands << "<tr><td colspan=\"7\" class=\"l\">none</td></tr>\n";
    s_bands << "</table></section>\n";
    return s_bands.str();
}

// D(s): its summary, the noisiest isovalue and the curve.
std::string fd_section(const json& j, const std::string& fd_png) {
    using html::number;
    std::ostringstream s_fd;
    s_fd << "<section id=\"fd\"><h2>Fractal dimension D(s)</h2>\n"
      << "<p>mean D " << number(j, "/fd/mean", 4) << ", std " << number(j, "/fd/std", 4) << ", count-weighted mean "
      << number(j, "/fd/weighted_mean", 4) << " over " << number(j, "/fd/defined") << " isovalues. Noisiest well-populated "
      << "isovalue: ";
    if (j["noisiest"].is_null()) s_fd << "none";
    else
        s_fd << number(j, "/noisiest/isovalue", 8) << " (D = " << number(j, "/noisiest/fd", 4) << ", "
          << number(j, "/noisiest/count") << " cubes, " << number(j, "/noisiest/components") << " components, r = "
          << number(j, "/noisiest/noise_ratio", 3) << ")";
    s_fd << ".</p>\n" << html::png_image(fd_png, "fractal dimension curve") << "</section>\n";
    return s_fd.str();
}

// The 4D dimension.
std::string d4_section(const json& j) {
    using html::number;
    std::ostringstream s_d4;
    s_d4 << "<section id=\"d4\"><h2>4D dimension</h2>\n<p>D4 = " << number(j, "/fd4/d4", 5) << " from I4(G, q) = "
      << number(j, "/fd4/i4_l0") << " and I4(G', 2q) = " << number(j, "/fd4/i4_l1") << ", bin width q = "
      << number(j, "/fd4/q", 6) << ": one number for the whole field, no isovalue (3: smooth, towards 4: noise).</p>"
      << "</section>\n";
    return s_d4.str();
}

// View i: its numbers, the mesh and the slice side by side.
std::string view_section(const json& j, const View& w, std::size_t i) {
    using html::escape;
    using html::number;
    std::ostringstream s_view;
    const std::string p = "/views/" + std::to_string(i);
    s_view << "<section id=\"view-" << i << "\" class=\"view\"><h2>" << escape(w.role) << ": isovalue "
      << number(j, p + "/isovalue", 8) << "</h2>\n<p>LD defined at " << number(j, p + "/ld_defined")
      << " vertices, mean LD " << number(j, p + "/ld_mean", 4) << ", share above 2.5 (red) "
      << number(j, p + "/ld_above_red", 3) << ".</p>\n<div class=\"pair\"><figure>"
      << html::png_image(w.mesh_png.get(), w.role + " mesh") << "<figcaption>isosurface coloured by LD</figcaption>"
      << "</figure><figure>" << html::png_image(w.slice_png.get(), w.role + " slice")
      << "<figcaption>axial slice " << number(j, p + "/slice_z")
      << ", the contour in yellow, LD blended where defined</figcaption></figure></div></section>\n";
    return s_view.str();
}

std::string build_html(const json& j, const std::string& fd_png, const std::string& comp_png,
                       const std::vector<View>& views, const std::string& explore) {
    using html::escape;
    using html::number;
    std::ostringstream b;
    const std::string name = j["volume"]["file"].get<std::string>();
    b << "<h1>clfractal report: " << escape(std::filesystem::path(name).filename().string()) << "</h1>\n"
      << "<p class=\"note\">Isosurface fractal dimension for every isovalue (<i>The Nature of the Isosurface Fractal "
         "Dimension</i>). D(s) about 2: a clean surface; towards 3: noise. Clean band: consecutive isovalues with "
         "D(s) &le; "
      << number(j, "/advice/clean_fd", 4) << " on a surface of at least " << number(j, "/advice/clean_share", 4)
      << " &times; the largest.</p>\n";

    const std::string s_components = "<section id=\"components\"><h2>Isosurface components</h2>\n" +
                                     html::png_image(comp_png, "component curve") + "</section>\n";
    std::vector<std::string> s_views;
    for (std::size_t i = 0; i < views.size(); ++i) s_views.push_back(view_section(j, views[i], i));
    // The answer and the pictures first (what a screenshot shows), the tables after.
    b << volume_section(j, name) << answer_section(j) << explore << "<div class=\"pair\">" << fd_section(j, fd_png)
      << s_components << "</div>\n";
    if (!s_views.empty()) b << s_views[0];
    b << recommended_section(j);
    for (std::size_t i = 1; i < s_views.size(); ++i) b << s_views[i];
    b << denoise_section(j) << bands_section(j) << d4_section(j);
    b << "<p class=\"note\">" << escape(j["device"].get<std::string>()) << "; " << number(j, "/seconds", 3)
      << " s.</p>\n";
    return html::page("clfractal report: " + name, b.str());
}

// The volume's shape, type, spacing and value range into j["volume"].
void describe_volume(json& j, const Volume& v) {
    const Dims d = v.dims();
    const ValueRange range = value_range(v);
    j["volume"]["dims"] = {d.nx, d.ny, d.nz};
    j["volume"]["vertices"] = v.vertices();
    j["volume"]["type"] = value_type_name(v.type());
    j["volume"]["spacing"] = {v.spacing[0], v.spacing[1], v.spacing[2]};
    j["volume"]["value_range"] = {range.min, range.max};
}

// The summary on stdout: the volume, the clean bands, the advice, the noise, D4, the files
// written and the time taken.
void print_summary(const ReportArgs& a, const Volume& v, const Analysis& an, std::size_t page_bytes, double seconds) {
    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n";
    print_bands(std::cout, an.curve, an.bands, a.clean_fd, a.clean_share);
    print_advice(std::cout, an, a.volume);
    if (an.noise_level && !std::isnan(an.noise_level->sigma))
        std::cout << "noise sigma " << std::setprecision(4) << an.noise_level->sigma << " grey levels\n";
    print_noise(std::cout, *an.surface_noise);
    std::cout << std::setprecision(4) << "D4          " << (std::isnan(an.fd4->d4) ? "n/a" : fd_string(an.fd4->d4).substr(0, 6))
              << "\n"
              << "wrote       " << a.output << " (" << page_bytes / 1024 << " KiB, self-contained)"
              << (a.json_path.empty() ? "" : " and " + a.json_path) << "\n"
              << "time        " << seconds << " s\n";
}

}  // namespace

AnalysisOptions report_options(const ReportSettings& a, const Volume& v) {
    AnalysisOptions o;
    o.advice.clean_fd = a.clean_fd;
    o.advice.clean_share = a.clean_share;
    o.bins = a.bins ? a.bins : 256;
    o.components = ComponentsScope::curve;
    o.fd4 = true;
    o.window = a.window;
    // The denoising ladder within the report's bound of 4x the volume + 256 MiB.
    o.memory_budget = (std::size_t(256) << 20) + 3 * v.size_bytes();
    return o;
}

namespace {

using Shown = std::vector<std::pair<std::size_t, std::string>>;

// The isovalues shown: the best recommendation and the noisiest (static pictures too, the
// first `static_views`; the 3D view opens on the noisiest, the best beside it), then, with the
// interactive view, other recommendations and a few across the populated range.
Shown shown_isovalues(const Analysis& an, double clean_share, bool interactive, std::size_t& static_views) {
    Shown shown;
    auto add = [&](std::size_t k, const std::string& role) {
        for (const auto& e : shown)
            if (e.first == k) return;
        shown.emplace_back(k, role);
    };
    if (!an.recommended.empty())
        add(an.best().index,
            an.clean ? "recommended (clean)" : "cleanest (" + std::string(verdict_name(an.best().verdict)) + ")");
    if (an.noisiest) add(an.noisiest->index, "noisiest well-populated");
    static_views = shown.size();
    if (!interactive) return shown;
    for (std::size_t r = 1; r < an.recommended.size() && r < 3; ++r)
        add(an.recommended[r].index, "recommended " + std::to_string(r + 1));
    const std::vector<std::uint64_t>& count = an.curve.counts[0];
    const double floor_count = count.empty() ? 0.0 : clean_share * double(*std::max_element(count.begin(), count.end()));
    std::vector<std::size_t> populated;
    for (std::size_t k = 0; k < count.size(); ++k)
        if (!std::isnan(an.curve.fd[k]) && count[k] > 0 && double(count[k]) >= floor_count) populated.push_back(k);
    for (int q = 1; q <= 3 && !populated.empty(); ++q) add(populated[populated.size() * q / 4], "across the range");
    return shown;
}

explore::Choice make_choice(const Pictures& p, const Analysis& an, std::size_t k, const std::string& role,
                            std::size_t budget) {
    explore::Choice c;
    c.role = role, c.text = an.isovalues.text(k), c.isovalue = an.isovalues.value(k);
    c.slice_z = p.z;
    c.mesh = explore::web_mesh(p.web ? *p.web : p.mesh, budget);
    if (p.web) c.mesh.triangles_full = p.triangles_full, c.mesh.cell = p.web_cell;
    c.slice_png = p.slice_png;
    return c;
}

}  // namespace

ReportPage report_page(Context& ctx, const Volume& v, const ReportSettings& a, const std::string& file,
                       const std::vector<std::string>& format, clock_type::time_point t0) {
    check_bins(a.bins, v.type());
    progress("report on " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " on " + ctx.description() +
             ": curve, components, noise, 4D dimension");
    ReportPage r{analyse(ctx, v, report_options(a, v)), {}, {}};
    const Analysis& an = r.analysis;
    json& j = r.json;
    j = json::parse(to_json(an));
    j["volume"]["file"] = file;
    j["volume"]["format"] = format;
    describe_volume(j, v);
    j["device"] = ctx.description();

    progress("plots");
    const FdCurve& f = an.curve;
    const std::string title = std::filesystem::path(file).filename().string();
    const CurveAxis axis = curve_axis(f, an.bands);
    const std::string fd_png =
        curve_plot(axis, {fd_panel(f)}, title + ": mean FD " + fd_string(an.summary.mean).substr(0, 5))
            .png("report: FD plot");
    const std::string comp_png =
        curve_plot(axis, {components_panel(an.components->components)}, title + ": isosurface components (cube)")
            .png("report: components plot");

    std::string why_static = a.static_page ? "--static" : "";
    std::optional<explore::Three> three;
    if (!a.static_page) {
        three = explore::load_three(why_static);
        if (!three)
            std::cerr << "clfractal: warning: " << why_static << " (setup.sh installs libjs-three): the static page\n";
    }
    std::size_t static_views = 0;
    const Shown shown = shown_isovalues(an, a.clean_share, three.has_value(), static_views);
    std::vector<View> views;
    std::vector<explore::Choice> choices;
    for (std::size_t i = 0; i < shown.size(); ++i) {
        const auto& [k, role] = shown[i];
        const Pictures p = pictures(ctx, v, an, k, role, a.window, a.mesh_triangles);
        if (i < static_views) views.push_back(make_view(p, an.isovalues, k, role, a.window));
        if (three)
            choices.insert(i == 1 && static_views == 2 ? choices.begin() : choices.end(),
                           make_choice(p, an, k, role, a.mesh_triangles));
    }
    j["views"] = json::array();
    for (const View& w : views) j["views"].push_back(w.facts);
    if (three) {
        j["explore"] = {{"three", three->dir}, {"choices", json::array()}};
        for (const explore::Choice& c : choices) j["explore"]["choices"].push_back(explore::facts(c));
    } else {
        j["explore"] = {{"static", why_static}};
    }
    // The page's time includes the figures still being drawn.
    for (const View& w : views) w.mesh_png.wait(), w.slice_png.wait();
    for (const explore::Choice& c : choices) c.slice_png.wait();
    j["seconds"] = seconds_since(t0);

    std::string explore_html;
    if (three && !choices.empty())
        explore_html = explore::section(j, choices, *three);
    else if (!a.static_page)
        explore_html = "<p class=\"note\">No interactive view: " + html::escape(why_static) +
                       " (setup.sh installs Debian's libjs-three).</p>\n";
    r.html = build_html(j, fd_png, comp_png, views, explore_html);
    return r;
}

namespace {

int run_report(const ReportArgs& a) {
    const auto t0 = clock_type::now();
    const Volume v = read_volume_within(a.volume, a.raw.options(), {"clfractal report"});
    check_bins(a.bins, v.type());  // before the device starts (report_page checks it for its other callers)
    const ReportPage r =
        report_page(Context::shared(), v, a, a.volume, describe_volume_file(a.volume, a.raw.options()), t0);
    write_file_atomic(a.output, r.html);
    if (!a.json_path.empty()) write_file_atomic(a.json_path, r.json.dump(1) + "\n");
    print_summary(a, v, r.analysis, r.html.size(), r.json["seconds"].get<double>());
    return 0;
}

}  // namespace

void setup_report(CLI::App* c, ReportArgs& a) {
    add_volume_argument(c, a.volume);
    add_output_option(c, a.output, "the HTML page to write");
    c->add_option("--json", a.json_path, "write the same numbers as JSON");
    add_bins_option(c, a.bins);
    c->add_option("--clean-fd", a.clean_fd, "clean bands: D(s) at most this");
    c->add_option("--clean-share", a.clean_share, "clean bands: I(s) at least this share of the largest");
    add_window_option(c, a.window, "LD window k of the pictures");
    c->add_option("--mesh-triangles", a.mesh_triangles, "most triangles of each mesh of the 3D view (clustered)")
        ->check(CLI::Range(std::size_t(1), explore::max_triangles));
    c->add_flag("--static", a.static_page, "the page without scripts: PNG figures only, no 3D view");
    a.raw.add(c);
}

Command report_command() {
    return command<ReportArgs>("report", "one self-contained HTML page: curves, clean bands, noise, D4, pictures",
                               setup_report, run_report);
}

}  // namespace cli
