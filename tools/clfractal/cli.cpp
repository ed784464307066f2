// Shared pieces of the command-line tool (see cli.hpp).
#include "cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "clfractal/device.hpp"
#include "clfractal/error.hpp"
#include "clfractal/local.hpp"
#include "clfractal/memory.hpp"
#include "clfractal/slice_reader.hpp"
#include "device/slab_plan.hpp"
#include "io/formats.hpp"
#include "clfractal/volume.hpp"

using namespace clfractal;

namespace cli {

bool quiet = false;
void progress(const std::string& s) {
    if (!quiet) std::cerr << "clfractal: " << s << "\n";
}

void print_bands(std::ostream& out, const FdCurve& f, const std::vector<CleanBand>& bands, double max_fd,
                 double min_share) {
    const IsovalueSet& iso = f.isovalues;
    std::ostringstream head;
    head << "D <= " << max_fd << ", surface >= " << 100 * min_share << "% of the largest";
    if (bands.empty()) {
        out << "clean bands none (" << head.str() << "); every well-populated isovalue is rough\n";
        return;
    }
    out << "clean bands " << bands.size() << " (" << head.str() << "; about 2 is a clean surface, towards 3 noise)\n";
    for (std::size_t i = 0; i < bands.size() && i < 5; ++i) {
        const CleanBand& b = bands[i];
        out << "  " << (i == 0 ? "best " : "     ") << iso_string(iso, b.first) << " .. " << iso_string(iso, b.last)
            << "  (" << b.width() << " isovalue" << (b.width() > 1 ? "s" : "") << ", mean D " << b.mean_fd
            << ", up to " << b.max_count << " cubes)  use " << iso_string(iso, b.representative) << "\n";
    }
}

void print_noise(std::ostream& out, const NoiseEstimate& e) {
    if (e.used == 0) {
        out << "noise       n/a: no well-populated isovalue has an edge dimension in [" << noise_fd_min << ", "
            << noise_fd_max << "] (below: too clean to measure; above: noise dominates)\n";
        return;
    }
    out << "noise       +-" << e.median_amplitude << " grey values uniform (std " << e.median_amplitude / std::sqrt(3.0)
        << "), r = noise / gradient " << e.median_ratio << "; median over " << e.used
        << " isovalues (Theorem 1 inverted)\n";
}

namespace {

// "isovalue 60  clean  D 2.0512  1234 cubes  17 components"
std::string entry_line(const Analysis& an, const Recommendation& e) {
    std::ostringstream o;
    o << "isovalue " << iso_string(an.isovalues, e.index) << "  " << verdict_name(e.verdict) << "  D "
      << (std::isnan(e.fd) ? std::string("n/a") : fd_string(e.fd).substr(0, 6)) << "  " << e.count << " cubes";
    if (e.components >= 0) o << "  " << e.components << " components";
    return o.str();
}

}  // namespace

namespace {

// The output name `run:` suggests for `volume`: its file name without the extension (".nii.gz"
// whole), or the synthetic volume's name ("synthetic:noisy-sphere:64": "noisy-sphere_64"),
// then "-denoised.nrrd".
std::string denoised_name(const std::string& volume) {
    const std::string synthetic = "synthetic:";
    std::string stem = volume.rfind(synthetic, 0) == 0 ? volume.substr(synthetic.size())
                                                        : std::filesystem::path(volume).stem().string();
    if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".nii") == 0) stem.resize(stem.size() - 4);
    std::replace(stem.begin(), stem.end(), ':', '_');
    return stem + "-denoised.nrrd";
}

}  // namespace

