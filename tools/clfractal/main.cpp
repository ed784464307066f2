// clfractal: the command-line tool (DESIGN §3). Exit 0 on success, 2 on bad input or
// arguments (one line "clfractal: error: ..."), 1 on a runtime failure.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "clfractal/advice.hpp"
#include "clfractal/bench.hpp"
#include "clfractal/components.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/output_file.hpp"
#include "clfractal/render.hpp"
#include "clfractal/span.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;
using json = nlohmann::json;
using namespace cli;

namespace {

// ------------------------------------------------------------------ devices

int cmd_devices() {
    auto all = list_devices();
    if (all.empty()) {
        std::cout << "no OpenCL devices (install an ICD, e.g. pocl-opencl-icd)\n";
        return 1;
    }
    for (auto& d : all)
        std::cout << (d.chosen ? "* " : "  ") << d.platform << " / " << d.name << "  [" << d.type << ", "
                  << d.compute_units << " CUs, " << (d.global_mem >> 20) << " MiB, max alloc "
                  << (d.max_alloc >> 20) << " MiB]\n";
    std::cout << "(* = chosen; set CLFRACTAL_DEVICE=<name substring> or CLFRACTAL_DEVICE_TYPE=cpu|gpu)\n";
    return 0;
}

// ------------------------------------------------------------------ info

int cmd_info(const std::string& spec, const RawArgs& raw) {
    // The format first: a directory of several DICOM series is listed even when none is chosen.
    std::cout << "volume    " << spec << "\n";
    for (const std::string& line : describe_volume_file(spec, raw.options())) std::cout << line << "\n";
    std::cout.flush();
    // NaN and Inf are reported, not refused: an LD field is float data with NaN where LD is
    // undefined. Range, mean and histogram are those of the finite values.
    Volume v = read_volume(spec, raw.options(), FiniteCheck::keep);
    // Range, NaN counts, mean and histogram in one pass for 8/16-bit data (two otherwise).
    const ValueSummary summary = summarize_values(v, 16);
    const NonFinite nf{summary.stats.nan, summary.stats.inf, 0};
    const std::size_t finite = summary.finite;
    const double lo = summary.stats.min, hi = summary.stats.max, mean = summary.mean, sd = summary.sd;
    const double n = double(finite);
    std::cout << "dims      " << dims_string(v.dims()) << " (" << v.vertices() << " vertices, " << v.dims().cubes()
              << " cubes)\n"
              << "type      " << value_type_name(v.type()) << "\n"
              << "spacing   " << v.spacing[0] << " " << v.spacing[1] << " " << v.spacing[2] << "\n";
    if (nf.nan + nf.inf)
        std::cout << "NaN       " << nf.nan << " (" << std::fixed << std::setprecision(2) << 100.0 * double(nf.nan) / double(v.vertices())
                  << "% of the vertices)" << std::defaultfloat << std::setprecision(6) << "\n"
                  << "infinite  " << nf.inf << "\n";
    if (finite == 0) {
        std::cout << "range     n/a (no finite value)\n";
        return 0;
    }
    std::cout << "range     " << lo << " .. " << hi << (nf.nan + nf.inf ? " (finite values)" : "") << "\n"
              << "mean      " << mean << "  (std " << sd << ")\n";
    // A 16-bin histogram of the value range, as shares of the finite values.
    const int bins = 16;
    const std::vector<std::size_t>& h = summary.histogram;
    const double w = (hi - lo) / bins;
    std::cout << "histogram (16 bins over the range, % of " << (nf.nan + nf.inf ? "the finite values" : "vertices")
              << "):\n";
    for (int b = 0; b < bins; ++b) {
        double share = 100.0 * double(h[b]) / n;
        std::cout << "  " << std::setw(12) << lo + b * w << "  " << std::setw(6) << std::fixed
                  << std::setprecision(2) << share << std::defaultfloat << std::setprecision(6) << "  "
                  << std::string(std::size_t(std::ceil(share / 2)), '#') << "\n";
    }
    if (nf.nan + nf.inf) {
        std::cout << "isovalues n/a (fd, local, filter, mesh and components need finite values)\n";
        return 0;
    }
    IsovalueSet iso = IsovalueSet::for_range(v.type(), lo, hi);
    std::cout << "isovalues " << iso.size() << (iso.integer() ? " (every integer of the range)"
                                                 : iso.float64() ? " (uniform float64 list)" : " (uniform float32 list)")
              << "\n";
    return 0;
}

// ------------------------------------------------------------------ fd

struct FdArgs {
    std::string volume, csv, json_path, plot, isovalues;
    bool edge = false, components = false, noise_level = false;
    double clean_fd = 2.2, clean_share = 0.01;
    int levels = 2;
    std::size_t bins = 0;
    std::uint64_t min_count = 0;
    std::size_t slab = 0;
    bool stream = false;
    RawArgs raw;
};

// D(s) read at a glance: guide lines at 2 (clean surface) and 3 (space-filling noise), the
// clean bands shaded, the cube count as a grey underlay on a second axis, isovalues whose
// subsampled count is below the floor (1% of the largest, or --min-count) drawn as grey
// points instead of the line, fd_fit dashed when there are more than two levels, values
// clamped into [1, 4] so that none runs off the chart, and the legend under the plot.
void write_fd_plot(const FdCurve& f, const std::vector<CleanBand>& bands, std::uint64_t min_count,
                   const std::string& title, const std::string& path) {
    const std::vector<std::uint64_t>& sub = f.counts[1];
    const std::uint64_t largest = sub.empty() ? 0 : *std::max_element(sub.begin(), sub.end());
    const std::uint64_t floor_count = std::max<std::uint64_t>({min_count, largest / 100, 1});
    const bool fit = f.levels() > 2;
    auto shown = [](double d) { return std::isnan(d) ? std::string("NaN") : std::to_string(std::clamp(d, 1.0, 4.0)); };
    std::ostringstream data;
    double lo = 1.8, hi = 3.05;
    for (std::size_t j = 0; j < f.fd.size(); ++j) {
        const bool low = sub[j] < floor_count;
        const double d = f.fd[j];
        if (!std::isnan(d)) lo = std::min(lo, std::clamp(d, 1.0, 4.0)), hi = std::max(hi, std::clamp(d, 1.0, 4.0));
        data << iso_string(f.isovalues, j) << " " << (low ? "NaN" : shown(d)) << " " << (low ? shown(d) : "NaN") << " "
             << f.counts[0][j] << " " << (fit ? shown(f.fd_fit[j]) : "NaN") << "\n";
    }
    std::ostringstream script;
    script << "set terminal pngcairo size 900,560 font 'sans,11'\n"
           << "set xlabel 'isovalue'\nset ylabel 'fractal " << (f.kind == SpanKind::cubes ? "box" : "edge")
           << " span dimension D(s)'\nset y2label 'intersected " << (f.kind == SpanKind::cubes ? "cubes" : "edges")
           << " I(s)'\nset y2tics\nset ytics nomirror\nset y2range [0:*]\n"
           << "set yrange [" << lo - 0.05 << ":" << hi + 0.05 << "]\nset autoscale xfix\nset grid\n"
           << "set key below horizontal maxrows 2 spacing 1.2\nset xlabel offset 0,0.3\n"
           << "set title " << std::quoted(title) << " noenhanced\n"
           << "set arrow from graph 0, first 2 to graph 1, first 2 nohead dt 2 lc rgb '#2e7d32' lw 1.5 front\n"
           << "set arrow from graph 0, first 3 to graph 1, first 3 nohead dt 2 lc rgb '#c62828' lw 1.5 front\n";
    for (const CleanBand& b : bands)
        script << "set object rect from first " << f.isovalues.value(b.first) << ", graph 0 to first "
               << f.isovalues.value(b.last) << ", graph 1 fc rgb '#c8e6c9' fs solid 0.6 noborder behind\n";
    script << "plot '$DATA' using 1:4 axes x1y2 with filledcurves x1 fs solid 0.25 lc rgb '#9e9e9e' title 'I(s)', "
           << "'' using 1:2 with lines lw 2 lc rgb '#1f5fa8' title 'D(s)', "
           << "'' using 1:3 with points pt 7 ps 0.4 lc rgb '#9e9e9e' title 'D(s), few cubes', "
           << (fit ? "'' using 1:5 with lines lw 1.5 dt 3 lc rgb '#6a1b9a' title 'fd\\_fit (all levels)', " : "")
           << "NaN with lines dt 2 lc rgb '#2e7d32' title '2: clean surface', "
           << "NaN with lines dt 2 lc rgb '#c62828' title '3: noise', "
           << "NaN with boxes fs solid 0.6 lc rgb '#c8e6c9' title 'clean band'\n";
    plot_png(script.str(), data.str(), path);
}

int cmd_fd(const FdArgs& a) {
    if (a.stream) {
        if (a.levels < 2 || a.levels > 16) throw InputError("--levels " + std::to_string(a.levels) + ": must be 2..16");
        if (a.slab) throw InputError("--slab: not with --stream (the stream counts a few slices at a time)");
        if (a.components) throw InputError("--components: not with --stream (the sweep needs the whole volume)");
    }
    const SpanKind kind = a.edge ? SpanKind::edges : SpanKind::cubes;
    StreamedSpans streamed = a.stream ? stream_spans(a.volume, a.raw.options(), a.isovalues, a.bins, a.levels, kind)
                                      : StreamedSpans{};
    // The finite check and the value range in one pass (read_volume checks by itself only
    // before a --as conversion).
    const bool convert = a.raw.options().as.has_value();
    Volume v = a.stream ? Volume()
                        : read_volume(a.volume, a.raw.options(), convert ? FiniteCheck::reject : FiniteCheck::keep);
    const ValueStats stats = a.stream ? ValueStats{} : value_stats(v);
    if (stats.nan + stats.inf) check_finite(v, a.volume);
    const Dims dims = a.stream ? streamed.dims : v.dims();
    const ValueType type = a.stream ? streamed.type : v.type();
    if (a.levels < 2 || a.levels > 16) throw InputError("--levels " + std::to_string(a.levels) + ": must be 2..16");
    if (a.bins && is_integer(type) && !is_wide(type))
        throw InputError("--bins: 8/16-bit integer data uses every integer isovalue; use --isovalues A:B:1 to select");
    IsovalueSet iso = a.stream ? streamed.spans.isovalues
                      : !a.isovalues.empty() ? IsovalueSet::parse_range(a.isovalues, type)
                                             : IsovalueSet::for_range(type, stats.min, stats.max, a.bins ? a.bins : 256);
    Context& ctx = Context::shared();
    if (!a.stream)
        progress("counting " + std::to_string(iso.size()) + " isovalues of " + dims_string(dims) + " " +
                 value_type_name(type) + " on " + ctx.description());
    SpanOptions opt{{kind}, a.levels, a.slab};
    if (a.components && kind != SpanKind::edges) opt.kinds.push_back(SpanKind::edges);  // E(s) for the correlation
    SpanResult spans = a.stream ? std::move(streamed.spans) : count_spans(ctx, v, iso, opt);
    FdCurve f = fd_curve(ctx, spans, kind);
    FdSummary s = summarize(f.fd, f.counts[0], f.counts[1], a.min_count);
    // --components: the component curve (cube connectivity) and its correlation with D.
    ComponentCurve comp;
    ComponentCorrelation corr;
    if (a.components) {
        comp = count_components(ctx, v, iso, Connectivity::cube);
        corr = correlate_components(ctx, f.fd, spans.get(SpanKind::edges).counts[0], comp.components, v.dims());
    }

    const std::vector<CleanBand> bands = clean_bands(f, BandOptions{a.clean_fd, a.clean_share});
    NoiseEstimate noise;
    if (a.noise_level) {
        if (a.stream) throw InputError("--noise-level: not with --stream (it needs the whole volume)");
        noise = estimate_noise(ctx, v, iso, a.clean_share);
    }

    const char* kind_name = a.edge ? "edge" : "box";
    std::cout << std::fixed << std::setprecision(4);
    std::cout << "volume      " << a.volume << "  " << dims_string(dims) << " " << value_type_name(type) << "\n"
              << "device      " << ctx.description() << "\n"
              << "dimension   fractal " << kind_name << " span dimension, levels 0.." << a.levels - 1 << "\n"
              << "isovalues   " << iso.size() << " (" << iso_string(iso, 0) << " .. "
              << iso_string(iso, iso.size() - 1) << "), defined at " << s.defined << "\n";
    if (s.defined) {
        std::cout << "mean FD     " << s.mean << "  std " << s.std << "  count-weighted mean " << s.weighted_mean
                  << "\n"
                  << "growth      I ~ N^" << s.kappa << "\n";
        print_bands(std::cout, f, bands, a.clean_fd, a.clean_share);
    } else {
        std::cout << "mean FD     n/a (no isovalue intersects both grids)\n";
    }
    if (a.noise_level) print_noise(std::cout, noise);
    if (a.components)
        std::cout << "components  corr(D, components) " << fd_string(corr.components).substr(0, 6)
                  << "  corr(D, components / E) " << fd_string(corr.components_per_area).substr(0, 6) << " over "
                  << corr.used << " isovalues\n";
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << spans.seconds << " s counting ("
              << (a.stream ? "streamed, " + streamed.method + ", " : "") << spans.slabs << " slab"
              << (spans.slabs > 1 ? "s" : "") << "), kernels compiled in "
              << ctx.compile_seconds() << " s\n";

    if (!a.csv.empty()) {
        write_file_atomic(a.csv, fd_csv(f, a.components ? &comp.components : nullptr));
    }
    if (!a.json_path.empty()) {
        json j;
        j["volume"] = a.volume;
        j["dims"] = {dims.nx, dims.ny, dims.nz};
        j["type"] = value_type_name(type);
        j["kind"] = kind_name;
        j["levels"] = a.levels;
        j["min_count"] = a.min_count;
        j["isovalues_total"] = iso.size();
        j["isovalues_defined"] = s.defined;
        j["mean_fd"] = fd_json(s.mean);
        j["std_fd"] = fd_json(s.std);
        j["weighted_mean_fd"] = fd_json(s.weighted_mean);
        j["kappa"] = fd_json(s.kappa);
        j["device"] = ctx.description();
        j["seconds_compute"] = spans.seconds;
        j["seconds_compile"] = ctx.compile_seconds();
        j["slabs"] = spans.slabs;
        j["clean_bands"] = bands_json(f, bands);
        if (a.noise_level) j["noise"] = noise_json(noise);
        if (a.components) {
            j["corr_components"] = fd_json(corr.components);
            j["corr_components_per_area"] = fd_json(corr.components_per_area);
            j["corr_isovalues"] = corr.used;
        }
        json curve = json::array();
        for (std::size_t k = 0; k < iso.size(); ++k) {
            json row;
            row["isovalue"] = iso.value(k);
            json counts = json::array();
            for (int l = 0; l < a.levels; ++l) counts.push_back(f.counts[l][k]);
            row["counts"] = counts;
            row["fd"] = fd_json(f.fd[k]);
            if (a.levels > 2) row["fd_fit"] = fd_json(f.fd_fit[k]);
            if (a.components) row["components"] = comp.components[k];
            curve.push_back(row);
        }
        j["curve"] = curve;
        write_file_atomic(a.json_path, j.dump(1) + "\n");
    }
    if (!a.plot.empty() && a.components)
        write_components_plot(iso, comp.components, &f.fd,
                              std::filesystem::path(a.volume).filename().string() + ": FD and isosurface components",
                              a.plot);
    else if (!a.plot.empty())
        write_fd_plot(f, bands, a.min_count,
                      std::filesystem::path(a.volume).filename().string() + ": mean FD " + fd_string(s.mean).substr(0, 5),
                      a.plot);
    return 0;
}

// ------------------------------------------------------------------ local

struct LocalArgs {
    std::string volume, output, mesh;
    double iso = 0;
    int window = 8;
    bool stream = false;
    RawArgs raw;
};

int cmd_local(LocalArgs a) {
    if (a.stream) {
        if (!a.mesh.empty()) throw InputError("--mesh: not with --stream (the mesh needs the whole volume)");
        if (is_auto_isovalue(a.iso)) throw InputError("--iso auto: not with --stream (it needs the whole curve first)");
        return cmd_local_stream(a.volume, a.raw.options(), a.iso, a.window, a.output);
    }
    Volume v = read_volume(a.volume, a.raw.options());
    a.iso = checked_isovalue(v, a.iso);
    Context& ctx = Context::shared();
    progress("local fractal dimension of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + ", window " +
             std::to_string(a.window) + ", on " + ctx.description());
    const auto t0 = std::chrono::steady_clock::now();
    Volume ld = local_fractal_dimension(ctx, v, a.iso, a.window);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    write_volume(ld, a.output, &v);
    const LocalSummary s = summarize_local(ld);

    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n"
              << "device      " << ctx.description() << "\n"
              << "isovalue    " << a.iso << compared_as(v.type()) << ", window "
              << a.window << "\n"
              << std::fixed << std::setprecision(2) << "defined     " << s.defined << " of " << s.vertices
              << " vertices (" << 100.0 * double(s.defined) / double(s.vertices) << "%, near the surface)\n";
    if (s.defined)
        std::cout << "LD > 2.2    " << 100 * s.above_blue << "% of them (colour map: blue up to 2.2)\n"
                  << "LD > 2.5    " << 100 * s.above_red << "% of them (red from 2.5)\n"
                  << std::setprecision(4) << "mean LD     " << s.mean << "\n";
    else
        std::cout << "mean LD     n/a (the isovalue intersects no window)\n";
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << seconds << " s, kernels compiled in "
              << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << " (float32, NaN where LD is undefined)\n";
    if (!a.mesh.empty()) {
        // The marching-cubes isosurface at the same isovalue, coloured by this LD field.
        Mesh mesh = extract_isosurface(v, a.iso);
        color_by_ld(mesh, ld);
        write_ply(mesh, a.mesh);
        std::cout << "wrote       " << a.mesh << " (" << mesh.positions.size() << " vertices, " << mesh.triangles.size()
                  << " triangles, coloured by LD)\n";
    }
    return 0;
}

// ------------------------------------------------------------------ mesh

struct MeshArgs {
    std::string volume, output, method = "mc", preview;
    double iso = 0;
    bool color_by_ld = false;
    int window = 8;
    RawArgs raw;
};

int cmd_mesh(MeshArgs a) {
    const MeshMethod method = parse_mesh_method(a.method);
    Volume v = read_volume(a.volume, a.raw.options());
    a.iso = checked_isovalue(v, a.iso);
    using clock = std::chrono::steady_clock;
    const auto seconds_since = [](clock::time_point t) { return std::chrono::duration<double>(clock::now() - t).count(); };

    auto t = clock::now();
    Mesh mesh = extract_isosurface(v, a.iso, method);
    const double extract_seconds = seconds_since(t);
    std::ostringstream times;
    times << std::setprecision(3) << "extraction " << extract_seconds << " s";
    if (a.color_by_ld) {
        Context& ctx = Context::shared();
        progress("local fractal dimension, window " + std::to_string(a.window) + ", on " + ctx.description());
        t = clock::now();
        color_by_ld(mesh, local_fractal_dimension(ctx, v, a.iso, a.window));
        times << ", LD field " << seconds_since(t) << " s";
    }
    t = clock::now();
    write_ply(mesh, a.output);
    times << ", PLY " << seconds_since(t) << " s";
    if (!a.preview.empty()) {
        t = clock::now();
        write_png(render_mesh(mesh), a.preview);
        times << ", preview " << seconds_since(t) << " s";
    }

    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n"
              << "isovalue    " << a.iso << "  ("
              << (method == MeshMethod::marching_cubes ? "marching cubes, negative vertices separated"
                                                       : "marching tetrahedra, Freudenthal triangulation")
              << ")\n"
              << "mesh        " << mesh.positions.size() << " vertices (one per intersected edge), "
              << mesh.triangles.size() << " triangles\n";
    if (mesh.triangles.empty()) {
        const ValueRange r = value_range(v);
        std::cout << "            no surface: the isovalue does not cross the values " << r.min << " .. " << r.max << "\n";
    }
    if (a.color_by_ld) {
        std::size_t red = 0, blue = 0, undefined = 0;
        for (float ld : mesh.ld) {
            red += ld >= ld_red;
            blue += ld <= ld_blue;
            undefined += std::isnan(ld);
        }
        const double n = std::max<double>(1, double(mesh.ld.size()));
        std::cout << std::fixed << std::setprecision(1) << "colour      LD window " << a.window << ": " << 100 * red / n
                  << "% red (LD >= " << ld_red << "), " << 100 * blue / n << "% blue (LD <= " << ld_blue << "), "
                  << 100 * undefined / n << "% grey (undefined)\n"
                  << std::defaultfloat;
    }
    std::cout << "time        " << times.str() << "\n";
    return 0;
}

// ------------------------------------------------------------------ gen

int cmd_gen(const std::string& name, const SyntheticOptions& o, const std::string& type, const std::string& out) {
    SyntheticOptions opt = o;
    if (!type.empty()) opt.type = parse_value_type(type);
    if (opt.size < 2 || opt.size > 2048) throw InputError("--size " + std::to_string(opt.size) + ": must be 2..2048");
    Volume v = make_synthetic(name, opt);
    write_volume(v, out);
    progress("wrote " + out + " (" + dims_string(v.dims()) + " " + value_type_name(v.type()) + ")");
    return 0;
}

// ------------------------------------------------------------------ bench

int cmd_bench(std::size_t size, int repeats, const std::string& json_path) {
    Context& ctx = Context::shared();
    progress("building inputs");
    auto cases = default_bench_cases(size);
    BenchReport r = run_span_bench(ctx, cases, repeats, [](const std::string& s) { progress("bench: " + s); });
    std::cout << "device          " << r.device << "\n"
              << "copy bandwidth  " << std::fixed << std::setprecision(2) << r.copy_gbs << " GB/s (read + write)\n"
              << "OpenMP threads  " << r.openmp_threads << "\n"
              << "kernel compile  " << r.compile_seconds << " s (apart from the figures below)\n\n"
              << "span curve, levels 0 and 1, best of " << repeats << ":\n"
              << "  volume        isovalues  device s  Gcubes/s  GB/s  roofline   OpenMP s  Gcubes/s  device/OpenMP  counts\n";
    json rows = json::array();
    for (auto& row : r.rows) {
        std::cout << "  " << std::left << std::setw(13) << row.label << std::right << std::setw(10) << row.isovalues
                  << std::setw(10) << std::setprecision(4) << row.device_seconds << std::setw(10)
                  << std::setprecision(3) << row.device_gcubes() << std::setw(6) << std::setprecision(2)
                  << row.device_gbs() << std::setw(9) << std::setprecision(1)
                  << 100 * row.device_gbs() / r.copy_gbs << "%" << std::setw(11) << std::setprecision(4)
                  << row.openmp_seconds << std::setw(10) << std::setprecision(3) << row.openmp_gcubes()
                  << std::setw(14) << std::setprecision(2) << row.speedup() << "x  "
                  << (row.counts_equal ? "equal" : "DIFFER") << "\n";
        rows.push_back({{"volume", row.label},
                        {"isovalues", row.isovalues},
                        {"cubes", row.cubes},
                        {"bytes", row.bytes},
                        {"device_seconds", row.device_seconds},
                        {"device_counting_seconds", row.counting_seconds},
                        {"device_gcubes_per_s", row.device_gcubes()},
                        {"device_gb_per_s", row.device_gbs()},
                        {"roofline_fraction", row.device_gbs() / r.copy_gbs},
                        {"openmp_seconds", row.openmp_seconds},
                        {"openmp_gcubes_per_s", row.openmp_gcubes()},
                        {"speedup_vs_openmp", row.speedup()},
                        {"counts_equal", row.counts_equal}});
    }
    std::cout << "(device s and OpenMP s: whole calls, buffers and threads included; GB/s and roofline: bytes of\n"
                 " one read per level over the device's counting time (uploads, kernels, downloads) against the\n"
                 " copy bandwidth; device/OpenMP > 1: device faster)\n";
    if (!json_path.empty()) {
        json j{{"device", r.device},
               {"copy_gb_per_s", r.copy_gbs},
               {"openmp_threads", r.openmp_threads},
               {"compile_seconds", r.compile_seconds},
               {"repeats", repeats},
               {"span", rows}};
        write_file_atomic(json_path, j.dump(1) + "\n");
    }
    for (auto& row : r.rows)
        if (!row.counts_equal) return 1;
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"clfractal: isosurface fractal dimension of 3D scalar grids, for every isovalue at once"};
    app.require_subcommand(1);
    app.add_flag("-q,--quiet", cli::quiet, "no progress on stderr");
    app.set_version_flag("--version", "clfractal 0.1.0");

