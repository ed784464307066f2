// clfractal filter: median, Gaussian or bilateral denoising, everywhere or only where the
// local fractal dimension says there is noise (include/clfractal/filter.hpp); or the
// small-components filter at one isovalue (include/clfractal/small_components.hpp).
#include <chrono>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "clfractal/components.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/small_components.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/stream.hpp"
#include "clfractal/span.hpp"
#include "cli.hpp"
#include "output.hpp"

#include <nlohmann/json.hpp>

using namespace clfractal;

namespace {

struct FilterArgs {
    std::string volume, output, bilateral, json_path, connectivity = "cube";
    bool median = false, fractal = false, fractal4 = false, ld_guided = false, stream = false;
    double gaussian = 0, iso = NAN, threshold = NAN, q = 0;
    int window = 8;
    long long small_components = -1;
    cli::RawArgs raw;
    CLI::App* app = nullptr;  // for which options were given
};

FilterSpec parse_spec(const FilterArgs& a, CLI::App* app) {
    const int chosen = int(a.median) + int(app->count("--gaussian") > 0) + int(!a.bilateral.empty());
    if (chosen != 1) throw InputError("filter: choose exactly one of --median, --gaussian SIGMA, --bilateral SS,SR");
    FilterSpec s;
    if (app->count("--gaussian")) s = FilterSpec::gaussian(a.gaussian);
    if (!a.bilateral.empty()) {
        std::istringstream in(a.bilateral);
        double ss = 0, sr = 0;
        char comma = 0;
        if (!(in >> ss >> comma >> sr) || comma != ',' || !(in >> std::ws).eof())
            throw InputError("--bilateral '" + a.bilateral + "': expected SIGMA_S,SIGMA_R");
        s = FilterSpec::bilateral(ss, sr);
    }
    s.check();
    return s;
}

// Intersected cubes of G and G' and the box span dimension at isovalue s (docs/definitions.md
// §8, §3): integer data counts at ceil(s), which selects the same cubes.
struct AtIso {
    std::uint64_t cubes = 0, cubes_sub = 0;
    double fd = NAN;
};
AtIso measure(const cli::ReportVolume& v, double s) {
    const SpanResult r = v.spans_at(s);
    AtIso m;
    m.cubes = r.get(SpanKind::cubes).counts[0][0];
    m.cubes_sub = r.get(SpanKind::cubes).counts[1][0];
    if (m.cubes && m.cubes_sub) m.fd = std::log2(double(m.cubes) / double(m.cubes_sub));
    return m;
}

std::string fd_text(double d) {
    if (std::isnan(d)) return "n/a";
    std::ostringstream s;
    s << std::fixed << std::setprecision(4) << d;
    return s.str();
}

// --fractal --stream: the file read slice by slice, the filtered slices written as they
// leave the stream (k/2 slices behind), cubes and FD at S counted by two SpanStreams.
int run_filter_stream(const FilterArgs& a, const FilterSpec& spec) {
    SliceReader reader(a.volume, a.raw.options());
    const Dims d = reader.dims();
    const ValueType t = reader.type();
    Context& ctx = Context::shared();
    cli::progress(spec.describe() + " where LD > " + std::to_string(a.threshold) + ", slice by slice (" +
                  reader.method() + "), " + dims_string(d) + " " + value_type_name(t) + " on " + ctx.description());
    const IsovalueSet iso = IsovalueSet::single(t, a.iso);
    SpanStream before(ctx, d.nx, d.ny, t, iso, 2, {SpanKind::cubes}), after(ctx, d.nx, d.ny, t, iso, 2, {SpanKind::cubes});
    const auto t0 = std::chrono::steady_clock::now();
    SliceWriter writer(a.output, d, t, reader);
    TargetedFilterStream stream(ctx, d.nx, d.ny, t, spec, a.iso, a.threshold, a.window,
                                [&](std::size_t, const void* filtered, const float*) {
                                    writer.write(filtered, 1);
                                    after.push_slice(filtered);
                                });
    std::vector<unsigned char> slice(reader.slice_bytes());
    for (std::size_t z = 0; z < d.nz; ++z) {
        reader.read(slice.data(), 1);
        before.push_slice(static_cast<const void*>(slice.data()));
        stream.push_slice(slice.data());
    }
    stream.finish();
    writer.close();
    const double seconds = seconds_since(t0);
    const auto at = [](const SpanStream& s) {
        AtIso m;
        const SpanResult r = s.counts();
        m.cubes = r.curves[0].counts[0][0];
        m.cubes_sub = r.curves[0].counts[1][0];
        if (m.cubes && m.cubes_sub) m.fd = std::log2(double(m.cubes) / double(m.cubes_sub));
        return m;
    };
    const AtIso b = at(before), f = at(after);
    const double n = double(d.vertices());
    std::cout << "volume      " << a.volume << "  " << dims_string(d) << " " << value_type_name(t) << "\n"
              << "filter      " << spec.describe() << ", fractal-targeted: where LD > " << a.threshold
              << " (isovalue " << a.iso << ", window " << a.window << "), streamed " << stream.slices()
              << " slices (" << reader.method() << ")\n"
              << "device      " << ctx.description() << "\n"
              << std::fixed << std::setprecision(2) << "selected    " << stream.selected() << " vertices ("
              << 100 * double(stream.selected()) / n << "%) with LD > " << a.threshold << "\n"
              << "changed     " << stream.changed() << " vertices (" << 100 * double(stream.changed()) / n << "%)\n"
              << "isovalue    " << a.iso << "     before      after\n"
              << "  cubes     " << std::setw(12) << b.cubes << " " << std::setw(10) << f.cubes << "\n"
              << "  FD        " << std::setw(12) << fd_text(b.fd) << " " << std::setw(10) << fd_text(f.fd) << "\n"
              << std::defaultfloat << std::setprecision(4) << "time        " << seconds << " s, kernels compiled in "
              << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << " (" << value_type_name(t) << ")\n";
    return 0;
}

// The combinations of options that make no sense, before any file is read.
void check_filter_options(const FilterArgs& a, const FilterSpec& spec, CLI::App* app) {
    if (int(a.fractal) + int(a.fractal4) + int(a.ld_guided) > 1)
        throw InputError("filter: --fractal, --fractal4 and --ld-guided exclude each other");
    if (a.fractal4 && std::isnan(a.threshold)) throw InputError("--fractal4 needs --threshold H4");
    if (!a.fractal4 && app->count("--q")) throw InputError("--q: only with --fractal4");
    if (a.fractal4 && a.stream) throw InputError("--stream: not with --fractal4 (LD4 needs the whole volume)");
    if ((a.fractal || a.ld_guided) && std::isnan(a.iso))
        throw InputError(std::string(a.fractal ? "--fractal" : "--ld-guided") + " needs --iso S");
    if (a.fractal && std::isnan(a.threshold)) throw InputError("--fractal needs --threshold H");
    if (!a.fractal && !a.fractal4 && !std::isnan(a.threshold))
        throw InputError("--threshold: only with --fractal or --fractal4");
    if (a.ld_guided && spec.kind != FilterKind::bilateral) throw InputError("--ld-guided: only with --bilateral");
    if (!std::isnan(a.iso) && !std::isfinite(a.iso)) throw InputError("--iso: must be a finite number");
    if (a.stream && !a.fractal) throw InputError("--stream: only with --fractal (the targeted filter streams)");
    if (a.stream && cli::is_auto_isovalue(a.iso))
        throw InputError("--iso auto: not with --stream (it needs the whole curve first)");
}

// The filter in words: what, and where (the mask), for the report and the progress line.
std::string describe_filter(const FilterArgs& a, const FilterSpec& spec, const Volume& v) {
    std::string how = spec.describe();
    if (a.fractal) {
        std::ostringstream s;
        s << ", fractal-targeted: where LD > " << a.threshold << " (isovalue " << a.iso << ", window " << a.window
          << ")";
        how += s.str();
    } else if (a.fractal4) {
        std::ostringstream s;
        s << ", targeted by the 4D field: where LD4 > " << a.threshold << " (bin width "
          << (a.q ? a.q : default_bin_width(v)) << ", window " << a.window << ")";
        how += s.str();
    } else if (a.ld_guided) {
        std::ostringstream s;
        s << ", LD-guided range (isovalue " << a.iso << ", window " << a.window << ")";
        how += s.str();
    }
    return how;
}

// The vertices a masked filter selected.
void print_selected(const FilterArgs& a, const TargetedResult& tr) {
    if (a.fractal)
        std::cout << "selected    " << tr.selected << " vertices (" << 100 * tr.selected_share << "%) with LD > "
                  << a.threshold << "\n";
    if (a.fractal4)
        std::cout << "selected    " << tr.selected << " vertices (" << 100 * tr.selected_share << "%) with LD4 > "
                  << a.threshold << "\n";
    if (a.ld_guided)
        std::cout << "selected    " << tr.selected << " vertices (" << 100 * tr.selected_share
                  << "%) with LD > 2 (the others keep their values)\n";
}

// Cubes, FD and components at the isovalue, before and after.
void print_at_iso(double iso, const cli::ReportVolume& v, const cli::ReportVolume& out, const AtIso& before,
                  const AtIso& after) {
    std::cout << "isovalue    " << iso << "     before      after\n"
              << "  cubes     " << std::setw(12) << before.cubes << " " << std::setw(10) << after.cubes << "\n"
              << "  FD        " << std::setw(12) << fd_text(before.fd) << " " << std::setw(10)
              << fd_text(after.fd) << "\n";
    std::cout << "  components" << std::setw(12) << v.components_at(iso) << " " << std::setw(10)
              << out.components_at(iso) << "\n";
}

// A copy of the volume's corner of at most 16^3 vertices: filtered once before the timed
// call so that kernel compilation, which PoCL finishes at each kernel's first launch, stays
// out of seconds_compute.
Volume corner_of(const Volume& v) {
    const Dims d = v.dims(), c{std::min<std::size_t>(d.nx, 16), std::min<std::size_t>(d.ny, 16),
                               std::min<std::size_t>(d.nz, 16)};
    Volume corner(c, v.type());
    const std::size_t vs = value_size(v.type());
    for (std::size_t z = 0; z < c.nz; ++z)
        for (std::size_t y = 0; y < c.ny; ++y)
            std::memcpy(static_cast<unsigned char*>(corner.data()) + (z * c.ny + y) * c.nx * vs,
                        static_cast<const unsigned char*>(v.data()) + v.index(0, y, z) * vs, c.nx * vs);
    return corner;
}

// The filter of the command line on `in`: targeted (LD or LD4), LD-guided or everywhere.
struct FilterRun {
    Volume out;
    std::optional<DeviceVolume> out_device;  ///< the unmasked filter of an input on the device
    TargetedResult tr;
    bool masked = false;
    double seconds = 0, compiled = 0;  ///< the timed call, and the compilation inside it
};

// `on_device`: `in` on the device (the unmasked filter reads it there), or nullptr.
void filter_once(Context& ctx, const FilterArgs& a, const FilterSpec& spec, const Volume& in,
                 const DeviceVolume* on_device, FilterRun& r) {
    using clock = std::chrono::steady_clock;
    if (a.fractal4) {
        const auto t = clock::now();
        const Volume ld4 = local_fractal_dimension_4d(ctx, in, a.q, a.window);
        const double field_seconds = seconds_since(t);
        r.tr = targeted_filter(ctx, in, spec, ld4, a.threshold);
        r.tr.ld_seconds = field_seconds;
    } else if (a.fractal && on_device) r.tr = targeted_filter(*on_device, in, spec, a.iso, a.threshold, a.window);
    else if (a.fractal) r.tr = targeted_filter(ctx, in, spec, a.iso, a.threshold, a.window);
    else if (a.ld_guided) r.tr = ld_bilateral_filter(ctx, in, spec.sigma_s, spec.sigma_r, a.iso, a.window);
    else if (on_device) r.out = r.out_device.emplace(apply_filter(*on_device, spec)).download();
    else r.out = apply_filter(ctx, in, spec);
}

FilterRun timed_filter(Context& ctx, const FilterArgs& a, const FilterSpec& spec, const Volume& v,
                       const DeviceVolume* on_device) {
    FilterRun r;
    r.masked = a.fractal || a.fractal4 || a.ld_guided;
    if (!a.json_path.empty()) filter_once(ctx, a, spec, corner_of(v), nullptr, r);
    const double compiled_before = ctx.compile_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    filter_once(ctx, a, spec, v, on_device, r);
    r.seconds = seconds_since(t0);
    // Compute only: the call's time less any kernel compiled during it (no file I/O is in it).
    r.compiled = ctx.compile_seconds() - compiled_before;
    if (r.masked) r.out = std::move(r.tr.volume);
    return r;
}

void write_filter_json(const FilterArgs& a, const std::string& how, const Context& ctx, const Volume& v,
                       const FilterRun& r, std::size_t changed) {
    nlohmann::json j;
    j["volume"] = a.volume;
    j["dims"] = {v.dims().nx, v.dims().ny, v.dims().nz};
    j["type"] = value_type_name(v.type());
    j["filter"] = how;
    j["device"] = ctx.description();
    j["vertices"] = v.vertices();
    j["selected"] = r.masked ? r.tr.selected : v.vertices();
    j["changed"] = changed;
    j["fraction_selected"] = r.masked ? r.tr.selected_share : 1.0;
    j["fraction_changed"] = double(changed) / double(v.vertices());
    j["seconds"] = r.seconds;
    j["seconds_compile"] = r.compiled;
    j["seconds_compute"] = std::max(0.0, r.seconds - r.compiled);
    // The parts of a masked filter (each may hold some of the compilation).
    j["seconds_ld"] = r.masked ? r.tr.ld_seconds : 0.0;
    j["seconds_filter"] = r.masked ? r.tr.filter_seconds : r.seconds;
    write_file_atomic(a.json_path, j.dump(2) + "\n");
}

// --small-components K: the options it excludes, before any file is read.
void check_small_components_options(const FilterArgs& a, CLI::App* app) {
    for (const char* other : {"--median", "--gaussian", "--bilateral", "--fractal", "--fractal4", "--ld-guided",
                              "--threshold", "--q", "--stream"})
        if (app->count(other)) throw InputError(std::string("--small-components: not with ") + other);
    if (a.small_components < 0) throw InputError("--small-components: K must be >= 0");
    if (std::isnan(a.iso)) throw InputError("--small-components needs --iso S (or --iso auto)");
}

int run_small_components(FilterArgs a, CLI::App* app) {
    check_small_components_options(a, app);
    const SmallComponentsConnectivity mode = parse_small_components_connectivity(a.connectivity);
    Volume v = cli::read_volume_within(a.volume, a.raw.options(), {"clfractal filter"});
    a.iso = cli::checked_isovalue(v, a.iso);
    Context& ctx = Context::shared();
    const cli::ReportVolume input(ctx, v);
    const AtIso before = measure(input, a.iso);
    std::ostringstream how;
    how << "small components: at most " << a.small_components << " vertices (isovalue " << a.iso << ", "
        << small_components_connectivity_name(mode) << " connectivity)";
    cli::progress(how.str() + " of " + dims_string(v.dims()) + " " + value_type_name(v.type()));
    SmallComponentsResult r;
    try {
        r = small_components_filter(v, a.iso, std::size_t(a.small_components), mode);
    } catch (const InputError& e) {
        throw InputError(a.volume + ": " + e.what());
    }
    const cli::ReportVolume output(ctx, r.volume);
    const AtIso after = measure(output, a.iso);
    write_volume(r.volume, a.output, &v);
    const double n = double(v.vertices());
    const auto surface = [](std::size_t p, std::size_t q) { return p && q ? std::int64_t(p + q) - 1 : 0; };
    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type())
              << "\n"
              << "filter      " << how.str() << "\n"
              << "removed     " << r.positive_removed << " components of {f >= s} (" << r.lowered
              << " vertices to " << r.lowered_value << "), " << r.negative_removed << " of {f < s} (" << r.raised
              << " vertices to " << r.raised_value << ")\n"
              << std::fixed << std::setprecision(2) << "changed     " << r.changed << " vertices ("
              << 100 * double(r.changed) / n << "%)\n"
              << "isovalue    " << a.iso << "     before      after\n"
              << "  cubes     " << std::setw(12) << before.cubes << " " << std::setw(10) << after.cubes << "\n"
              << "  FD        " << std::setw(12) << fd_text(before.fd) << " " << std::setw(10) << fd_text(after.fd)
              << "\n"
              << "  {f >= s}  " << std::setw(12) << r.positive_before << " " << std::setw(10) << r.positive_after
              << "\n"
              << "  {f < s}   " << std::setw(12) << r.negative_before << " " << std::setw(10) << r.negative_after
              << "\n"
              << "  components" << std::setw(12) << surface(r.positive_before, r.negative_before) << " "
              << std::setw(10) << surface(r.positive_after, r.negative_after) << "\n"
              << std::defaultfloat << std::setprecision(4) << "time        " << r.seconds << " s (host labelling)\n"
              << "wrote       " << a.output << " (" << value_type_name(v.type()) << ")\n";
    if (!a.json_path.empty()) {
        nlohmann::json j;
        j["volume"] = a.volume;
        j["dims"] = {v.dims().nx, v.dims().ny, v.dims().nz};
        j["type"] = value_type_name(v.type());
        j["filter"] = how.str();
        j["isovalue"] = r.isovalue;
        j["vertices"] = v.vertices();
        j["changed"] = r.changed;
        j["fraction_changed"] = r.changed_share;
        j["positive_before"] = r.positive_before;
        j["negative_before"] = r.negative_before;
        j["positive_removed"] = r.positive_removed;
        j["negative_removed"] = r.negative_removed;
        j["positive_after"] = r.positive_after;
        j["negative_after"] = r.negative_after;
        j["seconds"] = r.seconds;
        j["seconds_compile"] = 0.0;
        j["seconds_compute"] = r.seconds;
        write_file_atomic(a.json_path, j.dump(2) + "\n");
    }
    return 0;
}