void print_advice(std::ostream& out, const Analysis& an, const std::string& volume) {
    const IsovalueSet& iso = an.isovalues;
    for (std::size_t i = 0; i < an.recommended.size(); ++i) {
        const Recommendation& e = an.recommended[i];
        out << (i == 0 ? "recommended " : "            ") << i + 1 << ". " << entry_line(an, e) << "  (" << e.basis
            << " " << iso_string(iso, e.first) << " .. " << iso_string(iso, e.last) << ")\n";
    }
    if (an.recommended.empty()) {
        out << "recommended none: no cube is intersected at any isovalue (no surface to extract)\n";
        return;
    }
    if (an.noisiest) out << "noisiest    " << entry_line(an, *an.noisiest) << "\n";
    for (const std::string& why : an.skipped) out << "skipped     " << why << "\n";
    if (an.clean) return;
    std::ostringstream clean_fd;
    clean_fd << an.options.advice.clean_fd;
    out << "advice      no well-populated isovalue is clean (D <= " << clean_fd.str()
        << "); the cleanest is isovalue " << iso_string(iso, an.best().index) << " ("
        << verdict_name(an.best().verdict) << ")\n";
    for (const DenoiseAttempt& d : an.denoise) {
        std::ostringstream head;
        head << "denoise     " << d.filter;
        if (d.targeted) head << " where LD > " << d.threshold << " at isovalue " << iso_string(iso, an.best().index);
        head << ": " << std::fixed << std::setprecision(2) << 100 * d.changed_share << "% of vertices changed, ";
        out << head.str();
        if (d.clean && !d.recommended.empty()) {
            const Recommendation& e = d.recommended.front();
            out << "then clean at " << iso_string(iso, e.first) << " .. " << iso_string(iso, e.last) << " (use "
                << iso_string(iso, e.index) << ", D " << fd_string(e.fd).substr(0, 6) << ")\n"
                << "            run: " << d.command(volume, denoised_name(volume))
                << "\n";
        } else {
            out << "still not clean (mean D " << fd_string(d.summary.mean).substr(0, 6) << ")\n";
        }
    }
}

CLI::Option* add_window_option(CLI::App* app, int& window, const std::string& what) {
    return app
        ->add_option("--window", window, what + " (even, >= 2)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                const std::string problem = window_problem(std::atoi(text.c_str()));
                return problem.empty() ? problem : problem + ", not " + text;
            },
            "EVEN>=2"))
        ->capture_default_str();
}

CLI::Option* add_iso_option(CLI::App* app, double& iso, const std::string& what) {
    return app->add_option("--iso", iso, what + " (or auto: the first recommendation of the analysis)")
        ->transform(CLI::Validator(
            [](std::string& text) -> std::string {
                if (text == "auto") {
                    char buf[32];
                    std::snprintf(buf, sizeof buf, "%.17g", auto_isovalue);
                    text = buf;
                    return {};
                }
                char* end = nullptr;
                const double s = std::strtod(text.c_str(), &end);
                if (end == text.c_str() || *end || !std::isfinite(s)) return "must be a finite number or auto, not " + text;
                return {};
            },
            "S|auto"));
}

double checked_isovalue(const Volume& v, double iso) {
    if (!is_auto_isovalue(iso)) {
        warn_isovalue_outside(v, iso);
        return iso;
    }
    Recommendation e;
    const double s = clfractal::auto_isovalue(Context::shared(), v, &e);
    const IsovalueSet set = IsovalueSet::for_volume(v);
    const std::string taken = "isovalue " + iso_string(set, e.index) + " (" + verdict_name(e.verdict) + ", D " +
                              fd_string(e.fd).substr(0, 6) + "), the first recommendation, from the " + e.basis + " " +
                              iso_string(set, e.first) + " .. " + iso_string(set, e.last);
    if (e.verdict == Verdict::clean) {
        progress("--iso auto: " + taken + ": the first clean band's representative");
    } else {
        // Nothing well-populated is clean: the answer is the cleanest there is, said as a
        // warning (silenced by --quiet, as for an isovalue outside the values).
        if (!quiet)
            std::cerr << "clfractal: warning: --iso auto: " << taken << ": no well-populated isovalue of " << v.name
                      << " is clean (D <= " << AdviceOptions{}.clean_fd << "), so this is the cleanest; its surface is "
                      << verdict_name(e.verdict) << " (`clfractal fd` shows the denoising that makes a band clean)\n";
    }
    return s;
}

void warn_isovalue_outside(const Volume& v, double iso) {
    const ValueRange r = value_range(v);
    if (iso > r.min && iso <= r.max) return;
    std::ostringstream msg;
    msg << "clfractal: warning: isovalue " << iso << " is outside (" << r.min << ", " << r.max << "], the values of "
        << v.name << ": no cube is intersected";
    if (!quiet) std::cerr << msg.str() << "\n";
}

void RawArgs::add(CLI::App* app) {
    app->add_option("--dims", dims, "raw file dimensions X,Y,Z or XxYxZ (default: from a NAME_XxYxZ_TYPE.raw name)");
    app->add_option("--type", type, "raw file value type: " + value_type_names() + " (default: from the name)");
    app->add_option("--endian", endian, "raw file byte order")->check(CLI::IsMember({"little", "big"}));
    app->add_option("--spacing", spacing, "raw file vertex spacing SX,SY,SZ (meshes and reports use it)")
        ->default_str("1,1,1");
    app->add_option("--series", series, "DICOM: the series (SeriesInstanceUID) of a directory to read");
    app->add_flag("--scaled", scaled, "NIfTI: apply scl_slope/scl_inter to the stored values");
    app->add_option("--as", as, "convert the values to this type on read, from any format (" + value_type_names() +
                                    "); may round (float64 -> float32 keeps 24 bits) and saturates to the type's range");
}

