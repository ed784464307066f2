// The C ABI (include/clfractal/clfractal.h) over the C++ library: opaque handles, status
// codes and a thread-local last-error message; no exception leaves this file.
#include "clfractal/clfractal.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>
#include <new>
#include <string>

#include "clfractal/analysis.hpp"
#include "clfractal/components.hpp"
#include "clfractal/version.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/local.hpp"
#include "clfractal/small_components.hpp"
#include "clfractal/span.hpp"
#include "clfractal/stream.hpp"
#include "clfractal/volume_io.hpp"

using namespace clfractal;

struct clf_context {
    std::unique_ptr<Context> ctx;
    std::string description;
};

struct clf_volume {
    Volume volume;
};

struct clf_curve {
    FdCurve curve;
};

struct clf_analysis {
    Analysis analysis;
    std::string json;
};

struct clf_stream {
    std::unique_ptr<SpanStream> stream;
};

struct clf_components_stream {
    std::unique_ptr<ComponentsAtStream> stream;
    std::size_t isovalues = 0;
};

namespace {

thread_local std::string last_error;

clf_status fail(clf_status status, const std::string& message) {
    last_error = message;
    return status;
}

/// For getters: clears the last error and returns `value`, or records why `fallback` is
/// returned.
template <class T> T got(bool ok, T value, T fallback, const char* why) {
    if (ok) {
        last_error.clear();
        return value;
    }
    last_error = why;
    return fallback;
}

// Runs f, turning every exception into a status and the last-error message.
template <class F>
clf_status guarded(F&& f) {
    try {
        f();
        last_error.clear();
        return CLF_OK;
    } catch (const HostOutOfMemory& e) {
        return fail(CLF_ERROR_OUT_OF_MEMORY, e.what());
    } catch (const InputError& e) {
        return fail(CLF_ERROR_INPUT, printable(e.what()));
    } catch (const DeviceError& e) {
        return fail(e.out_of_memory() ? CLF_ERROR_OUT_OF_MEMORY : CLF_ERROR_DEVICE, e.what());
    } catch (const std::bad_alloc&) {
        return fail(CLF_ERROR_OUT_OF_MEMORY, "out of host memory");
    } catch (const std::exception& e) {
        return fail(CLF_ERROR_INTERNAL, e.what());
    } catch (...) {
        return fail(CLF_ERROR_INTERNAL, "unknown error");
    }
}

// clf_type's values are the ValueType enumerators' (the order of the type table).
static_assert(int(CLF_UINT8) == int(ValueType::uint8) && int(CLF_UINT16) == int(ValueType::uint16) &&
              int(CLF_INT16) == int(ValueType::int16) && int(CLF_FLOAT32) == int(ValueType::float32) &&
              int(CLF_INT8) == int(ValueType::int8) && int(CLF_INT32) == int(ValueType::int32) &&
              int(CLF_UINT32) == int(ValueType::uint32) && int(CLF_FLOAT64) == int(ValueType::float64) &&
              std::size(all_value_types) == 8, "clf_type and ValueType disagree");

// Types and kinds arrive as int and are compared as int: converting an int outside an
// enum's values to the enum would be undefined.
ValueType to_value_type(int t, const char* call) {
    if (t < 0 || std::size_t(t) >= std::size(all_value_types))
        throw InputError(std::string(call) + ": unknown clf_type " + std::to_string(t));
    return all_value_types[std::size_t(t)];
}

SpanKind to_span_kind(int kind, const char* call) {
    if (kind == int(CLF_BOX)) return SpanKind::cubes;
    if (kind == int(CLF_EDGE)) return SpanKind::edges;
    throw InputError(std::string(call) + ": kind " + std::to_string(kind) + " must be CLF_BOX or CLF_EDGE");
}

void require(bool ok, const char* what) {
    if (!ok) throw InputError(what);
}

// An explicit isovalue list of the C ABI (float values) in the list type of `t`.
IsovalueSet list_isovalues(ValueType t, const float* values, std::size_t count) {
    require(!is_integer(t) || is_wide(t), "isovalues: 8/16-bit integer data uses every integer of its value range");
    require(values != nullptr || count == 0, "isovalues: NULL list");
    if (t == ValueType::float32) return IsovalueSet::floats(std::vector<float>(values, values + count));
    return IsovalueSet::doubles(std::vector<double>(values, values + count));
}

}  // namespace

