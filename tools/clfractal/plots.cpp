// Annotated curve plots and LD figures (see plots.hpp), drawn by gnuplot.
#include "plots.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "clfractal/error.hpp"
#include "clfractal/local.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;
namespace fs = std::filesystem;

namespace cli {
namespace {

const char* const grey = "#9e9e9e";
const char* const band_fill = "#c8e6c9";

std::string number(double x) {
    if (std::isnan(x)) return "NaN";
    std::ostringstream s;
    s << std::setprecision(10) << x;
    return s.str();
}

// The LD colour map of local.hpp (blue up to ld_blue, red from ld_red) as a gnuplot palette
// over the colour bar's range.
std::string ld_palette() {
    std::ostringstream s;
    const double lo = ld_blue - 0.2, hi = ld_red + 0.2;
    s << "set cbrange [" << lo << ":" << hi << "]\n"
      << "set palette defined (" << lo << " '#0000ff', " << ld_blue << " '#0000ff', " << ld_red << " '#ff0000', " << hi
      << " '#ff0000')\nset cbtics (" << lo << ", " << ld_blue << ", " << (ld_blue + ld_red) / 2 << ", " << ld_red
      << ", " << hi << ")\nset cblabel 'local fractal dimension LD (2.2 blue: clean, 2.5 red: noisy)'\n";
    return s.str();
}

}  // namespace

CurveAxis curve_axis(const FdCurve& f, const std::vector<CleanBand>& bands, std::uint64_t min_count) {
    CurveAxis a;
    a.isovalues = f.isovalues;
    a.count = f.counts.at(0);
    a.count_label = std::string("intersected ") + (f.kind == SpanKind::cubes ? "cubes" : "edges") + " I(s)";
    const std::vector<std::uint64_t>& sub = f.counts.at(1);
    const std::uint64_t largest = sub.empty() ? 0 : *std::max_element(sub.begin(), sub.end());
    const std::uint64_t floor_count = std::max<std::uint64_t>({min_count, largest / 100, 1});
    a.few.resize(sub.size());
    for (std::size_t j = 0; j < sub.size(); ++j) a.few[j] = sub[j] < floor_count;
    a.bands = bands;
    return a;
}

CurvePanel fd_panel(const FdCurve& f) {
    CurvePanel p;
    p.ylabel = std::string("fractal ") + (f.kind == SpanKind::cubes ? "box" : "edge") + " span dimension D(s)";
    p.title = "D(s)";
    p.values = f.fd;
    if (f.levels() > 2) {
        p.fit = f.fd_fit;
        p.fit_title = "fd\\_fit (all levels)";
    }
    p.clamp_lo = 1, p.clamp_hi = 4;
    p.range_lo = 1.8, p.range_hi = 3.05;
    p.guides = {{2, "#2e7d32", "2: clean surface"}, {3, "#c62828", "3: noise"}};
    return p;
}

CurvePanel components_panel(const std::vector<std::int64_t>& components) {
    CurvePanel p;
    p.ylabel = "isosurface components (log scale)";
    p.title = "components(s)";
    p.colour = "#c0392b";
    p.values.resize(components.size());
    for (std::size_t j = 0; j < components.size(); ++j)
        p.values[j] = components[j] > 0 ? double(components[j]) : std::nan("");
    p.log_scale = true;
    p.range_lo = 0.7;
    p.guides = {{1, "#2e7d32", "1: one connected surface"}};
    return p;
}

void Figure::write(const std::string& path) const { plot_png(script, data, path); }
std::string Figure::png(const std::string& what) const { return plot_png_bytes(script, data, what); }

Figure curve_plot(const CurveAxis& axis, const std::vector<CurvePanel>& panels, const std::string& title) {
    const std::size_t n = axis.isovalues.size();
    std::ostringstream data;
    std::vector<double> lo(panels.size(), INFINITY), hi(panels.size(), -INFINITY);
    for (std::size_t j = 0; j < n; ++j) {
        data << iso_string(axis.isovalues, j) << " " << axis.count[j];
        for (std::size_t p = 0; p < panels.size(); ++p) {
            const CurvePanel& c = panels[p];
            auto shown = [&](double d) { return std::isnan(d) ? d : std::clamp(d, c.clamp_lo, c.clamp_hi); };
            const double d = shown(c.values[j]);
            if (!std::isnan(d)) lo[p] = std::min(lo[p], d), hi[p] = std::max(hi[p], d);
            const bool few = axis.few[j];
            data << " " << number(few ? NAN : d) << " " << number(few ? d : NAN) << " "
                 << number(c.fit.empty() ? NAN : shown(c.fit[j]));
        }
        data << "\n";
    }
    std::ostringstream script;
    script << "set terminal pngcairo size 900," << 560 * panels.size() << " font 'sans,11'\n";
    if (panels.size() > 1)
        script << "set multiplot layout " << panels.size() << ",1 title " << gnuplot_string(title) << " noenhanced\n";
    for (std::size_t p = 0; p < panels.size(); ++p) {
        const CurvePanel& c = panels[p];
        script << "unset arrow\nunset object\nunset logscale\n"
               << "set xlabel 'isovalue' offset 0,0.3\nset ylabel '" << c.ylabel << "'\nset y2label '" << axis.count_label
               << "'\nset y2tics\nset ytics nomirror\nset y2range [0:*]\nset autoscale xfix\nset grid\n"
               << "set key below horizontal maxrows 2 spacing 1.2\nset lmargin 11\nset rmargin 12\n"
               << "set title " << gnuplot_string(panels.size() > 1 ? std::string() : title) << " noenhanced\n";
        const bool empty = !(lo[p] <= hi[p]);  // nothing to draw: a fixed range (gnuplot cannot autoscale)
        if (c.log_scale) {
            script << "set logscale y\nset yrange [" << (std::isnan(c.range_lo) ? std::string("*") : number(c.range_lo))
                   << (empty ? ":10]\n" : ":*]\n");
        } else if (!std::isnan(c.range_lo)) {
            const double a = std::min(c.range_lo, lo[p]), b = std::max(c.range_hi, hi[p]);
            script << "set yrange [" << number(a - 0.05) << ":" << number(b + 0.05) << "]\n";
        } else {
            script << (empty ? "set yrange [0:1]\n" : "set yrange [*:*]\n");
        }
        if (std::all_of(axis.count.begin(), axis.count.end(), [](std::uint64_t c) { return c == 0; })) script << "set y2range [0:1]\n";
        for (const Guide& g : c.guides)
            script << "set arrow from graph 0, first " << g.value << " to graph 1, first " << g.value
                   << " nohead dt 2 lc rgb '" << g.colour << "' lw 1.5 front\n";
        for (const CleanBand& b : axis.bands)
            script << "set object rect from first " << axis.isovalues.value(b.first) << ", graph 0 to first "
                   << axis.isovalues.value(b.last) << ", graph 1 fc rgb '" << band_fill << "' fs solid 0.6 noborder behind\n";
        const std::size_t col = 3 + 3 * p;
        script << "plot '$DATA' using 1:2 axes x1y2 with filledcurves x1 fs solid 0.25 lc rgb '" << grey << "' title '"
               << axis.count_label << "', '' using 1:" << col << " with lines lw 2 lc rgb '" << c.colour << "' title '"
               << c.title << "', '' using 1:" << col + 1 << " with points pt 7 ps 0.4 lc rgb '" << grey << "' title '"
               << c.title << ", few cubes'";
        if (!c.fit.empty())
            script << ", '' using 1:" << col + 2 << " with lines lw 1.5 dt 3 lc rgb '#6a1b9a' title '" << c.fit_title << "'";
        for (const Guide& g : c.guides)
            script << ", NaN with lines dt 2 lc rgb '" << g.colour << "' title '" << g.title << "'";
        if (!axis.bands.empty()) script << ", NaN with boxes fs solid 0.6 lc rgb '" << band_fill << "' title 'clean band'";
        script << "\n";
    }
    if (panels.size() > 1) script << "unset multiplot\n";
    return Figure{script.str(), data.str(), nullptr};
}

void write_fd_plot(const FdCurve& f, const std::vector<CleanBand>& bands, std::uint64_t min_count,
                   const std::string& title, const std::string& path) {
    curve_plot(curve_axis(f, bands, min_count), {fd_panel(f)}, title).write(path);
}

void write_components_plot(const FdCurve& f, const std::vector<CleanBand>& bands,
                           const std::vector<std::int64_t>& components, bool with_fd, const std::string& title,
                           const std::string& path) {
    std::vector<CurvePanel> panels;
    if (with_fd) panels.push_back(fd_panel(f));
    panels.push_back(components_panel(components));
    curve_plot(curve_axis(f, bands), panels, title).write(path);
}

Figure image_figure(const ImageFigure& fig) {
    const Image& img = *fig.image;
    if (img.width == 0 || img.height == 0) throw std::logic_error("image_figure: empty image");
    // The pixels go to gnuplot as a raw file in the temporary folder (its datablocks are
    // text), removed with the last copy of the figure.
    struct Remove {
        fs::path p;
        ~Remove() {
            std::error_code ec;
            if (!p.empty()) fs::remove(p, ec);
        }
    };
    static std::atomic<unsigned> serial{0};
    const fs::path raw = fs::temp_directory_path() /
                         ("clfractal-figure-" + std::to_string(::getpid()) + "-" + std::to_string(serial++) + ".rgb");
    auto keep = std::make_shared<Remove>();
    keep->p = raw;
    {
        std::ofstream out(raw, std::ios::binary);
        out.write(reinterpret_cast<const char*>(img.rgb.data()), std::streamsize(img.rgb.size()));
        if (!out) throw InputError(raw.string() + ": cannot write a temporary file");
    }
    std::string quoted;
    for (char c : raw.string()) quoted += c == '\'' ? std::string("''") : std::string(1, c);

    std::ostringstream data;
    for (const auto& l : fig.lines) data << l[0] << " " << l[1] << "\n" << l[2] << " " << l[3] << "\n\n";
    if (fig.lines.empty()) data << "NaN NaN\n";
    const double w = double(img.width) * fig.dx, h = double(img.height) * fig.dy;
    std::ostringstream script;
    script << "set terminal pngcairo size " << fig.width << "," << fig.height << " font 'sans,11'\n"
           << "set title " << gnuplot_string(fig.title) << " noenhanced\n"
           << "set size ratio -1\nset xrange [" << -fig.dx / 2 << ":" << w - fig.dx / 2 << "]\nset yrange ["
           << -fig.dy / 2 << ":" << h - fig.dy / 2 << "]\n"
           << "set lmargin at screen " << (fig.axes ? 0.1 : 0.02) << "\nset rmargin at screen 0.78\n"
           << "set colorbox vertical user origin screen 0.81, screen 0.15 size screen 0.03, screen 0.7\n"
           << ld_palette() << "set label 1 " << gnuplot_string(fig.label)
           << " at graph 0.02, graph 0.96 front noenhanced font ',15' tc rgb '#000000' boxed\n"
           << "set style textbox opaque fc rgb '#ffffff' noborder\n";
    if (fig.axes)
        script << "set xlabel '" << fig.xlabel << "'\nset ylabel '" << fig.ylabel << "'\nset tics out\n";
    else
        script << "unset border\nunset xtics\nunset ytics\n";
    script << "set key below\n"
           << "plot '" << quoted << "' binary array=(" << img.width << "," << img.height << ") flipy dx=" << fig.dx
           << " dy=" << fig.dy << " origin=(0,0) format='%uchar' with rgbimage notitle, "
           << "'$DATA' using 1:2 with lines lw 1.2 lc rgb '" << fig.line_colour << "' "
           << (fig.line_title.empty() ? std::string("notitle") : "title '" + fig.line_title + "'")
           << ", '+' using 1:(NaN):(" << ld_blue << ") with points lc palette notitle\n";
    return Figure{script.str(), data.str(), keep};
}

}  // namespace cli