Dims parse_dims(const std::string& option, const std::string& text) {
    char c1 = 0, c2 = 0;
    std::istringstream in(text);
    long long x = 0, y = 0, z = 0;
    if (!(in >> x >> c1 >> y >> c2 >> z) || c1 != c2 || (c1 != ',' && c1 != 'x') || !(in >> std::ws).eof() ||
        x < 1 || y < 1 || z < 1)
        throw InputError(option + " '" + text + "': expected three positive integers X,Y,Z");
    const Dims d{std::size_t(x), std::size_t(y), std::size_t(z)};
    check_dims(d, option + " " + text);
    return d;
}

RawOptions RawArgs::options() const {
    RawOptions o;
    if (!dims.empty()) o.dims = parse_dims("--dims", dims);
    if (!type.empty()) o.type = parse_value_type(type);
    o.big_endian = endian == "big";
    if (!spacing.empty()) {
        const std::vector<double> s = parse_list("--spacing", spacing);
        if (s.size() != 3 || spacing.find(':') != std::string::npos)
            throw InputError("--spacing " + spacing + ": expected three numbers SX,SY,SZ");
        for (int a = 0; a < 3; ++a) {
            if (!(s[a] > 0)) throw InputError("--spacing " + spacing + ": spacings must be > 0");
            o.spacing[a] = s[a];
        }
    }
    o.series = series;
    o.scaled = scaled;
    if (!as.empty()) o.as = parse_value_type(as);
    return o;
}

CLI::Option* add_volume_argument(CLI::App* app, std::string& volume) {
    return app->add_option("VOLUME", volume, "a volume file (raw, NRRD, NIfTI, DICOM, TIFF, MetaImage) or synthetic:NAME[:N]")
        ->required();
}

void add_volume_and_iso(CLI::App* app, std::string& volume, double& iso, const std::string& what) {
    add_volume_argument(app, volume);
    add_iso_option(app, iso, what)->required();
}

std::uint64_t MemoryNeed::bytes(std::uint64_t volume_bytes) const {
    return std::uint64_t(factor * double(volume_bytes)) + (std::uint64_t(256) << 20);
}

namespace {

void require_volume_memory(const std::string& volume, const MemoryNeed& need, std::uint64_t volume_bytes,
                           std::uint64_t held) {
    char factor[16];
    std::snprintf(factor, sizeof factor, "%g", need.factor);
    MemoryRequest r;
    r.need = need.bytes(volume_bytes), r.held = held;
    r.file = volume, r.what = need.command;
    r.basis = std::string(factor) + "x the " + byte_size_string(volume_bytes) + " volume + 256 MiB";
    r.hint = std::string(need.hint) + (*need.hint ? "; " : "") + "CLFRACTAL_MEMORY_LIMIT=off runs it anyway";
    require_memory(r);
}

}  // namespace

namespace {

// Whether start_device_for left the start of the device context to read_volume_within.
bool device_after_read = false;

}  // namespace

void start_device_for(const CLI::App& command) {
    const CLI::Option* volume = command.get_option_no_throw("VOLUME");
    const CLI::Option* stream = command.get_option_no_throw("--stream");
    if (volume && volume->count() == 1 && !(stream && stream->count() > 0)) {
        const std::string path = volume->as<std::string>();
        std::error_code ec;
        if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) >= io::parallel_read_bytes && !ec) {
            device_after_read = true;
            return;
        }
    }
    Context::start_shared();
}

Volume read_volume_within(const std::string& volume, const RawOptions& raw, const MemoryNeed& need,
                          FiniteCheck finite) {
    const std::optional<VolumeShape> shape = peek_volume(volume, raw);
    if (shape) require_volume_memory(volume, need, shape->bytes(), 0);
    // Data stored uncompressed is read on every core: the platform starts after it.
    if (device_after_read && !(shape && shape->method == "mmap")) Context::start_shared();
    Volume v = read_volume(volume, raw, finite);
    if (device_after_read) Context::start_shared();  // (once: a second call does nothing)
    if (!shape) require_volume_memory(volume, need, v.size_bytes(), v.size_bytes());
    return v;
}

Volume read_volume_at_isovalue(const std::string& volume, const RawArgs& raw, double& iso, const MemoryNeed& need) {
    Volume v = read_volume_within(volume, raw.options(), need);
    iso = checked_isovalue(v, iso);
    return v;
}