extern "C" {

const char* clf_version(void) { return clfractal::version(); }

const char* clf_last_error(void) { return last_error.c_str(); }

clf_status clf_context_create(const char* device_filter, clf_context** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_context_create: out is NULL");
    *out = nullptr;
    return guarded([&] {
        const bool by_filter = device_filter && *device_filter;
        const cl::Device device = by_filter ? select_device({device_filter, ""}).device : choose_device();
        auto c = std::make_unique<clf_context>();
        c->ctx = std::make_unique<Context>(device);
        c->description = c->ctx->description();
        *out = c.release();
    });
}

void clf_context_destroy(clf_context* ctx) {
    clfractal::release_blas_caches();  // CLBlast's programs, shared by every context
    delete ctx;
    last_error.clear();
}

const char* clf_context_description(const clf_context* ctx) {
    return got<const char*>(ctx != nullptr, ctx ? ctx->description.c_str() : "", "", "clf_context_description: context is NULL");
}

clf_status clf_volume_read(const char* path, clf_volume** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_volume_read: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(path != nullptr, "clf_volume_read: path is NULL");
        auto v = std::make_unique<clf_volume>();
        v->volume = read_volume(path);
        *out = v.release();
    });
}

clf_status clf_volume_create(const void* data, size_t nx, size_t ny, size_t nz, int type, clf_volume** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_volume_create: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(data != nullptr, "clf_volume_create: data is NULL");
        auto v = std::make_unique<clf_volume>();
        v->volume = Volume(Dims{nx, ny, nz}, to_value_type(type, "clf_volume_create"), "clf_volume_create");
        std::memcpy(v->volume.data(), data, v->volume.size_bytes());
        check_finite(v->volume, "clf_volume_create");
        *out = v.release();
    });
}

void clf_volume_destroy(clf_volume* volume) {
    delete volume;
    last_error.clear();
}

void clf_volume_dims(const clf_volume* volume, size_t dims[3]) {
    if (!got(volume && dims, true, false, "clf_volume_dims: volume or dims is NULL")) return;
    dims[0] = volume->volume.dims().nx;
    dims[1] = volume->volume.dims().ny;
    dims[2] = volume->volume.dims().nz;
}

clf_type clf_volume_type(const clf_volume* volume) {
    if (!got(volume != nullptr, true, false, "clf_volume_type: volume is NULL")) return CLF_TYPE_NONE;
    return clf_type(int(volume->volume.type()));
}

void clf_curve_options_default(clf_curve_options* options) {
    if (!got(options != nullptr, true, false, "clf_curve_options_default: options is NULL")) return;
    *options = clf_curve_options{};
    options->kind = CLF_BOX;
    options->levels = 2;
}

clf_status clf_curve_compute(clf_context* ctx, const clf_volume* volume, const clf_curve_options* options,
                             clf_curve** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_curve_compute: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(ctx && volume, "clf_curve_compute: context or volume is NULL");
        clf_curve_options o;
        clf_curve_options_default(&o);
        if (options) o = *options;
        const SpanKind kind = to_span_kind(o.kind, "clf_curve_compute");
        if (o.levels < 2 || o.levels > 16) throw InputError("levels " + std::to_string(o.levels) + ": must be 2..16");
        const Volume& v = volume->volume;
        SpanOptions opt{{kind}, o.levels, 0};
        SpanResult spans;
        if (o.isovalues) {
            spans = count_spans(*ctx->ctx, v, list_isovalues(v.type(), o.isovalues, o.isovalue_count), opt);
        } else {
            require(o.bins == 0 || !is_integer(v.type()) || is_wide(v.type()),
                    "bins: 8/16-bit integer data uses every integer of its value range");
            spans = count_spans(*ctx->ctx, v, opt, o.bins ? o.bins : 256);  // the set comes with the counts
        }
        auto c = std::make_unique<clf_curve>();
        c->curve = fd_curve(*ctx->ctx, spans, kind);
        *out = c.release();
    });
}

void clf_curve_destroy(clf_curve* curve) {
    delete curve;
    last_error.clear();
}

size_t clf_curve_size(const clf_curve* curve) {
    return got<size_t>(curve != nullptr, curve ? curve->curve.fd.size() : 0, 0, "clf_curve_size: curve is NULL");
}

int clf_curve_levels(const clf_curve* curve) {
    return got(curve != nullptr, curve ? curve->curve.levels() : 0, 0, "clf_curve_levels: curve is NULL");
}

