// The extension module behind the `clfractal` Python package (python/clfractal/__init__.py):
// thin calls into the C++ library. Arrays arrive as 3D NumPy arrays in (z, y, x) order of a
// value type the library computes in (the package's one dtype table chose it, by name); a
// C-contiguous one is read in place (Volume::wrap), any other copied once, honouring its
// strides, into a clfractal::Volume (x fastest). Results
// leave as NumPy arrays that own the library's buffers (no copy). Device work runs without
// the GIL, one call at a time per OpenCL context; contexts and their program caches live for
// the whole process.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/analysis.hpp"
#include "cli.hpp"
#include "output.hpp"
#include "report_page.hpp"
#include "clfractal/components.hpp"
#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/noise.hpp"
#include "clfractal/noise_level.hpp"
#include "clfractal/ply.hpp"
#include "clfractal/small_components.hpp"
#include "clfractal/smooth.hpp"
#include "clfractal/span.hpp"
#include "clfractal/stream.hpp"
#include "clfractal/version.hpp"
#include "clfractal/volume_io.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using namespace clfractal;

namespace {

// ------------------------------------------------------------------ devices and contexts

/// One OpenCL context with the lock that serialises the calls made on it.
struct Device {
    Context* ctx = nullptr;
    std::mutex* lock = nullptr;
};

/// The context for `selector` (select_device: a substring of "platform / device",
/// case-insensitive), or the library's shared context (CLFRACTAL_DEVICE,
/// CLFRACTAL_DEVICE_TYPE) when it is empty.
/// One context per device, created on first use and kept for the life of the process, so
/// every selector naming the same device shares its compiled programs.
std::mutex registry_lock;
std::map<Context*, std::unique_ptr<std::mutex>> context_locks;  // every context used so far

Device device_for(const std::optional<std::string>& selector) {
    // Never destroyed, like Context::shared(): no OpenCL object is released after the
    // interpreter has finalised and the OpenCL runtime's exit handlers may have run.
    static auto& contexts = *new std::map<cl_device_id, std::unique_ptr<Context>>;
    std::lock_guard<std::mutex> guard(registry_lock);
    Context* ctx = nullptr;
    if (!selector || selector->empty()) {
        ctx = &Context::shared();
    } else {
        const DeviceEntry match = select_device({*selector, ""});
        if (match.chosen) {
            ctx = &Context::shared();  // the default device: its context
        } else {
            auto& owned_ctx = contexts[match.device()];
            if (!owned_ctx) owned_ctx = std::make_unique<Context>(match.device);
            ctx = owned_ctx.get();
        }
    }
    auto& lock = context_locks[ctx];
    if (!lock) lock = std::make_unique<std::mutex>();
    return {ctx, lock.get()};
}

/// Runs f(ctx) on the selected device with the GIL released and the device's lock held.
template <class F> auto on_device(const std::optional<std::string>& selector, F&& f) {
    Device d = device_for(selector);
    nb::gil_scoped_release no_gil;
    std::lock_guard<std::mutex> guard(*d.lock);
    return f(*d.ctx);
}

// ------------------------------------------------------------------ arrays in and out

using InArray = nb::ndarray<nb::ro, nb::ndim<3>, nb::device::cpu>;

/// Arrays copied into a Volume so far (clfractal._clfractal.host_copies): C-contiguous
/// arrays are read in place and count none.
std::atomic<std::size_t> host_copies{0};

/// Whether the volume may read the array in place, or must own a copy of its values.
enum class InPlace { allowed, never };

/// A (z, y, x) array of the value type `type_name` as a Volume: read in place when it is
/// C-contiguous (Volume::wrap; the array outlives the call that uses it) and `in_place`
/// allows, else copied following its strides (in elements, any sign), so views and
/// transposes need no copy beforehand. Float data holding NaN or Inf is rejected unless
/// `finite` is keep.
Volume to_volume(const InArray& a, const std::string& type_name, FiniteCheck finite = FiniteCheck::reject,
                 InPlace in_place = InPlace::allowed) {
    const ValueType type = parse_value_type(type_name);
    const std::size_t item = value_size(type);
    if (a.itemsize() != item)
        throw InputError("array: " + std::to_string(a.itemsize()) + "-byte elements given as " + type_name);
    const Dims dims{a.shape(2), a.shape(1), a.shape(0)};
    const bool contiguous = a.stride(2) == 1 && a.stride(1) == std::int64_t(a.shape(2)) &&
                            a.stride(0) == std::int64_t(a.shape(2) * a.shape(1));
    if (contiguous && in_place == InPlace::allowed) {
        // Read only: every computing call takes its input as const.
        Volume v = Volume::wrap(const_cast<void*>(a.data()), dims, type, "array");
        if (finite == FiniteCheck::reject) check_finite(v, "array");
        return v;
    }
    ++host_copies;
    Volume v(dims, type, "array");
    const auto* src = static_cast<const unsigned char*>(a.data());
    auto* dst = static_cast<unsigned char*>(v.data());
    const std::int64_t sz = a.stride(0) * std::int64_t(item), sy = a.stride(1) * std::int64_t(item),
                       sx = a.stride(2) * std::int64_t(item);
    const std::size_t nx = a.shape(2), row = nx * item;
    for (std::size_t z = 0; z < a.shape(0); ++z)
        for (std::size_t y = 0; y < a.shape(1); ++y, dst += row) {
            const unsigned char* s = src + std::int64_t(z) * sz + std::int64_t(y) * sy;
            if (sx == std::int64_t(item)) {
                std::memcpy(dst, s, row);
            } else {
                for (std::size_t x = 0; x < nx; ++x) std::memcpy(dst + x * item, s + std::int64_t(x) * sx, item);
            }
        }
    // NaN and Inf rejected as from files (docs/definitions.md §1); writers keep them (LD fields).
    if (finite == FiniteCheck::reject) check_finite(v, "array");
    return v;
}

/// A volume uploaded once (clfractal.DeviceVolume): the host copy and the device volume that
/// reads it (zero-copy where the device shares host memory), on the device it was uploaded
/// to. Every call given it reads the device copy: no upload.
struct Uploaded {
    Device device;
    Volume host;  // declared before `on_device`: it outlives the zero-copy buffer
    DeviceVolume on_device;
    Uploaded(const InArray& a, const std::string& type, const std::optional<std::string>& selector)
        : device(device_for(selector)), host(to_volume(a, type, FiniteCheck::reject, InPlace::never)) {
        nb::gil_scoped_release no_gil;
        std::lock_guard<std::mutex> guard(*device.lock);
        on_device = DeviceVolume(*device.ctx, host);
    }
};

/// The volume of a call: a NumPy array (copied into a Volume; the call uploads it) or an
/// Uploaded volume.
struct Input {
    Volume copy;
    Uploaded* uploaded = nullptr;
    const Volume& host() const { return uploaded ? uploaded->host : copy; }
    const DeviceVolume* device() const { return uploaded ? &uploaded->on_device : nullptr; }
};

Input input_of(nb::handle volume, const std::string& type) {
    Input in;
    if (nb::isinstance<Uploaded>(volume)) in.uploaded = nb::inst_ptr<Uploaded>(volume);
    else in.copy = to_volume(nb::cast<InArray>(volume), type);
    return in;
}

/// Runs f(ctx) where the input is: an Uploaded volume's device (a device selector must
/// not name another), else the selected one.
template <class F> auto on_input(const Input& in, const std::optional<std::string>& selector, F&& f) {
    if (!in.uploaded) return on_device(selector, std::forward<F>(f));
    if (selector && device_for(selector).ctx != in.uploaded->device.ctx)
        throw InputError("device '" + *selector + "': the DeviceVolume was uploaded to another device");
    nb::gil_scoped_release no_gil;
    std::lock_guard<std::mutex> guard(*in.uploaded->device.lock);
    return f(*in.uploaded->device.ctx);
}

/// A 1D NumPy array that owns `values` (moved to the heap, freed with the array).
template <class T> nb::ndarray<nb::numpy, T, nb::ndim<1>> owned(std::vector<T>&& values) {
    auto* heap = new std::vector<T>(std::move(values));
    nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
    return nb::ndarray<nb::numpy, T, nb::ndim<1>>(heap->data(), {heap->size()}, owner);
}

/// A volume's bytes as a 1D uint8 NumPy array that owns the volume, with its type name;
/// the package views them as (z, y, x) of its dtype.
nb::tuple volume_out(Volume&& v) {
    auto* heap = new Volume(std::move(v));
    nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<Volume*>(p); });
    nb::ndarray<nb::numpy, std::uint8_t, nb::ndim<1>> bytes(static_cast<std::uint8_t*>(heap->data()),
                                                            {heap->size_bytes()}, owner);
    const Dims& d = heap->dims();
    return nb::make_tuple(bytes, std::string(value_type_name(heap->type())), nb::make_tuple(d.nz, d.ny, d.nx));
}