CLI::Option* add_output_option(CLI::App* app, std::string& output, const std::string& what) {
    return app->add_option("-o,--output", output, what)->required();
}

CLI::Option* add_mesh_option(CLI::App* app, std::string& mesh, const std::string& what) {
    return app->add_option("--mesh", mesh, what);
}

CLI::Option* add_preview_option(CLI::App* app, std::string& preview, const std::string& what) {
    return app->add_option("--preview", preview, what);
}

CLI::Option* add_bins_option(CLI::App* app, std::size_t& bins) {
    return app->add_option("--bins", bins, "number of uniform isovalues for float data (0: 256)");
}

std::vector<double> parse_list(const std::string& option, const std::string& spec) {
    const auto number = [&](const std::string& s) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(s, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != s.size() || s.empty() || !std::isfinite(x))
            throw InputError(option + " " + spec + ": '" + s + "' is not a number");
        return x;
    };
    std::vector<double> out;
    if (spec.find(':') != std::string::npos) {
        std::vector<std::string> parts;
        std::stringstream ss(spec);
        for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
        if (parts.size() != 3) throw InputError(option + " " + spec + ": a range is A:B:STEP");
        const double a = number(parts[0]), b = number(parts[1]), step = number(parts[2]);
        if (!(step > 0) || b < a) throw InputError(option + " " + spec + ": needs STEP > 0 and A <= B");
        if ((b - a) / step > 100000) throw InputError(option + " " + spec + ": more than 100000 values");
        for (long k = 0; a + k * step <= b + 1e-9 * step; ++k) out.push_back(a + k * step);
    } else {
        std::stringstream ss(spec);
        for (std::string p; std::getline(ss, p, ',');) out.push_back(number(p));
    }
    if (out.empty()) throw InputError(option + ": the list is empty");
    return out;
}

void check_bins(std::size_t bins, ValueType type) {
    if (bins && is_integer(type) && !is_wide(type))
        throw InputError("--bins: 8/16-bit integer data uses every integer isovalue; use --isovalues A:B:1 to select");
}

IsovalueSet parse_isovalues(const std::string& spec, ValueType type) {
    if (spec.find(':') != std::string::npos) return IsovalueSet::parse_range(spec, type);
    std::vector<double> v = parse_list("--isovalues", spec);
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    if (is_integer(type) && !is_wide(type)) {
        // Every integer of a range is counted at once: a list of consecutive integers.
        for (std::size_t j = 0; j < v.size(); ++j)
            if (v[j] != std::floor(v[j]) || v[j] != v[0] + double(j))
                throw InputError("--isovalues '" + spec + "': " + value_type_name(type) +
                                 " data takes consecutive integers (or A:B:1)");
        return IsovalueSet::integers(std::int64_t(v.front()), std::int64_t(v.back()));
    }
    if (type != ValueType::float32) return IsovalueSet::doubles(v);
    std::vector<float> f(v.begin(), v.end());
    f.erase(std::unique(f.begin(), f.end()), f.end());
    return IsovalueSet::floats(f);
}

CLI::Option* add_isovalues_option(CLI::App* app, std::string& spec) {
    return app->add_option("--isovalues", spec,
                           "isovalues A:B:STEP or A,B,... (8/16-bit integer data: A:B:1 or consecutive integers; "
                           "default: every integer of the range, or --bins uniform ones)");
}

std::string iso_string(const IsovalueSet& iso, std::size_t j) { return iso.text(j); }

std::string compared_as(ValueType t) {
    return is_integer(t) ? "" : std::string(" (compared as ") + value_type_name(t) + ")";
}

std::string fd_string(double d) {
    if (std::isnan(d)) return "";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", d);
    return buf;
}

nlohmann::json fd_json(double d) { return std::isnan(d) ? nlohmann::json(nullptr) : nlohmann::json(d); }

std::string components_csv(const IsovalueSet& iso, const std::vector<std::int64_t>& components) {
    std::ostringstream out;
    out << "isovalue,components\n";
    for (std::size_t j = 0; j < iso.size(); ++j) out << iso_string(iso, j) << "," << components[j] << "\n";
    return out.str();
}

nlohmann::json fd_analysis_json(const Analysis& an, const FdSummary& s, const FdJsonFacts& f) {
    nlohmann::json j = nlohmann::json::parse(to_json(an));
    j["volume"] = f.volume;
    j["dims"] = {an.dims.nx, an.dims.ny, an.dims.nz};
    j["type"] = value_type_name(an.type);
    j["kind"] = f.edge ? "edge" : "box";
    j["levels"] = f.levels;
    j["min_count"] = f.min_count;
    j["isovalues_total"] = an.isovalues.size();
    j["isovalues_defined"] = s.defined;
    j["mean_fd"] = fd_json(s.mean);
    j["std_fd"] = fd_json(s.std);
    j["weighted_mean_fd"] = fd_json(s.weighted_mean);
    j["kappa"] = fd_json(s.kappa);
    return j;
}