namespace {
constexpr double no_value = std::numeric_limits<double>::quiet_NaN();
bool valid_index(const clf_curve* curve, size_t j) { return curve && j < curve->curve.fd.size(); }
constexpr const char* bad_index = "curve is NULL or index out of range";
}  // namespace

double clf_curve_isovalue(const clf_curve* curve, size_t j) {
    const bool ok = valid_index(curve, j);
    return got(ok, ok ? curve->curve.isovalues.value(j) : no_value, no_value, bad_index);
}

double clf_curve_dimension(const clf_curve* curve, size_t j) {
    const bool ok = valid_index(curve, j);
    return got(ok, ok ? curve->curve.fd[j] : no_value, no_value, bad_index);
}

double clf_curve_dimension_fit(const clf_curve* curve, size_t j) {
    const bool ok = valid_index(curve, j);
    return got(ok, ok ? (curve->curve.levels() > 2 ? curve->curve.fd_fit[j] : curve->curve.fd[j]) : no_value, no_value,
               bad_index);
}

uint64_t clf_curve_count(const clf_curve* curve, int level, size_t j) {
    const bool ok = valid_index(curve, j) && level >= 0 && level < curve->curve.levels();
    return got<uint64_t>(ok, ok ? curve->curve.counts[std::size_t(level)][j] : 0, 0,
                         "clf_curve_count: curve is NULL or level or index out of range");
}

void clf_curve_summary(const clf_curve* curve, uint64_t min_count, clf_summary* out) {
    if (!got(curve && out, true, false, "clf_curve_summary: curve or out is NULL")) return;
    const FdSummary s = summarize(curve->curve.fd, curve->curve.counts[0], curve->curve.counts[1], min_count);
    out->defined = s.defined;
    out->mean = s.mean;
    out->std = s.std;
    out->weighted_mean = s.weighted_mean;
    out->kappa = s.kappa;
}

clf_status clf_stream_create(clf_context* ctx, size_t nx, size_t ny, int type, const clf_curve_options* options,
                             const double* range, clf_stream** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_stream_create: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(ctx != nullptr, "clf_stream_create: context is NULL");
        clf_curve_options o;
        clf_curve_options_default(&o);
        if (options) o = *options;
        if (o.levels < 2 || o.levels > 16) throw InputError("levels " + std::to_string(o.levels) + ": must be 2..16");
        const ValueType t = to_value_type(type, "clf_stream_create");
        check_dims(Dims{nx, ny, 1}, "clf_stream_create");
        if (range && !(std::isfinite(range[0]) && std::isfinite(range[1]) && range[0] <= range[1]))
            throw InputError("clf_stream_create: range must be finite with min <= max");
        IsovalueSet iso;
        if (o.isovalues) {
            iso = list_isovalues(t, o.isovalues, o.isovalue_count);
        } else if (is_integer(t)) {
            require(o.bins == 0 || is_wide(t), "bins: 8/16-bit integer data uses every integer of its range");
            const double lo = std::ceil(range ? std::max(range[0], type_min(t)) : type_min(t));
            const double hi = std::floor(range ? std::min(range[1], type_max(t)) : type_max(t));
            require(lo <= hi, "clf_stream_create: the range holds no value of the type");
            iso = IsovalueSet::for_range(t, lo, hi, o.bins ? o.bins : 256);
        } else {
            require(range != nullptr, "clf_stream_create: float data needs a value range or an isovalue list");
            iso = IsovalueSet::uniform(range[0], range[1], o.bins ? o.bins : 256, t);
        }
        auto st = std::make_unique<clf_stream>();
        st->stream = std::make_unique<SpanStream>(*ctx->ctx, nx, ny, t, iso, o.levels);
        *out = st.release();
    });
}

void clf_stream_destroy(clf_stream* stream) {
    delete stream;
    last_error.clear();
}

clf_status clf_stream_push_slice(clf_stream* stream, const void* slice) {
    return guarded([&] {
        require(stream && slice, "clf_stream_push_slice: stream or slice is NULL");
        stream->stream->push_slice(slice);
    });
}

size_t clf_stream_slices(const clf_stream* stream) {
    return got<size_t>(stream != nullptr, stream ? stream->stream->slices() : 0, 0, "clf_stream_slices: stream is NULL");
}