    app.add_subcommand("devices", "list OpenCL platforms and devices, marking the chosen one");

    auto* info = app.add_subcommand("info", "dimensions, type, value range and histogram of a volume");
    std::string info_volume;
    RawArgs info_raw;
    info->add_option("VOLUME", info_volume, "a .nrrd/.nhdr/.raw file or synthetic:NAME[:N]")->required();
    info_raw.add(info);

    auto* fd = app.add_subcommand("fd", "fractal dimension curve for every isovalue");
    FdArgs fa;
    fd->add_option("VOLUME", fa.volume, "a .nrrd/.nhdr/.raw file or synthetic:NAME[:N]")->required();
    fd->add_flag("--edge", fa.edge, "edge span dimension (eq. 3.1) instead of box (eq. 2.5)");
    fd->add_option("--levels", fa.levels, "pyramid levels for the least-squares estimate (2 = eq. 2.5)");
    fd->add_option("--isovalues", fa.isovalues, "isovalues A:B:STEP (float data; integer data: A:B:1)");
    fd->add_option("--bins", fa.bins, "number of uniform isovalues for float data (default 256)");
    fd->add_option("--min-count", fa.min_count, "summary only where the subsampled count is >= M");
    fd->add_option("--csv", fa.csv, "write isovalue,count,count_sub,fd");
    fd->add_option("--json", fa.json_path, "write the summary and curve as JSON");
    fd->add_option("--plot", fa.plot, "draw the curve to a PNG with gnuplot");
    fd->add_flag("--components", fa.components,
                 "add the isosurface component count (cube connectivity) and its correlation with D");
    fd->add_option("--slab", fa.slab, "process z-slabs of at most this many slices (default: from device memory)");
    fd->add_flag("--stream", fa.stream, "read the file slice by slice (memory: a few slices; same numbers)");
    fd->add_option("--clean-fd", fa.clean_fd, "clean bands: D(s) at most this")->capture_default_str();
    fd->add_option("--clean-share", fa.clean_share, "clean bands: I(s) at least this share of the largest")
        ->capture_default_str();
    fd->add_flag("--noise-level", fa.noise_level,
                 "estimate the noise in grey values from the edge dimension (Theorem 1 inverted)");
    fa.raw.add(fd);