nb::dict make_dict(std::initializer_list<std::pair<const char*, nb::object>> items) {
    nb::dict d;
    for (auto& [key, value] : items) d[key] = value;
    return d;
}

// ------------------------------------------------------------------ isovalues

/// The isovalue set the library counts, and which of its entries the caller asked for
/// (all when `pick` is empty). Integer data counts the integer range spanning the request.
struct Isovalues {
    IsovalueSet set;
    std::vector<std::size_t> pick;
};

Isovalues requested_isovalues(ValueType type, const std::vector<double>& s);

Isovalues choose_isovalues(const Volume& v, const std::optional<std::vector<double>>& requested, std::size_t bins) {
    if (!requested) return {IsovalueSet::for_volume(v, bins), {}};
    return requested_isovalues(v.type(), *requested);
}

/// The isovalue set of a requested list for data of `type`.
Isovalues requested_isovalues(ValueType type, const std::vector<double>& s) {
    if (s.empty()) throw InputError("isovalues: the list is empty");
    for (std::size_t j = 0; j < s.size(); ++j) {
        if (!std::isfinite(s[j])) throw InputError("isovalues: value " + std::to_string(j) + " is not finite");
        if (j && !(s[j - 1] < s[j]))
            throw InputError("isovalues: the list must be strictly increasing (at index " + std::to_string(j) + ")");
    }
    if (type == ValueType::float32) return {IsovalueSet::floats(std::vector<float>(s.begin(), s.end())), {}};
    // float64 data, and int32/uint32 data (whose ranges may be wider than an integer set):
    // float64 isovalues, compared exactly in double.
    if (!is_integer(type) || is_wide(type)) return {IsovalueSet::doubles(s), {}};
    for (std::size_t j = 0; j < s.size(); ++j)
        if (s[j] != std::floor(s[j]))
            throw InputError("isovalues: integer data takes integer isovalues (value " + std::to_string(j) + " is " +
                             std::to_string(s[j]) + ")");
    Isovalues r{IsovalueSet::integers(std::int64_t(s.front()), std::int64_t(s.back())), {}};
    for (double x : s) r.pick.push_back(std::size_t(std::int64_t(x) - std::int64_t(s.front())));
    return r;
}

template <class T> std::vector<T> picked(const std::vector<T>& all, const std::vector<std::size_t>& pick) {
    if (pick.empty() || all.empty()) return all;  // all: also fd_fit, empty with 2 levels
    std::vector<T> out;
    out.reserve(pick.size());
    for (std::size_t j : pick) out.push_back(all[j]);
    return out;
}

std::vector<double> isovalue_list(const Isovalues& iso) {
    std::vector<double> all(iso.set.size());
    for (std::size_t j = 0; j < all.size(); ++j) all[j] = iso.set.value(j);
    return picked(all, iso.pick);
}

// ------------------------------------------------------------------ the calls

SpanKind span_kind(const std::string& kind_name) {
    if (kind_name == "box") return SpanKind::cubes;
    if (kind_name == "edge") return SpanKind::edges;
    throw InputError("kind '" + kind_name + "': expected 'box' or 'edge'");
}

/// An FD curve as the package's FdCurve takes it: the rows of the requested isovalues
/// (flattened level by level, levels x K), the curve and its summary.
nb::dict curve_dict(const Isovalues& iso, const FdCurve& f, const std::string& kind_name, int levels,
                    std::uint64_t min_count, const std::string& description, double seconds, double compile) {
    // Rows of the requested isovalues, flattened level by level (levels x K).
    std::vector<std::vector<std::uint64_t>> rows;
    std::vector<std::uint64_t> counts;
    for (auto& level : f.counts) {
        rows.push_back(picked(level, iso.pick));
        counts.insert(counts.end(), rows.back().begin(), rows.back().end());
    }
    std::vector<double> fd = picked(f.fd, iso.pick);
    FdSummary s = summarize(fd, rows[0], rows[1], min_count);
    nb::dict summary = make_dict({{"defined", nb::cast(s.defined)},
                                  {"mean", nb::cast(s.mean)},
                                  {"std", nb::cast(s.std)},
                                  {"weighted_mean", nb::cast(s.weighted_mean)},
                                  {"kappa", nb::cast(s.kappa)},
                                  {"min_count", nb::cast(min_count)},
                                  {"isovalues", nb::cast(fd.size())},
                                  {"kind", nb::cast(kind_name)},
                                  {"levels", nb::cast(levels)},
                                  {"device", nb::cast(description)},
                                  {"seconds_compute", nb::cast(seconds)},
                                  {"seconds_compile", nb::cast(compile)}});
    nb::dict out;
    out["isovalues"] = owned(isovalue_list(iso));
    out["counts"] = owned(std::move(counts));
    out["fd"] = owned(std::move(fd));
    out["fd_fit"] = owned(picked(f.fd_fit, iso.pick));
    out["summary"] = summary;
    return out;
}