clf_status clf_stream_curve(const clf_stream* stream, int kind, clf_curve** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_stream_curve: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(stream != nullptr, "clf_stream_curve: stream is NULL");
        const SpanKind k = to_span_kind(kind, "clf_stream_curve");
        auto c = std::make_unique<clf_curve>();
        c->curve = stream->stream->curve(k);
        *out = c.release();
    });
}

clf_status clf_components_stream_create(size_t nx, size_t ny, int type, const double* isovalues, size_t count,
                                        int connectivity, clf_components_stream** out) {
    if (!out) return fail(CLF_ERROR_INPUT, "clf_components_stream_create: out is NULL");
    *out = nullptr;
    return guarded([&] {
        require(isovalues != nullptr || count == 0, "clf_components_stream_create: isovalues is NULL");
        require(connectivity == CLF_COMPONENTS_CUBE || connectivity == CLF_COMPONENTS_FREUDENTHAL,
                "clf_components_stream_create: connectivity must be CLF_COMPONENTS_CUBE or CLF_COMPONENTS_FREUDENTHAL");
        const ValueType t = to_value_type(type, "clf_components_stream_create");
        check_dims(Dims{nx, ny, 1}, "clf_components_stream_create");
        auto st = std::make_unique<clf_components_stream>();
        st->stream = std::make_unique<ComponentsAtStream>(
            nx, ny, t, std::vector<double>(isovalues, isovalues + count),
            connectivity == CLF_COMPONENTS_CUBE ? Connectivity::cube : Connectivity::freudenthal);
        st->isovalues = count;
        *out = st.release();
    });
}

void clf_components_stream_destroy(clf_components_stream* stream) {
    delete stream;
    last_error.clear();
}

clf_status clf_components_stream_push(clf_components_stream* stream, const void* slices, size_t count) {
    return guarded([&] {
        require(stream && (slices || count == 0), "clf_components_stream_push: stream or slices is NULL");
        stream->stream->push_slices(slices, count);
    });
}

size_t clf_components_stream_slices(const clf_components_stream* stream) {
    return got<size_t>(stream != nullptr, stream ? stream->stream->slices() : 0, 0,
                       "clf_components_stream_slices: stream is NULL");
}

clf_status clf_components_stream_counts(const clf_components_stream* stream, int64_t* out) {
    return guarded([&] {
        require(stream && (out || stream->isovalues == 0), "clf_components_stream_counts: stream or out is NULL");
        const std::vector<std::int64_t> c = stream->stream->counts();
        std::copy(c.begin(), c.end(), out);
    });
}

clf_status clf_local_dimension(clf_context* ctx, const clf_volume* volume, double iso, int window, float* out) {
    return guarded([&] {
        require(ctx && volume && out, "clf_local_dimension: context, volume or out is NULL");
        Volume ld = local_fractal_dimension(*ctx->ctx, volume->volume, iso, window);
        std::memcpy(out, ld.data(), ld.size_bytes());
    });
}

clf_status clf_fd4_compute(clf_context* ctx, const clf_volume* volume, double q, clf_fd4* out) {
    return guarded([&] {
        require(ctx && volume && out, "clf_fd4_compute: context, volume or out is NULL");
        require(std::isfinite(q) && q >= 0, "clf_fd4_compute: q must be 0 (the default) or a finite number > 0");
        const Fd4Result r = fractal_dimension_4d(*ctx->ctx, volume->volume, q);
        *out = clf_fd4{r.q, r.vmin, r.i4, r.i4_sub, r.d4};
    });
}

void clf_analysis_options_default(clf_analysis_options* options) {
    if (!options) return;
    const AnalysisOptions o;
    *options = clf_analysis_options{o.advice.clean_fd, o.advice.noisy_fd, o.advice.clean_share, o.bins, 1, 1, 0, 1,
                                    o.window};
}