int run_filter(FilterArgs a, CLI::App* app) {
    if (app->count("--small-components")) return run_small_components(a, app);
    if (app->count("--connectivity")) throw InputError("--connectivity: only with --small-components");
    const FilterSpec spec = parse_spec(a, app);
    check_filter_options(a, spec, app);
    if (a.stream) return run_filter_stream(a, spec);

    Volume v = cli::read_volume_within(a.volume, a.raw.options(), {"clfractal filter"});
    if (!std::isnan(a.iso)) a.iso = cli::checked_isovalue(v, a.iso);
    Context& ctx = Context::shared();
    const bool at_iso = !std::isnan(a.iso);
    // The input on the device once: the reports before and the unmasked filter read it.
    const cli::ReportVolume input(ctx, v);
    AtIso before, after;
    if (at_iso) before = measure(input, a.iso);

    const std::string how = describe_filter(a, spec, v);
    cli::progress(how + " of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " on " + ctx.description());
    FilterRun r = timed_filter(ctx, a, spec, v, input.device());
    const Volume& out = r.out;
    std::optional<cli::ReportVolume> output;  // the result on the device once, for the reports after
    if (at_iso && r.out_device) output.emplace(out, std::move(*r.out_device));
    else if (at_iso) output.emplace(ctx, out);
    if (at_iso) after = measure(*output, a.iso);
    write_volume(out, a.output, &v);

    std::size_t changed = r.masked ? r.tr.changed : 0;
    if (!r.masked)
        for (std::size_t i = 0; i < v.vertices(); ++i) changed += out.value(i) != v.value(i);
    const double n = double(v.vertices());
    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type())
              << "\n"
              << "filter      " << how << "\n"
              << "device      " << ctx.description() << "\n";
    std::cout << std::fixed << std::setprecision(2);
    print_selected(a, r.tr);
    std::cout << "changed     " << changed << " vertices (" << 100 * double(changed) / n << "%)\n";
    if (at_iso) print_at_iso(a.iso, input, *output, before, after);
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << r.seconds << " s";
    if (r.masked) std::cout << " (LD field " << r.tr.ld_seconds << " s, masked filter " << r.tr.filter_seconds << " s)";
    std::cout << ", kernels compiled in " << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << " (" << value_type_name(out.type()) << ")\n";
    if (!a.json_path.empty()) write_filter_json(a, how, ctx, v, r, changed);
    return 0;
}