nb::dict fd_curve_call(nb::handle a, const std::string& type, const std::string& kind_name, int levels,
                       const std::optional<std::vector<double>>& isovalues, std::size_t bins,
                       std::uint64_t min_count, const std::optional<std::string>& device) {
    const SpanKind kind = span_kind(kind_name);
    if (levels < 2 || levels > 16) throw InputError("levels " + std::to_string(levels) + ": must be 2..16");
    const Input in = input_of(a, type);
    const Volume& v = in.host();
    std::string description;
    double compile = 0;
    auto [iso, f, seconds] = on_input(in, device, [&](Context& ctx) {
        const SpanOptions opt{{kind}, levels};
        // Without isovalues, the default set comes with the counts (8-bit data: no pass for
        // the value range).
        Isovalues iso;
        SpanResult spans;
        if (isovalues) {
            iso = requested_isovalues(v.type(), *isovalues);
            spans = in.device() ? count_spans(*in.device(), iso.set, opt) : count_spans(ctx, v, iso.set, opt);
        } else {
            spans = in.device() ? count_spans(*in.device(), v, opt, bins) : count_spans(ctx, v, opt, bins);
            iso.set = spans.isovalues;
        }
        FdCurve f = fd_curve(ctx, spans, kind);
        description = ctx.description();
        compile = ctx.compile_seconds();
        return std::make_tuple(std::move(iso), std::move(f), spans.seconds);
    });
    return curve_dict(iso, f, kind_name, levels, min_count, description, seconds, compile);
}

/// (k, ny, nx) C-contiguous slices, in z order, for the streams.
using Slices = nb::ndarray<nb::ro, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

/// InputError unless `slices` are (k, ny, nx) values of `type`.
void check_slices(const Slices& slices, std::size_t ny, std::size_t nx, ValueType type) {
    if (slices.shape(1) != ny || slices.shape(2) != nx)
        throw InputError("slice: shape (" + std::to_string(slices.shape(1)) + ", " + std::to_string(slices.shape(2)) +
                         "), the stream takes (" + std::to_string(ny) + ", " + std::to_string(nx) + ")");
    if (slices.itemsize() != value_size(type))
        throw InputError("slice: " + std::to_string(slices.itemsize()) + "-byte values, the stream takes " +
                         value_type_name(type));
}

/// clfractal.SliceStream: SpanStream (stream.hpp) on one device, fed (ny, nx) slices in z
/// order; the curve of the slices so far at any time.
struct SliceStream {
    Device device;
    Isovalues iso;
    std::string kind_name;
    int levels;
    std::unique_ptr<SpanStream> stream;
    std::size_t nx, ny;
    SliceStream(std::size_t ny_, std::size_t nx_, const std::string& type, const std::vector<double>& isovalues,
                int levels_, const std::string& kind, const std::optional<std::string>& selector)
        : device(device_for(selector)), kind_name(kind), levels(levels_), nx(nx_), ny(ny_) {
        const ValueType t = parse_value_type(type);
        const SpanKind k = span_kind(kind);
        if (levels < 2 || levels > 16) throw InputError("levels " + std::to_string(levels) + ": must be 2..16");
        if (nx == 0 || ny == 0) throw InputError("shape: every axis needs at least 1 vertex");
        iso = requested_isovalues(t, isovalues);
        nb::gil_scoped_release no_gil;
        std::lock_guard<std::mutex> guard(*device.lock);
        stream = std::make_unique<SpanStream>(*device.ctx, nx, ny, t, iso.set, levels, std::vector<SpanKind>{k});
    }
    /// Adds (k, ny, nx) C-contiguous slices of the stream's type, in z order.
    void push(const Slices& slices) {
        check_slices(slices, ny, nx, stream->type());
        const auto* p = static_cast<const unsigned char*>(slices.data());
        const std::size_t bytes = nx * ny * value_size(stream->type());
        nb::gil_scoped_release no_gil;
        std::lock_guard<std::mutex> guard(*device.lock);
        for (std::size_t z = 0; z < slices.shape(0); ++z) stream->push_slice(static_cast<const void*>(p + z * bytes));
    }
    nb::dict curve() {
        FdCurve f;
        double seconds = 0, compile = 0;
        std::string description;
        {
            nb::gil_scoped_release no_gil;
            std::lock_guard<std::mutex> guard(*device.lock);
            f = stream->curve(span_kind(kind_name));
            seconds = stream->counts().seconds;
            description = device.ctx->description();
            compile = device.ctx->compile_seconds();
        }
        return curve_dict(iso, f, kind_name, levels, 0, description, seconds, compile);
    }
};

/// clfractal.ComponentsStream: ComponentsAtStream (components.hpp), fed (ny, nx) slices in z
/// order; the component counts at its isovalues of the slices so far at any time (host only).
struct ComponentsStream {
    Isovalues iso;
    ValueType type;
    std::size_t nx, ny;
    std::unique_ptr<ComponentsAtStream> stream;
    ComponentsStream(std::size_t ny_, std::size_t nx_, const std::string& type_name, const std::vector<double>& isovalues,
                     const std::string& connectivity)
        : type(parse_value_type(type_name)), nx(nx_), ny(ny_) {
        const Connectivity mode = parse_connectivity(connectivity);
        iso = requested_isovalues(type, isovalues);
        stream = std::make_unique<ComponentsAtStream>(nx, ny, type, isovalue_list(iso), mode);
    }
    void push(const Slices& slices) {
        check_slices(slices, ny, nx, type);
        nb::gil_scoped_release no_gil;
        stream->push_slices(slices.data(), slices.shape(0));
    }
    nb::tuple counts() const { return nb::make_tuple(owned(isovalue_list(iso)), owned(stream->counts())); }
};