clf_status clf_analyse(clf_context* ctx, const clf_volume* volume, const clf_analysis_options* options,
                       clf_analysis** out) {
    return guarded([&] {
        require(ctx && volume && out, "clf_analyse: context, volume or out is NULL");
        *out = nullptr;
        clf_analysis_options c;
        clf_analysis_options_default(&c);
        if (options) c = *options;
        require(c.components >= 0 && c.components <= 2, "clf_analyse: components must be 0, 1 or 2");
        require(c.bins > 0, "clf_analyse: bins must be > 0");
        AnalysisOptions o;
        o.advice.clean_fd = c.clean_fd;
        o.advice.noisy_fd = c.noisy_fd;
        o.advice.clean_share = c.clean_share;
        o.bins = c.bins;
        o.components = c.components == 0 ? ComponentsScope::none
                       : c.components == 1 ? ComponentsScope::recommended
                                           : ComponentsScope::curve;
        o.noise_level = o.surface_noise = c.noise_level != 0;
        o.fd4 = c.fd4 != 0;
        o.denoise = c.denoise != 0;
        require(window_problem(c.window).empty(), "clf_analyse: window must be even and >= 2");
        o.window = c.window;
        auto a = std::make_unique<clf_analysis>();
        a->analysis = analyse(*ctx->ctx, volume->volume, o);
        a->json = to_json(a->analysis);
        *out = a.release();
    });
}

void clf_analysis_destroy(clf_analysis* analysis) {
    delete analysis;
    last_error.clear();
}

size_t clf_analysis_recommended(const clf_analysis* analysis) {
    return got<size_t>(analysis != nullptr, analysis ? analysis->analysis.recommended.size() : 0, 0,
                       "clf_analysis_recommended: analysis is NULL");
}

clf_status clf_analysis_recommendation(const clf_analysis* analysis, size_t i, clf_recommendation* out) {
    return guarded([&] {
        require(analysis && out, "clf_analysis_recommendation: analysis or out is NULL");
        const Analysis& a = analysis->analysis;
        require(i < a.recommended.size(), "clf_analysis_recommendation: index out of range");
        const Recommendation& e = a.recommended[i];
        *out = clf_recommendation{e.isovalue, e.fd, e.count, e.count_sub, e.components, int(e.verdict),
                                  a.isovalues.value(e.first), a.isovalues.value(e.last)};
    });
}

int clf_analysis_clean(const clf_analysis* analysis) {
    return got(analysis != nullptr, analysis && analysis->analysis.clean ? 1 : 0, 0, "clf_analysis_clean: analysis is NULL");
}

double clf_analysis_noise_sigma(const clf_analysis* analysis) {
    const double sigma = analysis && analysis->analysis.noise_level ? analysis->analysis.noise_level->sigma : NAN;
    return got(analysis != nullptr, sigma, double(NAN), "clf_analysis_noise_sigma: analysis is NULL");
}

clf_status clf_analysis_noise_level(const clf_analysis* analysis, clf_noise_level* out) {
    return guarded([&] {
        require(analysis && out, "clf_analysis_noise_level: analysis or out is NULL");
        require(analysis->analysis.noise_level.has_value(), "clf_analysis_noise_level: the analysis has no noise level");
        const NoiseLevel& l = *analysis->analysis.noise_level;
        *out = clf_noise_level{l.sigma,
                               l.sigma_white,
                               {l.correlation[0], l.correlation[1], l.correlation[2]},
                               {l.spread[0], l.spread[1], l.spread[2]},
                               l.flat_share};
    });
}

const char* clf_analysis_json(const clf_analysis* analysis) {
    return got<const char*>(analysis != nullptr, analysis ? analysis->json.c_str() : nullptr, nullptr,
                            "clf_analysis_json: analysis is NULL");
}

clf_status clf_small_components_filter(const clf_volume* volume, double iso, uint64_t k, int connectivity, void* out,
                                       clf_small_components* stats) {
    return guarded([&] {
        require(volume && out, "clf_small_components_filter: volume or out is NULL");
        if (connectivity != int(CLF_SMALL_CUBE) && connectivity != int(CLF_SMALL_SIX))
            throw InputError("clf_small_components_filter: connectivity " + std::to_string(connectivity) +
                             " must be CLF_SMALL_CUBE or CLF_SMALL_SIX");
        const SmallComponentsResult r =
            small_components_filter(volume->volume, iso, std::size_t(k),
                                    connectivity == int(CLF_SMALL_CUBE) ? SmallComponentsConnectivity::cube
                                                                        : SmallComponentsConnectivity::six);
        std::memcpy(out, r.volume.data(), r.volume.size_bytes());
        if (stats)
            *stats = clf_small_components{r.isovalue,        r.positive_before, r.negative_before,
                                          r.positive_removed, r.negative_removed, r.positive_after,
                                          r.negative_after,   r.changed,          r.changed_share};
    });
}

}  // extern "C"