    auto* local = app.add_subcommand("local", "local fractal dimension field (eq. 2.6) for one isovalue, as NRRD");
    LocalArgs la;
    local->add_option("VOLUME", la.volume, "a .nrrd/.nhdr/.raw file or synthetic:NAME[:N]")->required();
    add_iso_option(local, la.iso, "isovalue S (cubes with a < S <= b are intersected)")->required();
    add_window_option(local, la.window, "window k");
    local->add_option("-o,--output", la.output, "output .nrrd, .nii or .nii.gz (float32)")->required();
    local->add_option("--mesh", la.mesh, "also write the isosurface as PLY, coloured by LD");
    local->add_flag("--stream", la.stream, "read and write slice by slice (memory: a few slices; same field)");
    la.raw.add(local);

    auto* gen = app.add_subcommand("gen", "write a synthetic volume (NRRD, or NIfTI for .nii/.nii.gz)");
    std::string gen_name, gen_type, gen_out;
    SyntheticOptions gen_opt;
    std::string names;
    for (auto& s : synthetic_catalog()) names += (names.empty() ? "" : ", ") + s.name;
    gen->add_option("NAME", gen_name, "one of: " + names)->required();
    gen->add_option("--size", gen_opt.size, "N: the volume is N^3 (default 128)");
    gen->add_option("--noise", gen_opt.noise, "uniform noise amplitude mu");
    gen->add_option("--seed", gen_opt.seed, "noise / point seed");
    gen->add_option("--points", gen_opt.points, "number of points for 'points'");
    gen->add_option("--type", gen_type, "convert to " + value_type_names());
    gen->add_option("-o,--output", gen_out, "output .nrrd, .nii or .nii.gz")->required();