/// The LD field of the input (downloaded).
Volume local_field(Context& ctx, const Input& in, double iso, int window) {
    return in.device() ? local_fractal_dimension(*in.device(), iso, window).download()
                       : local_fractal_dimension(ctx, in.host(), iso, window);
}

nb::tuple local_fd_call(nb::handle a, const std::string& type, double iso, int window,
                        const std::optional<std::string>& device) {
    const Input in = input_of(a, type);
    return volume_out(on_input(in, device, [&](Context& ctx) { return local_field(ctx, in, iso, window); }));
}

nb::dict fd4_call(const InArray& a, const std::string& type, double q, const std::optional<std::string>& device) {
    Volume v = to_volume(a, type);
    const Fd4Result r = on_device(device, [&](Context& ctx) { return fractal_dimension_4d(ctx, v, q); });
    return make_dict({{"q", nb::cast(r.q)},
                      {"vmin", nb::cast(r.vmin)},
                      {"i4_l0", nb::cast(r.i4)},
                      {"i4_l1", nb::cast(r.i4_sub)},
                      {"d4", nb::cast(r.d4)}});
}

// The analysis (clfractal::analyse) as the JSON text of to_json; Python builds its records.
std::string analyse_call(const InArray& a, const std::string& type, double clean_fd, double noisy_fd,
                         double clean_share, std::size_t bins, const std::string& components, bool noise_level,
                         bool fd4, bool denoise, int window, const std::optional<std::string>& device) {
    Volume v = to_volume(a, type);
    // The report's analysis (cli::report_options: its memory budget too), then the arguments.
    AnalysisOptions o = cli::report_options({}, v);
    o.advice.clean_fd = clean_fd;
    o.advice.noisy_fd = noisy_fd;
    o.advice.clean_share = clean_share;
    o.bins = bins;
    o.components = parse_components_scope(components);
    o.noise_level = o.surface_noise = noise_level;
    o.fd4 = fd4;
    o.denoise = denoise;
    if (!window_problem(window).empty()) throw InputError("window: " + window_problem(window));
    o.window = window;
    const Analysis r = on_device(device, [&](Context& ctx) { return analyse(ctx, v, o); });
    return to_json(r, -1);
}

/// clfractal report's page and JSON (cli::report_page) of `v`, named `file` and described by
/// `format` on the page; progress lines on stderr only when `progress`.
std::string report_of(const std::string& out, const std::string& json_out, Volume& v, const std::string& file,
                      const std::vector<std::string>& format, double clean_fd, double clean_share, int window,
                      std::size_t bins, std::size_t mesh_triangles, bool static_page, bool progress,
                      const std::optional<std::string>& device, cli::clock_type::time_point t0) {
    if (!window_problem(window).empty()) throw InputError("window: " + window_problem(window));
    cli::ReportSettings s;
    s.clean_fd = clean_fd, s.clean_share = clean_share, s.window = window, s.bins = bins;
    s.mesh_triangles = mesh_triangles, s.static_page = static_page;
    std::string json;
    on_device(device, [&](Context& ctx) {
        // cli::quiet is the tool's one switch; the device lock serialises the calls that set it.
        const bool was_quiet = cli::quiet;
        cli::quiet = !progress;
        try {
            const cli::ReportPage r = cli::report_page(ctx, v, s, file, format, t0);
            json = r.json.dump(1) + "\n";
            ::write_file_atomic(out, r.html);
            if (!json_out.empty()) ::write_file_atomic(json_out, json);
        } catch (...) {
            cli::quiet = was_quiet;
            throw;
        }
        cli::quiet = was_quiet;
        return 0;
    });
    return json;
}

std::string report_file_call(const std::string& out, const std::string& json_out, const std::string& path,
                             const RawOptions& raw, double clean_fd, double clean_share, int window, std::size_t bins,
                             std::size_t mesh_triangles, bool static_page, bool progress,
                             const std::optional<std::string>& device) {
    const auto t0 = cli::clock_type::now();
    std::vector<std::string> format;
    Volume v;
    {
        nb::gil_scoped_release no_gil;
        v = read_volume(path, raw);
        format = describe_volume_file(path, raw);
    }
    return report_of(out, json_out, v, path, format, clean_fd, clean_share, window, bins, mesh_triangles, static_page,
                     progress, device, t0);
}

std::string report_array_call(const std::string& out, const std::string& json_out, const InArray& a,
                              const std::string& type, const std::string& name, const std::vector<double>& spacing,
                              double clean_fd, double clean_share, int window, std::size_t bins,
                              std::size_t mesh_triangles, bool static_page, bool progress,
                              const std::optional<std::string>& device) {
    const auto t0 = cli::clock_type::now();
    Volume v = to_volume(a, type);
    if (spacing.size() != 3) throw InputError("spacing: three values (z, y, x)");
    for (double d : spacing)
        if (!(d > 0) || !std::isfinite(d)) throw InputError("spacing: every value must be finite and > 0");
    v.spacing = {spacing[2], spacing[1], spacing[0]};
    const Dims d = v.dims();
    const std::vector<std::string> format = {"NumPy array (z, y, x) = (" + std::to_string(d.nz) + ", " +
                                             std::to_string(d.ny) + ", " + std::to_string(d.nx) + ") " + type};
    return report_of(out, json_out, v, name, format, clean_fd, clean_share, window, bins, mesh_triangles, static_page,
                     progress, device, t0);
}

nb::dict noise_level_call(nb::handle a, const std::string& type, std::size_t block, std::size_t map_block, double clip,
                          const std::optional<std::string>& device) {
    const Input in = input_of(a, type);
    NoiseLevelOptions o;
    o.block = block;
    o.map_block = map_block;
    o.clip = clip;
    NoiseLevel r = on_input(in, device, [&](Context& ctx) {
        return in.device() ? estimate_noise_level(*in.device(), o) : estimate_noise_level(ctx, in.host(), o);
    });
    const Dims m = r.map_dims;
    const auto triple = [](const std::array<double, 3>& t) { return nb::make_tuple(t[0], t[1], t[2]); };
    nb::list notes;
    for (const std::string& note : noise_level_notes(r)) notes.append(note);
    return make_dict({{"sigma", nb::cast(r.sigma)},
                      {"sigma_white", nb::cast(r.sigma_white)},
                      {"correlation", triple(r.correlation)},
                      {"sigma_strides", nb::make_tuple(r.sigma_strides[0], r.sigma_strides[1], r.sigma_strides[2])},
                      {"texture", nb::cast(r.texture)},
                      {"spread", triple(r.spread)},
                      {"variation", nb::cast(noise_variation(r))},
                      {"notes", notes},
                      {"flat_share", nb::cast(r.flat_share)},
                      {"block", nb::cast(r.block)},
                      {"blocks", nb::cast(r.blocks)},
                      {"blocks_usable", nb::cast(r.usable_blocks)},
                      {"blocks_flat", nb::cast(r.flat_blocks)},
                      {"typical_variance", nb::cast(r.typical_variance)},
                      {"seconds", nb::cast(r.seconds)},
                      {"map_cell", nb::cast(r.map_block)},
                      {"map_shape", nb::make_tuple(m.nz, m.ny, m.nx)},
                      {"map", nb::cast(owned(std::move(r.map)))}});
}