std::string denoise_not_streamed() {
    return "denoise: nothing is clean, but the ladder filters the whole volume in one process's memory; "
           "clfractal fd without --stream runs it";
}

std::string components_json(const std::string& volume, const Dims& dims, ValueType type, Connectivity mode,
                            const IsovalueSet& iso, const std::vector<std::int64_t>& components) {
    nlohmann::json j;
    j["volume"] = volume;
    j["dims"] = {dims.nx, dims.ny, dims.nz};
    j["type"] = value_type_name(type);
    j["connectivity"] = connectivity_name(mode);
    std::vector<double> values(iso.size());
    for (std::size_t k = 0; k < iso.size(); ++k) values[k] = iso.value(k);
    j["isovalues"] = values;
    j["components"] = components;
    return j.dump(1) + "\n";
}

std::string components_plot_title(const std::string& volume, Connectivity mode) {
    return std::filesystem::path(volume).filename().string() + ": isosurface components (" + connectivity_name(mode) +
           ")";
}

void print_components(std::ostream& out, const std::string& volume, const Dims& dims, ValueType type,
                      Connectivity mode, const IsovalueSet& iso, const std::vector<std::int64_t>& components) {
    std::size_t peak = 0;
    for (std::size_t j = 0; j < iso.size(); ++j)
        if (components[j] > components[peak]) peak = j;
    out << "volume        " << volume << "  " << dims_string(dims) << " " << value_type_name(type) << "\n"
        << "connectivity  " << connectivity_name(mode)
        << (mode == Connectivity::cube ? " ({f < s} 6-connected, {f >= s} 26-connected; marching cubes)"
                                       : " (both 14-connected; Freudenthal triangulation, marching tetrahedra)")
        << "\n"
        << "isovalues     " << iso.size() << " (" << iso_string(iso, 0) << " .. " << iso_string(iso, iso.size() - 1)
        << ")\n"
        << "most          " << components[peak] << " components at isovalue " << iso_string(iso, peak) << "\n";
}

std::string fd_csv(const FdCurve& f, const std::vector<std::int64_t>* components) {
    const int levels = f.levels();
    std::ostringstream out;
    out << "isovalue,count,count_sub,fd";
    for (int l = 2; l < levels; ++l) out << ",count_l" << l;
    if (levels > 2) out << ",fd_fit";
    if (components) out << ",components";
    out << "\n";
    for (std::size_t j = 0; j < f.fd.size(); ++j) {
        out << iso_string(f.isovalues, j) << "," << f.counts[0][j] << "," << f.counts[1][j] << "," << fd_string(f.fd[j]);
        for (int l = 2; l < levels; ++l) out << "," << f.counts[l][j];
        if (levels > 2) out << "," << fd_string(f.fd_fit[j]);
        if (components) out << "," << (*components)[j];
        out << "\n";
    }
    return out.str();
}

ReportVolume::ReportVolume(Context& ctx, const Volume& v) : ctx_(ctx), host_(v) {
    SlabNeed need;
    need.nz = v.dims().nz;
    need.input_slice_bytes = v.dims().nx * v.dims().ny * value_size(v.type());
    need.memory_divisor = 2;
    // Where the copy would double the volume in host memory, each count uploads what it reads.
    if (!copy_doubles_host_memory(ctx, v.size_bytes()) && v.vertices() > 0 && int_axes(v.dims()) && slab_fit(ctx, need) >= need.nz) device_.emplace(ctx, v);
}

ReportVolume::ReportVolume(const Volume& v, DeviceVolume&& on_device)
    : ctx_(on_device.context()), host_(v), device_(std::move(on_device)) {}

SpanResult ReportVolume::spans_at(double s) const {
    const IsovalueSet iso = IsovalueSet::single(host_.type(), s);
    return device_ ? count_spans(*device_, iso) : count_spans(ctx_, host_, iso);
}

IsoCounts ReportVolume::counts_at(double s) const {
    return device_ ? intersected_counts(*device_, s) : intersected_counts(ctx_, host_, s);
}

std::int64_t ReportVolume::components_at(double s) const {
    return device_ ? count_components_at(*device_, s) : count_components_at(ctx_, host_, s);
}

}  // namespace cli