void setup_filter(CLI::App* c, FilterArgs& a) {
    a.app = c;
    cli::add_volume_argument(c, a.volume);
    c->add_flag("--median", a.median, "3x3x3 median");
    c->add_option("--gaussian", a.gaussian, "separable Gaussian with this sigma (radius ceil(3 sigma))");
    c->add_option("--bilateral", a.bilateral, "bilateral filter SIGMA_S,SIGMA_R (radius ceil(2 sigma_s))");
    c->add_flag("--fractal", a.fractal, "filter only vertices with LD > H (needs --iso, --threshold)");
    c->add_flag("--fractal4", a.fractal4,
                "filter only vertices whose local 4D dimension LD4 > H4 (needs --threshold; no isovalue)");
    cli::add_q_option(c, a.q);
    c->add_flag("--ld-guided", a.ld_guided,
                "bilateral with the range scale sigma_r * min(LD - 2, 1) (thesis 6.3; needs --iso)");
    cli::add_iso_option(c, a.iso, "isovalue S of the LD field, needed by --fractal, --ld-guided and --small-components; also reports cubes and FD at S before/after");
    c->add_option("--threshold", a.threshold, "LD threshold H of --fractal (LD4 threshold H4 of --fractal4), needed by both");
    c->add_option("--small-components", a.small_components,
                  "set the components of {f >= s} and {f < s} with at most K vertices just across s (needs --iso)");
    c->add_option("--connectivity", a.connectivity,
                  "of --small-components: cube ({f >= s} 26-connected, {f < s} 6-connected) or six (both 6)");
    cli::add_window_option(c, a.window);
    cli::add_output_option(c, a.output, "output .nrrd, .nii or .nii.gz (the input's type)");
    c->add_option("--json", a.json_path,
                  "write the times (seconds_compute: no file I/O, no compilation; seconds_ld, seconds_filter) and "
                  "the fractions selected and changed as JSON");
    c->add_flag("--stream", a.stream,
                "with --fractal: read, filter and write slice by slice (memory for a few slices; radius <= k/2)");
    a.raw.add(c);
}

}  // namespace

namespace cli {

Command filter_command() {
    return command<FilterArgs>(
        "filter", "median, Gaussian or bilateral filter, everywhere or where the local fractal dimension is high; or small components removed",
        setup_filter, [](const FilterArgs& a) { return run_filter(a, a.app); });
}

}  // namespace cli