nb::tuple components_call(nb::handle a, const std::string& type, const std::string& connectivity,
                          const std::optional<std::vector<double>>& isovalues, std::size_t bins,
                          const std::optional<std::string>& device) {
    const Connectivity mode = parse_connectivity(connectivity);
    const Input in = input_of(a, type);
    const Volume& v = in.host();
    if (isovalues && isovalues->size() <= few_isovalues) {
        // A few isovalues: each labelled directly (count_components_at), no sort of the volume.
        const Isovalues iso = choose_isovalues(v, isovalues, bins);
        const std::vector<double> at = isovalue_list(iso);
        return nb::make_tuple(owned(std::vector<double>(at)), owned(count_components_at(v, at, mode)));
    }
    auto [iso, curve] = on_input(in, device, [&](Context& ctx) {
        Isovalues iso = choose_isovalues(v, isovalues, bins);
        ComponentCurve c =
            in.device() ? count_components(*in.device(), iso.set, mode) : count_components(ctx, v, iso.set, mode);
        return std::make_pair(std::move(iso), std::move(c));
    });
    return nb::make_tuple(owned(isovalue_list(iso)), owned(picked(curve.components, iso.pick)));
}

FilterSpec filter_spec(const std::string& method, double sigma, double sigma_s, double sigma_r) {
    FilterSpec spec;
    if (method == "median") spec = FilterSpec::median();
    else if (method == "gaussian") spec = FilterSpec::gaussian(sigma);
    else if (method == "bilateral") spec = FilterSpec::bilateral(sigma_s, sigma_r);
    else throw InputError("method '" + method + "': expected 'median', 'gaussian' or 'bilateral'");
    spec.check();
    return spec;
}

nb::tuple filter_call(nb::handle a, const std::string& type, const std::string& method, double sigma,
                      double sigma_s, double sigma_r, const std::optional<std::string>& device) {
    const FilterSpec spec = filter_spec(method, sigma, sigma_s, sigma_r);
    const Input in = input_of(a, type);
    return volume_out(on_input(in, device, [&](Context& ctx) {
        return in.device() ? apply_filter(*in.device(), spec).download() : apply_filter(ctx, in.host(), spec);
    }));
}

/// The counts of a masked filter, as the package's TargetedFilterResult takes them.
nb::tuple targeted_out(TargetedResult&& r) {
    nb::dict info = make_dict({{"selected", nb::cast(r.selected)},
                               {"changed", nb::cast(r.changed)},
                               {"selected_share", nb::cast(r.selected_share)},
                               {"changed_share", nb::cast(r.changed_share)}});
    return nb::make_tuple(volume_out(std::move(r.volume)), info);
}

/// The fractal-targeted filter where the LD field (`mask` "ld", isovalue `iso`) or the LD4
/// field (`mask` "ld4", bin width `q`) exceeds `threshold`.
nb::tuple targeted_filter_call(const InArray& a, const std::string& type, const std::string& mask, double iso,
                               double q, double threshold, const std::string& method, int window, double sigma,
                               double sigma_s, double sigma_r, const std::optional<std::string>& device) {
    const FilterSpec spec = filter_spec(method, sigma, sigma_s, sigma_r);
    if (mask != "ld" && mask != "ld4") throw InputError("mask '" + mask + "': expected 'ld' or 'ld4'");
    Volume v = to_volume(a, type);
    return targeted_out(on_device(device, [&](Context& ctx) {
        if (mask == "ld") return targeted_filter(ctx, v, spec, iso, threshold, window);
        const Volume field = local_fractal_dimension_4d(ctx, v, q, window);
        return targeted_filter(ctx, v, spec, field, threshold);
    }));
}

nb::tuple ld_guided_call(const InArray& a, const std::string& type, double iso, double sigma_s, double sigma_r,
                         int window, const std::optional<std::string>& device) {
    filter_spec("bilateral", 1.0, sigma_s, sigma_r);  // the same checks of the sigmas
    Volume v = to_volume(a, type);
    return targeted_out(
        on_device(device, [&](Context& ctx) { return ld_bilateral_filter(ctx, v, sigma_s, sigma_r, iso, window); }));
}

nb::tuple local4_call(const InArray& a, const std::string& type, double q, int window,
                      const std::optional<std::string>& device) {
    Volume v = to_volume(a, type);
    return volume_out(on_device(device, [&](Context& ctx) { return local_fractal_dimension_4d(ctx, v, q, window); }));
}

nb::tuple smooth_call(nb::handle a, const std::string& type, double iso, double threshold, int window,
                      const std::string& variant, double tau, const std::optional<std::string>& device) {
    const SmoothVariant var = parse_smooth_variant(variant);
    const Input in = input_of(a, type);
    SmoothResult r = on_input(in, device, [&](Context& ctx) {
        return in.device() ? smooth_isosurface(*in.device(), iso, threshold, window, var, tau)
                           : smooth_isosurface(ctx, in.host(), iso, threshold, window, var, tau);
    });
    nb::dict info = make_dict({{"high_vertices", nb::cast(r.high_vertices)},
                               {"initial_edges", nb::cast(r.initial_edges)},
                               {"edges_processed", nb::cast(r.edges_processed)},
                               {"edges_lowered", nb::cast(r.edges_lowered)},
                               {"vertices_changed", nb::cast(r.vertices_changed)}});
    return nb::make_tuple(volume_out(std::move(r.volume)), info);
}