    auto* mesh = app.add_subcommand("mesh", "isosurface mesh as PLY (marching cubes or tetrahedra), optional preview PNG");
    MeshArgs ma;
    mesh->add_option("VOLUME", ma.volume, "a .nrrd/.nhdr/.raw file or synthetic:NAME[:N]")->required();
    add_iso_option(mesh, ma.iso, "isovalue S (positive vertices: f >= S)")->required();
    mesh->add_option("-o,--output", ma.output, "output .ply (binary)")->required();
    mesh->add_option("--method", ma.method, "mc: marching cubes (default), mt: marching tetrahedra")
        ->check(CLI::IsMember({"mc", "mt"}));
    auto* color_flag = mesh->add_flag("--color-by-ld", ma.color_by_ld, "colour vertices by local fractal dimension");
    add_window_option(mesh, ma.window)->needs(color_flag);
    mesh->add_option("--preview", ma.preview, "render the mesh to a PNG (three-quarter view)");
    ma.raw.add(mesh);

    auto* bench = app.add_subcommand("bench", "span-curve throughput: device vs copy bandwidth vs OpenMP");
    std::size_t bench_size = 256;
    int bench_repeats = 3;
    std::string bench_json;
    bench->add_option("--size", bench_size, "N for the N^3 cases (2N^3 is run too; default 256)");
    bench->add_option("--repeats", bench_repeats, "best of this many runs (default 3)");
    bench->add_option("--json", bench_json, "write the figures as JSON");

