// clfractal fd: the fractal dimension curve for every isovalue, its summary, clean bands,
// noise level and component correlation; CSV, JSON and a plot.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <chrono>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "clfractal/advice.hpp"
#include "clfractal/analysis.hpp"
#include "clfractal/components.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/noise_level.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"
#include "plots.hpp"

using namespace clfractal;

namespace cli {

namespace {

using json = nlohmann::json;

struct FdArgs {
    std::string volume, csv, json_path, plot, isovalues;
    bool edge = false, components = false, noise_level = false, no_denoise = false;
    double clean_fd = 2.2, clean_share = 0.01;
    int levels = 2;
    std::size_t bins = 0;
    std::uint64_t min_count = 0;
    std::size_t slab = 0;
    bool stream = false;
    RawArgs raw;
};

// What fd computes before it reports: the analysis (curve, bands, recommendations, noise,
// denoising) and the extras of its options.
struct FdRun {
    Dims dims;
    ValueType type;
    std::string stream_method;
    Analysis an;
    FdSummary s;  ///< with --min-count
    ComponentCorrelation corr;
};

AnalysisOptions analysis_options(const FdArgs& a, ValueType type) {
    AnalysisOptions o;
    o.advice.clean_fd = a.clean_fd;
    o.advice.clean_share = a.clean_share;
    o.kind = a.edge ? SpanKind::edges : SpanKind::cubes;
    o.levels = a.levels;
    o.slab_slices = a.slab;
    o.bins = a.bins ? a.bins : 256;
    if (!a.isovalues.empty()) o.isovalues = parse_isovalues(a.isovalues, type);
    o.components = a.components ? ComponentsScope::curve : ComponentsScope::recommended;
    o.edge_counts = a.components;  // E(s) for the correlation
    o.noise_level = o.surface_noise = a.noise_level;
    o.denoise = !a.no_denoise;
    return o;
}

FdRun count_fd(const FdArgs& a) {
    if (a.levels < 2 || a.levels > 16) throw InputError("--levels " + std::to_string(a.levels) + ": must be 2..16");
    if (a.stream) {
        if (a.slab) throw InputError("--slab: not with --stream (the stream counts a few slices at a time)");
        if (a.components) throw InputError("--components: not with --stream (the sweep needs the whole volume)");
        if (a.noise_level) throw InputError("--noise-level: not with --stream (it needs the whole volume)");
    }
    // The device is looked up only once the input is read: main() began creating it, and the
    // read runs meanwhile.
    FdRun r;
    if (a.stream) {
        const SpanKind kind = a.edge ? SpanKind::edges : SpanKind::cubes;
        SliceReader reader(a.volume, a.raw.options());
        StreamedSpans streamed = stream_spans(reader, a.volume, a.isovalues, a.bins, a.levels, kind);
        r.stream_method = streamed.method;
        r.dims = streamed.dims;
        r.type = streamed.type;
        AnalysisOptions o = analysis_options(a, r.type);
        o.isovalues.reset();
        const auto t0 = std::chrono::steady_clock::now();
        r.an = analyse_curve(fd_curve(Context::shared(), streamed.spans, kind), o, std::move(streamed.histogram));
        // The entries' components, as in core: one more pass over the file, slice by slice.
        const auto labelling = std::chrono::steady_clock::now();
        fill_entry_components(r.an, [&](const std::vector<double>& at) {
            progress("labelling the components at " + std::to_string(at.size()) + " isovalues (" + a.volume +
                     " read once more, slice by slice)");
            reader.rewind();
            return stream_components_at(reader, at, Connectivity::cube);
        });
        r.an.seconds_components = seconds_since(labelling);  // the second read of the file included
        r.an.seconds = seconds_since(t0);
        r.an.spans = std::move(streamed.spans);
        r.an.dims = r.dims;
        r.an.type = r.type;
        if (!a.no_denoise && !r.an.clean && !r.an.recommended.empty()) r.an.skipped.push_back(denoise_not_streamed());
    } else {
        const bool convert = a.raw.options().as.has_value();
        const Volume v = read_volume_within(a.volume, a.raw.options(),
                                           {"clfractal fd", 1.25, "clfractal fd --stream counts within 512 MiB"},
                                           convert ? FiniteCheck::reject : FiniteCheck::keep);
        r.dims = v.dims();
        r.type = v.type();
        check_bins(a.bins, r.type);
        AnalysisOptions o = analysis_options(a, r.type);
        // fd stays within a quarter of the volume + 256 MiB beyond it; --components asks for more.
        if (!a.components) o.memory_budget = (std::size_t(256) << 20) + v.size_bytes() / 4;
        // The host part of the analysis (value range, finite check, isovalue histogram) while
        // the OpenCL platform starts; read_volume_within checks by itself only before a --as
        // conversion.
        AnalysisInput input = prepare_analysis(v, o);
        if (input.stats.nan + input.stats.inf) check_finite(v, a.volume);
        Context& ctx = Context::shared();
        progress("counting " + std::to_string(input.isovalues.size()) + " isovalues of " + dims_string(r.dims) + " " +
                 value_type_name(r.type) + " on " + ctx.description());
        r.an = analyse(ctx, v, o, std::move(input));
        // --components: the correlation of D with the component curve (cube connectivity).
        if (a.components)
            r.corr = correlate_components(ctx, r.an.curve.fd, r.an.spans.get(SpanKind::edges).counts[0],
                                          r.an.components->components, v.dims());
    }
    r.s = summarize(r.an.curve.fd, r.an.curve.counts[0], r.an.curve.counts[1], a.min_count);
    return r;
}

// A number with 3 significant digits ("4.01", "34.6", "0.000123").
std::string short_number(double x) {
    std::ostringstream o;
    o << std::defaultfloat << std::setprecision(3) << x;
    return o.str();
}

// The noise level, its map's range and the per-isovalue Theorem 1 inversion.
void print_noise_level(std::ostream& out, const NoiseLevel& l, const NoiseEstimate& e) {
    if (std::isnan(l.sigma)) {
        out << "noise sigma n/a: no block of " << l.block << "^3 voxels is usable (each reads the volume's smallest "
            << "or largest value, or has too few interior voxels)\n";
    } else {
        out << "noise sigma " << short_number(l.sigma) << " grey levels (estimated on "
            << short_number(100 * l.flat_share) << "% of voxels; white part " << short_number(l.sigma_white) << ")\n";
        out << "correlation";
        for (int a = 0; a < 3; ++a)
            out << (a ? ", " : " ") << "xyz"[a] << " "
                << (std::isnan(l.correlation[a]) ? std::string("n/a") : short_number(l.correlation[a]));
        out << " voxels (width of the Gaussian smoothing the noise's correlation matches; 0: white)\n";
        out << "noise map   " << dims_string(l.map_dims) << " cells of " << l.map_block << "^3: sigma percentiles "
            << "10/50/90 " << short_number(l.spread[0]) << " / " << short_number(l.spread[1]) << " / "
            << short_number(l.spread[2]) << "\n";
        for (const std::string& note : noise_level_notes(l)) out << "note        " << note << "\n";
    }
    out << "surface     is the surface at s noise-dominated? r(s) = noise / gradient per isovalue (Theorem 1 "
           "inverted; it assumes independent noise)\n";
    if (e.used == 0) {
        out << "            n/a: no well-populated isovalue has an edge dimension in [" << noise_fd_min << ", "
            << noise_fd_max << "] (below: too clean to measure; above: noise dominates)\n";
        return;
    }
    out << "            median over " << e.used << " isovalues: uniform r " << short_number(e.median_ratio) << " (+-"
        << short_number(e.median_amplitude) << " grey values, std " << short_number(e.median_amplitude / std::sqrt(3.0))
        << "), Gaussian r " << short_number(e.median_ratio_gaussian) << " (std "
        << short_number(e.median_sigma_gaussian) << ")\n";
}

void print_fd(const FdArgs& a, const FdRun& r) {
    const FdSummary& s = r.s;
    const Analysis& an = r.an;
    const IsovalueSet& iso = an.isovalues;
    Context& ctx = Context::shared();
    const char* kind_name = a.edge ? "edge" : "box";
    std::cout << std::fixed << std::setprecision(4);
    std::cout << "volume      " << a.volume << "  " << dims_string(r.dims) << " " << value_type_name(r.type) << "\n"
              << "device      " << ctx.description() << "\n"
              << "dimension   fractal " << kind_name << " span dimension, levels 0.." << a.levels - 1 << "\n"
              << "isovalues   " << iso.size() << " (" << iso_string(iso, 0) << " .. "
              << iso_string(iso, iso.size() - 1) << "), defined at " << s.defined << "\n";
    if (s.defined) {
        std::cout << "mean FD     " << s.mean << "  std " << s.std << "  count-weighted mean " << s.weighted_mean
                  << "\n"
                  << "growth      I ~ N^" << s.kappa << "\n";
        print_bands(std::cout, an.curve, an.bands, a.clean_fd, a.clean_share);
    } else {
        std::cout << "mean FD     n/a (no isovalue intersects both grids)\n";
    }
    print_advice(std::cout, an, a.volume);
    if (a.noise_level) print_noise_level(std::cout, *an.noise_level, *an.surface_noise);
    if (a.components)
        std::cout << "components  corr(D, components) " << fd_string(r.corr.components).substr(0, 6)
                  << "  corr(D, components / E) " << fd_string(r.corr.components_per_area).substr(0, 6) << " over "
                  << r.corr.used << " isovalues\n";
    const SpanResult& spans = an.spans;
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << spans.seconds << " s counting ("
              << (a.stream ? "streamed, " + r.stream_method + ", " : "") << spans.slabs << " slab"
              << (spans.slabs > 1 ? "s" : "") << ")";
    std::cout << ", " << an.seconds << " s analysis in all";
    std::cout << ", kernels compiled in " << ctx.compile_seconds() << " s\n";
}

// The analysis's JSON (clfractal::to_json, shared with report --json), fd's own keys and the
// facts of this run.
json fd_json_report(const FdArgs& a, const FdRun& r) {
    Context& ctx = Context::shared();
    json j = fd_analysis_json(r.an, r.s, FdJsonFacts{a.volume, a.edge, a.levels, a.min_count});
    j["device"] = ctx.description();
    j["seconds_compute"] = r.an.spans.seconds;
    j["seconds_compile"] = ctx.compile_seconds();
    j["slabs"] = r.an.spans.slabs;
    if (a.components) {
        j["corr_components"] = fd_json(r.corr.components);
        j["corr_components_per_area"] = fd_json(r.corr.components_per_area);
        j["corr_isovalues"] = r.corr.used;
    }
    return j;
}

int cmd_fd(const FdArgs& a) {
    const FdRun r = count_fd(a);
    print_fd(a, r);
    const FdCurve& f = r.an.curve;
    const std::vector<std::int64_t>* comp = r.an.components ? &r.an.components->components : nullptr;
    if (!a.csv.empty()) write_file_atomic(a.csv, fd_csv(f, comp));
    if (!a.json_path.empty()) write_file_atomic(a.json_path, fd_json_report(a, r).dump(1) + "\n");
    if (!a.plot.empty() && comp)
        write_components_plot(f, r.an.bands, *comp, true,
                              std::filesystem::path(a.volume).filename().string() + ": FD and isosurface components",
                              a.plot);
    else if (!a.plot.empty())
        write_fd_plot(f, r.an.bands, a.min_count,
                      std::filesystem::path(a.volume).filename().string() + ": mean FD " + fd_string(r.s.mean).substr(0, 5),
                      a.plot);
    return 0;
}

void setup_fd(CLI::App* fd, FdArgs& fa) {
    add_volume_argument(fd, fa.volume);
    fd->add_flag("--edge", fa.edge, "edge span dimension (eq. 3.1) instead of box (eq. 2.5)");
    fd->add_option("--levels", fa.levels, "pyramid levels for the least-squares estimate (2 = eq. 2.5)");
    add_isovalues_option(fd, fa.isovalues);
    add_bins_option(fd, fa.bins);
    fd->add_option("--min-count", fa.min_count, "summary only where the subsampled count is >= M");
    fd->add_option("--csv", fa.csv, "write isovalue,count,count_sub,fd");
    fd->add_option("--json", fa.json_path, "write the summary and curve as JSON");
    fd->add_option("--plot", fa.plot, "draw the curve to a PNG with gnuplot");
    fd->add_flag("--components", fa.components,
                 "add the isosurface component count (cube connectivity) and its correlation with D");
    fd->add_option("--slab", fa.slab, "process z-slabs of at most this many slices (0: from device memory)");
    fd->add_flag("--stream", fa.stream, "read the file slice by slice (memory: a few slices; same numbers)");
    fd->add_option("--clean-fd", fa.clean_fd, "clean bands: D(s) at most this");
    fd->add_option("--clean-share", fa.clean_share, "clean bands: I(s) at least this share of the largest");
    fd->add_flag("--noise-level", fa.noise_level,
                 "the noise's standard deviation in grey values (residuals of flat blocks), and per isovalue "
                 "whether the surface is noise-dominated (Theorem 1 inverted)");
    fd->add_flag("--no-denoise", fa.no_denoise,
                 "when no isovalue is clean, do not try the denoising ladder (targeted median, with small components, median)");
    fa.raw.add(fd);
}

}  // namespace

Command fd_command() { return command<FdArgs>("fd", "fractal dimension curve for every isovalue", setup_fd, cmd_fd); }

}  // namespace cli