/// The small-components filter (host labelling, no device): the volume and its counts.
nb::tuple small_components_call(const InArray& a, const std::string& type, double iso, std::size_t k,
                                const std::string& connectivity) {
    const SmallComponentsConnectivity mode = parse_small_components_connectivity(connectivity);
    const Volume v = to_volume(a, type);
    SmallComponentsResult r;
    {
        nb::gil_scoped_release no_gil;
        r = small_components_filter(v, iso, k, mode);
    }
    nb::dict info = make_dict({{"isovalue", nb::cast(r.isovalue)},
                               {"positive_before", nb::cast(r.positive_before)},
                               {"negative_before", nb::cast(r.negative_before)},
                               {"positive_removed", nb::cast(r.positive_removed)},
                               {"negative_removed", nb::cast(r.negative_removed)},
                               {"positive_after", nb::cast(r.positive_after)},
                               {"negative_after", nb::cast(r.negative_after)},
                               {"changed", nb::cast(r.changed)},
                               {"changed_share", nb::cast(r.changed_share)}});
    return nb::make_tuple(volume_out(std::move(r.volume)), info);
}

/// Mesh vertices as (n, 3) float32 in (z, y, x) order and triangles as (m, 3) int32 with the
/// winding reversed, so that the right-hand normals still point towards lower values after
/// the axis swap (a reflection).
nb::tuple mesh_call(nb::handle a, const std::string& type, double iso, const std::string& method, bool color_by_ld,
                    int window, const std::vector<double>& spacing_zyx, const std::optional<std::string>& device) {
    const MeshMethod m = parse_mesh_method(method);
    if (spacing_zyx.size() != 3) throw InputError("spacing: expected 3 values (dz, dy, dx)");
    for (double s : spacing_zyx)
        if (!(std::isfinite(s) && s > 0)) throw InputError("spacing: values must be finite and > 0");
    Input in = input_of(a, type);
    const std::array<double, 3> spacing{spacing_zyx[2], spacing_zyx[1], spacing_zyx[0]};
    Mesh mesh;
    if (in.uploaded) {
        // Extracted from the device copy (no upload), with this spacing.
        mesh = on_input(in, device, [&](Context& ctx) {
            in.uploaded->on_device.spacing = spacing;
            Mesh m3 = extract_isosurface(*in.device(), iso, m);
            if (color_by_ld) clfractal::color_by_ld(m3, local_field(ctx, in, iso, window));
            return m3;
        });
    } else if (color_by_ld) {
        in.copy.spacing = spacing;
        Volume ld = on_device(device, [&](Context& ctx) { return local_field(ctx, in, iso, window); });
        nb::gil_scoped_release no_gil;
        mesh = extract_isosurface(in.copy, iso, m);
        clfractal::color_by_ld(mesh, ld);
    } else {
        in.copy.spacing = spacing;
        nb::gil_scoped_release no_gil;
        mesh = extract_isosurface(in.copy, iso, m);
    }
    std::vector<float> vertices;
    vertices.reserve(mesh.positions.size() * 3);
    for (auto& p : mesh.positions) vertices.insert(vertices.end(), {p[2], p[1], p[0]});
    std::vector<std::int32_t> faces;
    faces.reserve(mesh.triangles.size() * 3);
    for (auto& t : mesh.triangles)
        faces.insert(faces.end(), {std::int32_t(t[0]), std::int32_t(t[2]), std::int32_t(t[1])});
    nb::object ld = nb::none();
    if (color_by_ld) ld = nb::cast(owned(std::move(mesh.ld)));
    return nb::make_tuple(owned(std::move(vertices)), owned(std::move(faces)), ld);
}

/// The raw-read options of `clfractal` (--dims, --type, --endian, --spacing, --series,
/// --scaled, --as); dims and spacing in (x, y, z) order.
RawOptions raw_options(const std::optional<std::vector<std::size_t>>& dims, const std::optional<std::string>& type,
                       const std::string& endian, const std::optional<std::vector<double>>& spacing,
                       const std::string& series, bool scaled, const std::optional<std::string>& as) {
    RawOptions o;
    if (dims) {
        if (dims->size() != 3) throw InputError("dims: expected 3 values (nz, ny, nx)");
        o.dims = Dims{(*dims)[0], (*dims)[1], (*dims)[2]};
    }
    if (type) o.type = parse_value_type(*type);
    if (endian == "big") o.big_endian = true;
    else if (endian != "little") throw InputError("endian '" + endian + "': expected 'little' or 'big'");
    if (spacing) {
        if (spacing->size() != 3) throw InputError("spacing: expected 3 values (dz, dy, dx)");
        for (double x : *spacing)
            if (!(std::isfinite(x) && x > 0)) throw InputError("spacing: values must be finite and > 0");
        o.spacing = {(*spacing)[0], (*spacing)[1], (*spacing)[2]};
    }
    o.series = series;
    o.scaled = scaled;
    if (as) o.as = parse_value_type(*as);
    return o;
}

nb::tuple read_volume_call(const std::string& path, const RawOptions& raw) {
    Volume v;
    {
        nb::gil_scoped_release no_gil;
        v = read_volume(path, raw, FiniteCheck::keep);  // LD fields hold NaN; computing calls reject it
    }
    auto spacing = nb::make_tuple(v.spacing[2], v.spacing[1], v.spacing[0]);
    return nb::make_tuple(volume_out(std::move(v)), spacing);
}

/// The orientation of a volume as Python holds it: the LPS origin (L, P, S) of vertex
/// (0, 0, 0) and the LPS direction of each array axis, rows in (z, y, x) order.
nb::object orientation_out(const Volume& v) {
    if (!v.oriented) return nb::none();
    return nb::make_tuple(nb::make_tuple(v.origin[0], v.origin[1], v.origin[2]),
                          nb::make_tuple(nb::make_tuple(v.axes[2][0], v.axes[2][1], v.axes[2][2]),
                                         nb::make_tuple(v.axes[1][0], v.axes[1][1], v.axes[1][2]),
                                         nb::make_tuple(v.axes[0][0], v.axes[0][1], v.axes[0][2])));
}

/// Sets v's orientation from `origin` (3 values) and `axes` (9 values, rows z, y, x), each
/// axis normalised; every value finite and no axis zero.
void set_orientation(Volume& v, const std::vector<double>& origin, const std::vector<double>& axes_zyx) {
    if (origin.size() != 3 || axes_zyx.size() != 9)
        throw InputError("orientation: expected an origin of 3 values and 3 axes of 3 values");
    for (double x : origin)
        if (!std::isfinite(x)) throw InputError("orientation: the origin must be finite");
    for (int r = 0; r < 3; ++r) {
        const double* d = &axes_zyx[3 * std::size_t(r)];
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(std::isfinite(len) && len > 0))
            throw InputError("orientation: axis " + std::to_string(r) + " must be finite and not zero");
        for (int c = 0; c < 3; ++c) v.axes[2 - r][c] = d[c] / len;
    }
    v.origin = {origin[0], origin[1], origin[2]};
    v.oriented = true;
}