    // Subcommands that live in their own files (cmd_*.cpp).
    cli::Commands commands;
    cli::add_smooth_command(app, commands);
    add_noise_command(app, commands);
    cli::add_filter_command(app, commands);
    add_components_command(app, commands);
    add_survey_command(app, commands);
    cli::add_fd4_commands(app, commands);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::string msg = e.what();
        std::replace(msg.begin(), msg.end(), '\n', ' ');
        std::cerr << "clfractal: error: " << msg << " (see clfractal --help)\n";
        return 2;
    }

    const auto run = [&]() -> int {
        if (app.got_subcommand("devices")) return cmd_devices();
        if (app.got_subcommand(info)) return cmd_info(info_volume, info_raw);
        if (app.got_subcommand(fd)) return cmd_fd(fa);
        if (app.got_subcommand(local)) return cmd_local(la);
        if (app.got_subcommand(gen)) return cmd_gen(gen_name, gen_opt, gen_type, gen_out);
        if (app.got_subcommand(mesh)) return cmd_mesh(ma);
        if (app.got_subcommand(bench)) return cmd_bench(bench_size, bench_repeats, bench_json);
        for (auto& c : commands)
            if (app.got_subcommand(c.app)) return c.run();
        return 0;
    };
    try {
        // Every output path is checked before any work; with one of them "-" (stdout), the
        // report moves to stderr. The outputs appear together when the command succeeds.
        for (const CLI::App* chosen : app.get_subcommands())
            if (check_output_options(*chosen)) std::cout.rdbuf(std::cerr.rdbuf());
        OutputRun outputs;
        const int rc = run();
        if (rc == 0) outputs.commit();
        return rc;
    } catch (const InputError& e) {
        std::cerr << "clfractal: error: " << printable(e.what()) << "\n";
        return 2;
    } catch (const DeviceError& e) {
        std::cerr << "clfractal: error: " << (e.out_of_memory() ? "the device is out of memory: " : "") << e.what()
                  << "\n";
        return e.out_of_memory() ? 2 : 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "clfractal: error: out of host memory\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "clfractal: error: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