/// What `clfractal info` reports: the header facts, the grid and the value statistics.
nb::dict info_call(const std::string& path, const RawOptions& raw) {
    std::vector<std::string> header;
    Volume v;
    ValueStats stats;
    {
        nb::gil_scoped_release no_gil;
        header = describe_volume_file(path, raw);
        v = read_volume(path, raw, FiniteCheck::keep);
        stats = value_stats(v);
    }
    const Dims& d = v.dims();
    return make_dict({{"path", nb::cast(path)},
                      {"header", nb::cast(header)},
                      {"shape", nb::make_tuple(d.nz, d.ny, d.nx)},
                      {"dtype", nb::cast(std::string(value_type_name(v.type())))},
                      {"spacing", nb::make_tuple(v.spacing[2], v.spacing[1], v.spacing[0])},
                      {"min", nb::cast(stats.min)},
                      {"max", nb::cast(stats.max)},
                      {"nan", nb::cast(stats.nan)},
                      {"inf", nb::cast(stats.inf)},
                      {"orientation", orientation_out(v)}});
}

/// Writes a (z, y, x) array as NRRD or NIfTI (by the extension) with spacing (dz, dy, dx)
/// and, when given, the orientation (set_orientation).
void write_volume_call(const InArray& a, const std::string& type, const std::string& path,
                       const std::vector<double>& spacing_zyx, const std::optional<std::vector<double>>& origin,
                       const std::optional<std::vector<double>>& axes_zyx) {
    Volume v = to_volume(a, type, FiniteCheck::keep);
    if (spacing_zyx.size() != 3) throw InputError("spacing: expected 3 values (dz, dy, dx)");
    for (double x : spacing_zyx)
        if (!(std::isfinite(x) && x > 0)) throw InputError("spacing: values must be finite and > 0");
    v.spacing = {spacing_zyx[2], spacing_zyx[1], spacing_zyx[0]};
    if (origin && axes_zyx) set_orientation(v, *origin, *axes_zyx);
    v.name = path;
    nb::gil_scoped_release no_gil;
    write_volume(v, path);
}

/// Writes a mesh as mesh_call returns it ((n, 3) float32 in (z, y, x), (m, 3) triangles of
/// reversed winding, optional per-vertex LD coloured by the thesis map) as PLY.
void write_ply_call(const std::string& path,
                    const nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>& vertices,
                    const nb::ndarray<const std::int64_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>& faces,
                    const std::optional<nb::ndarray<const float, nb::ndim<1>, nb::c_contig, nb::device::cpu>>& ld) {
    if (vertices.shape(1) != 3 || faces.shape(1) != 3)
        throw InputError(path + ": vertices and faces must have 3 columns");
    const std::size_t n = vertices.shape(0), m = faces.shape(0);
    Mesh mesh;
    const float* p = vertices.data();
    for (std::size_t i = 0; i < n; ++i) mesh.positions.push_back({p[3 * i + 2], p[3 * i + 1], p[3 * i]});
    const std::int64_t* t = faces.data();
    for (std::size_t i = 0; i < 3 * m; ++i)
        if (t[i] < 0 || std::size_t(t[i]) >= n)
            throw InputError(path + ": face " + std::to_string(i / 3) + " names vertex " + std::to_string(t[i]) +
                             " of " + std::to_string(n));
    for (std::size_t i = 0; i < m; ++i)
        mesh.triangles.push_back({std::uint32_t(t[3 * i]), std::uint32_t(t[3 * i + 2]), std::uint32_t(t[3 * i + 1])});
    if (ld) {
        if (ld->shape(0) != n) throw InputError(path + ": ld must have one value per vertex");
        mesh.ld.assign(ld->data(), ld->data() + n);
        for (float x : mesh.ld) {
            const Rgb c = ld_colour(x);
            mesh.colors.push_back({c.r, c.g, c.b});
        }
    }
    nb::gil_scoped_release no_gil;
    write_ply(mesh, path);
}

nb::list devices_call() {
    nb::list out;
    for (auto& e : list_devices())
        out.append(make_dict({{"platform", nb::cast(e.platform)},
                              {"name", nb::cast(e.name)},
                              {"type", nb::cast(e.type)},
                              {"global_mem", nb::cast(e.global_mem)},
                              {"max_alloc", nb::cast(e.max_alloc)},
                              {"compute_units", nb::cast(e.compute_units)},
                              {"default", nb::cast(e.chosen)}}));
    return out;
}

// The slice streams' classes (clfractal.SliceStream, clfractal.ComponentsStream).
void bind_streams(nb::module_& m) {
    nb::class_<SliceStream>(m, "SliceStream", "A slice stream; see clfractal.SliceStream.")
        .def(nb::init<std::size_t, std::size_t, const std::string&, const std::vector<double>&, int, const std::string&,
                      const std::optional<std::string>&>(),
             "ny"_a, "nx"_a, "type"_a, "isovalues"_a, "levels"_a, "kind"_a, "device"_a.none())
        .def("push", &SliceStream::push, "slices"_a)
        .def("curve", &SliceStream::curve)
        .def_prop_ro("slices", [](const SliceStream& s) { return s.stream->slices(); });
    nb::class_<ComponentsStream>(m, "ComponentsStream", "A components stream; see clfractal.ComponentsStream.")
        .def(nb::init<std::size_t, std::size_t, const std::string&, const std::vector<double>&, const std::string&>(),
             "ny"_a, "nx"_a, "type"_a, "isovalues"_a, "connectivity"_a)
        .def("push", &ComponentsStream::push, "slices"_a)
        .def("counts", &ComponentsStream::counts)
        .def_prop_ro("slices", [](const ComponentsStream& s) { return s.stream->slices(); });
}

}  // namespace

NB_MODULE(_clfractal, m) {
    m.doc() = "clfractal's C++ library; use the clfractal package, which documents every call.";
    m.attr("__version__") = clfractal::version();
    // CLBlast's cached programs are released at interpreter exit, while the OpenCL runtime
    // is still whole (its own exit handlers run after the interpreter has finalised).
    nb::module_::import_("atexit").attr("register")(nb::cpp_function([] { release_blas_caches(); }));
    // Bad input (clfractal::InputError) -> ValueError; device failures -> RuntimeError.
    nb::register_exception_translator([](const std::exception_ptr& p, void*) {
        try {
            std::rethrow_exception(p);
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const DeviceError& e) {
            std::string what = e.what();
            if (e.code() == CL_DEVICE_NOT_FOUND && what.find("no OpenCL platform") != std::string::npos) {
                what +=
                    "; for a CPU device: pip install 'clfractal[cpu]' (PoCL from PyPI); for a GPU: its "
                    "vendor's OpenCL driver";
                // Where the package looked, and why it left a driver out (clfractal.OPENCL_DRIVERS).
                const nb::object package = nb::module_::import_("sys").attr("modules").attr("get")("clfractal");
                if (!package.is_none() && nb::hasattr(package, "OPENCL_DRIVERS"))
                    what += "; drivers: " + nb::cast<std::string>(nb::str(package.attr("OPENCL_DRIVERS")));
            }
            PyErr_SetString(PyExc_RuntimeError, what.c_str());
        } catch (const cl::Error& e) {
            PyErr_Format(PyExc_RuntimeError, "%s: %s (%d)", e.what(), cl_error_name(e.err()), e.err());
        }
    });
    nb::class_<Uploaded>(m, "Uploaded", "A volume uploaded once; see clfractal.DeviceVolume.")
        .def(nb::init<const InArray&, const std::string&, const std::optional<std::string>&>(), "volume"_a, "type"_a,
             "device"_a.none())
        .def_prop_ro("zero_copy", [](const Uploaded& u) { return u.on_device.in_host_memory(); });
    bind_streams(m);
    m.def("uploads", [](const std::optional<std::string>& device) {
        return on_device(device, [](Context& ctx) { return ctx.uploads(); });
    }, "device"_a = nb::none(), "Volumes uploaded to the device so far (DeviceVolume counts one).");
    m.def("devices", &devices_call);
    m.def("device_description", [](const std::optional<std::string>& device) {
        return on_device(device, [](Context& ctx) { return ctx.description(); });
    }, "device"_a = nb::none());
    m.def("host_copies", [] { return host_copies.load(); },
          "Arrays copied into the library's volumes so far (C-contiguous ones are read in place).");
    m.def("context_count", [] {
        std::lock_guard<std::mutex> guard(registry_lock);
        return context_locks.size();
    }, "The number of OpenCL contexts this process has created (one per device used).");
    m.def("fd_curve", &fd_curve_call, "volume"_a, "type"_a, "kind"_a, "levels"_a, "isovalues"_a.none(), "bins"_a,
          "min_count"_a, "device"_a.none());
    m.def("local_fd", &local_fd_call, "volume"_a, "type"_a, "iso"_a, "window"_a, "device"_a.none());
    m.def("fd4", &fd4_call, "volume"_a, "type"_a, "q"_a, "device"_a.none());
    m.def("analyse", &analyse_call, "volume"_a, "type"_a, "clean_fd"_a, "noisy_fd"_a, "clean_share"_a, "bins"_a,
          "components"_a, "noise_level"_a, "fd4"_a, "denoise"_a, "window"_a, "device"_a.none());
    m.def("report_file", &report_file_call, "out"_a, "json_out"_a, "path"_a, "raw"_a, "clean_fd"_a, "clean_share"_a,
          "window"_a, "bins"_a, "mesh_triangles"_a, "static_page"_a, "progress"_a, "device"_a.none());
    m.def("report_array", &report_array_call, "out"_a, "json_out"_a, "volume"_a, "type"_a, "name"_a, "spacing"_a,
          "clean_fd"_a, "clean_share"_a, "window"_a, "bins"_a, "mesh_triangles"_a, "static_page"_a, "progress"_a,
          "device"_a.none());
    m.def("noise_level", &noise_level_call, "volume"_a, "type"_a, "block"_a, "map_block"_a, "clip"_a, "device"_a.none());
    m.def("components", &components_call, "volume"_a, "type"_a, "connectivity"_a, "isovalues"_a.none(), "bins"_a,
          "device"_a.none());
    m.def("filter", &filter_call, "volume"_a, "type"_a, "method"_a, "sigma"_a, "sigma_s"_a, "sigma_r"_a,
          "device"_a.none());
    m.def("targeted_filter", &targeted_filter_call, "volume"_a, "type"_a, "mask"_a, "iso"_a, "q"_a, "threshold"_a,
          "method"_a, "window"_a, "sigma"_a, "sigma_s"_a, "sigma_r"_a, "device"_a.none());
    m.def("ld_guided_filter", &ld_guided_call, "volume"_a, "type"_a, "iso"_a, "sigma_s"_a, "sigma_r"_a, "window"_a,
          "device"_a.none());
    m.def("local4", &local4_call, "volume"_a, "type"_a, "q"_a, "window"_a, "device"_a.none());
    m.def("smooth", &smooth_call, "volume"_a, "type"_a, "iso"_a, "threshold"_a, "window"_a, "variant"_a, "tau"_a,
          "device"_a.none());
    m.def("small_components", &small_components_call, "volume"_a, "type"_a, "iso"_a, "k"_a, "connectivity"_a);
    m.def("mesh", &mesh_call, "volume"_a, "type"_a, "iso"_a, "method"_a, "color_by_ld"_a, "window"_a, "spacing"_a,
          "device"_a.none());
    m.def("noise_dimension", [](double r, const std::string& kind) {
        if (!(r >= 0) || !std::isfinite(r)) throw InputError("noise_dimension: r must be finite and >= 0");
        const NoiseKind k = parse_noise_kind(kind);
        return k == NoiseKind::uniform ? expected_edge_dimension(r) : expected_edge_dimension(r, k);
    }, "r"_a, "kind"_a);
    nb::class_<RawOptions>(m, "RawOptions");
    m.def("raw_options", &raw_options, "dims"_a.none(), "type"_a.none(), "endian"_a, "spacing"_a.none(), "series"_a,
          "scaled"_a, "as_type"_a.none());
    m.def("read_volume", &read_volume_call, "path"_a, "raw"_a);
    m.def("info", &info_call, "path"_a, "raw"_a);
    m.def("write_volume", &write_volume_call, "volume"_a, "type"_a, "path"_a, "spacing"_a, "origin"_a.none(),
          "axes"_a.none());
    m.def("write_ply", &write_ply_call, "path"_a, "vertices"_a, "faces"_a, "ld"_a.none());
}
