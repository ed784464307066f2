// The noise model, reproducible noise injection and the noise experiment (noise.hpp).
#include "clfractal/noise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "clfractal/fd.hpp"
#include "clfractal/span.hpp"
#include "clfractal/synthetic.hpp"

#include "kernels/counter_rng.h"
#include "device/slab_plan.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "device/name_table.hpp"

namespace clfractal {

namespace {

using detail::gaussian_draw;
using detail::pi;
using detail::splitmix64_mix;
using detail::uniform_draw;

// Draw `counter` of the stream of a scrambled seed (as uniform_noise in synthetic.cpp).
constexpr auto noise_bits = detail::counter_bits;

void check_amplitude(double a) {
    if (!(a >= 0) || !std::isfinite(a))
        throw InputError("noise amplitude " + std::to_string(a) + ": must be a finite number >= 0");
}

// Composite Simpson's rule with n (even) intervals.
template <class F> double simpson(const F& f, double a, double b, int n) {
    if (!(b > a)) return 0;
    const double h = (b - a) / n;
    double s = f(a) + f(b);
    for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
    return s * h / 3;
}

// Integral of f over [a, b], split at the points of `cuts` that fall inside (kinks of f).
template <class F> double simpson_pieces(const F& f, double a, double b, std::vector<double> cuts, int n) {
    cuts.push_back(a);
    cuts.push_back(b);
    std::sort(cuts.begin(), cuts.end());
    double sum = 0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double lo = std::max(a, cuts[i]), hi = std::min(b, cuts[i + 1]);
        if (hi > lo) sum += simpson(f, lo, hi, n);
    }
    return sum;
}

// Rounds half away from zero and clamps to T's range (in the type N of the noisy value);
// float types take the value as it is (float32 output of a double: rounded to nearest).
template <class T, class N> T to_type(N v) {
    if constexpr (std::is_floating_point_v<T>) {
        return T(v);
    } else {
        const N lo = N(std::numeric_limits<T>::min()), hi = N(std::numeric_limits<T>::max());
        return T(std::clamp(std::round(v), lo, hi));
    }
}

}  // namespace

// ------------------------------------------------------------------ Theorem 1 and lemmas

double lemma1_probability(double s_a, double s_b, double sigma, double mu) {
    if (!(mu > 0)) throw std::invalid_argument("lemma1_probability: mu must be > 0");
    // P(s + n < sigma) for n uniform on [-mu, mu].
    const auto below = [&](double s) { return std::clamp((sigma - s + mu) / (2 * mu), 0.0, 1.0); };
    const double pa = below(s_a), pb = below(s_b);
    return pa * (1 - pb) + (1 - pa) * pb;
}

double lemma2_probability(double delta, double mu, double lambda) {
    if (!(delta >= 0) || !(mu >= 0) || !(lambda >= mu + delta))
        throw std::invalid_argument("lemma2_probability: needs delta, mu >= 0 and Lambda >= mu + delta");
    if (delta >= 2 * mu) return delta / (2 * lambda);
    return (8 * mu * mu * mu - delta * delta * delta) / (24 * mu * mu * lambda) + delta * delta / (4 * mu * lambda);
}

double lemma3_probability(double gamma, double mu, double lambda) {
    if (!(gamma > 0) || !(mu >= 0) || !(lambda >= mu + gamma))
        throw std::invalid_argument("lemma3_probability: needs gamma > 0, mu >= 0 and Lambda >= mu + gamma");
    if (gamma <= 2 * mu)
        return (32 * mu * mu * mu + 8 * mu * gamma * gamma - gamma * gamma * gamma) / (96 * mu * mu * lambda);
    return (3 * gamma * gamma + 2 * mu * mu) / (12 * gamma * lambda);
}

double expected_edge_dimension(double r) {
    if (!(r >= 0)) throw std::invalid_argument("expected_edge_dimension: r must be >= 0");
    if (std::isinf(r)) return 3;
    const double r2 = r * r, r3 = r2 * r;
    if (r >= 1) return std::log2((32 * r3 + 8 * r - 1) / (4 * r3 + 4 * r - 1));
    if (r >= 0.5) return std::log2((32 * r3 + 8 * r - 1) / (r2 * r2 + 6 * r2));
    return std::log2(8 * (2 * r2 + 3) / (r2 + 6));
}

// ------------------------------------------------------------------ beyond the thesis

template <> struct detail::NameTable<NoiseKind> {
    static constexpr const char* what = "--noise";
    static constexpr std::pair<NoiseKind, const char*> names[] = {{NoiseKind::uniform, "uniform"},
                                                                  {NoiseKind::gaussian, "gaussian"}};
};
CLFRACTAL_NAME_TABLE(NoiseKind)

const char* noise_kind_name(NoiseKind k) { return variant_name(k); }

NoiseKind parse_noise_kind(const std::string& name) { return parse_variant<NoiseKind>(name); }

double edge_span_measure(double delta, NoiseKind kind, double amplitude) {
    check_amplitude(amplitude);
    if (amplitude == 0) return std::abs(delta);
    if (kind == NoiseKind::uniform) {
        // n_b - n_a: triangular density (2 mu - |w|) / (4 mu^2) on [-2 mu, 2 mu]. The integrand
        // is quadratic between the kinks -delta, 0, so Simpson is exact there.
        const double mu = amplitude;
        const auto f = [&](double w) { return std::abs(delta + w) * (2 * mu - std::abs(w)) / (4 * mu * mu); };
        return simpson_pieces(f, -2 * mu, 2 * mu, {-delta, 0.0}, 2);
    }
    const double tau = amplitude * std::sqrt(2.0);
    const auto f = [&](double w) {
        const double t = w / tau;
        return std::abs(delta + w) * std::exp(-0.5 * t * t) / (tau * std::sqrt(2 * pi));
    };
    return simpson_pieces(f, -10 * tau, 10 * tau, {-delta}, 400);
}

double expected_edge_dimension(double r, NoiseKind kind) {
    check_amplitude(r);
    // A(g) = (1/g) int_0^g E|delta + n_b - n_a| d delta; for uniform noise the integrand has
    // a kink (second derivative) at delta = 2 mu.
    const auto average = [&](double g) {
        const auto h = [&](double delta) { return edge_span_measure(delta, kind, r); };
        return simpson_pieces(h, 0, g, {2 * r}, 200) / g;
    };
    return std::log2(8 * average(1.0) / average(2.0));
}

double expected_box_dimension(double r, NoiseKind kind, std::size_t samples, std::uint64_t seed) {
    check_amplitude(r);
    if (samples == 0) throw std::invalid_argument("expected_box_dimension: samples must be > 0");
    const std::uint64_t mixed = splitmix64_mix(seed);
    // Each sample uses 2 draws for the direction and 16 for the noise of the 8 corners
    // (uniform uses the first 8). Fixed chunks summed in order: the result does not depend
    // on the number of threads.
    const auto unit = [&](std::uint64_t c) { return double(noise_bits(mixed, c) >> 11) * 0x1p-53; };  // [0, 1)
    const std::size_t chunk = 4096, chunks = (samples + chunk - 1) / chunk;
    std::vector<double> sum1(chunks), sum2(chunks);
#pragma omp parallel for schedule(static)
    for (long long k = 0; k < (long long)chunks; ++k) {
        double s1 = 0, s2 = 0;
        const std::size_t end = std::min(samples, std::size_t(k + 1) * chunk);
        for (std::size_t s = std::size_t(k) * chunk; s < end; ++s) {
            const std::uint64_t c = std::uint64_t(s) * 18;
            const double z = 2 * unit(c) - 1, phi = 2 * pi * unit(c + 1), q = std::sqrt(std::max(0.0, 1 - z * z));
            const double g[3] = {q * std::cos(phi), q * std::sin(phi), z};
            double noise[8];
            for (int v = 0; v < 8; ++v) {
                if (kind == NoiseKind::uniform) {
                    noise[v] = r * (2 * unit(c + 2 + v) - 1);
                } else {
                    const double u1 = 1 - unit(c + 2 + 2 * v), u2 = unit(c + 3 + 2 * v);
                    noise[v] = r * std::sqrt(-2 * std::log(u1)) * std::cos(2 * pi * u2);
                }
            }
            double lo1 = 1e300, hi1 = -1e300, lo2 = 1e300, hi2 = -1e300;
            for (int v = 0; v < 8; ++v) {
                const double lin = (v & 1 ? g[0] : 0) + (v & 2 ? g[1] : 0) + (v & 4 ? g[2] : 0);
                const double a = lin + noise[v], b = 2 * lin + noise[v];
                lo1 = std::min(lo1, a), hi1 = std::max(hi1, a), lo2 = std::min(lo2, b), hi2 = std::max(hi2, b);
            }
            s1 += hi1 - lo1;
            s2 += hi2 - lo2;
        }
        sum1[k] = s1;
        sum2[k] = s2;
    }
    double r1 = 0, r2 = 0;
    for (std::size_t k = 0; k < chunks; ++k) r1 += sum1[k], r2 += sum2[k];
    return std::log2(8 * r1 / r2);
}

// ------------------------------------------------------------------ reproducible noise

float uniform_noise_f32(std::uint64_t seed, std::uint64_t index) { return uniform_draw(splitmix64_mix(seed), index); }

float gaussian_noise_f32(std::uint64_t seed, std::uint64_t index) { return gaussian_draw(splitmix64_mix(seed), index); }

Volume add_noise_host(const Volume& v, const NoiseOptions& opt) {
    check_amplitude(opt.amplitude);
    const ValueType out_type = opt.keep_type ? v.type() : ValueType::float32;
    Volume out(v.dims(), out_type, v.name);
    out.spacing = v.spacing;
    const std::uint64_t mixed = splitmix64_mix(opt.seed);
    const float amplitude = float(opt.amplitude);
    const bool wide = is_wide(v.type());
    visit(v, [&](const auto* in) {
        visit(out, [&](auto* dst) {
            using O = std::remove_pointer_t<decltype(dst)>;
#pragma omp parallel for schedule(static)
            for (long long i = 0; i < (long long)v.vertices(); ++i) {
                const float draw = opt.kind == NoiseKind::uniform ? uniform_draw(mixed, std::uint64_t(i))
                                                                  : gaussian_draw(mixed, std::uint64_t(i));
                // Two separately rounded operations, as the kernel (volatile keeps the
                // compiler from fusing them into a multiply-add).
                volatile float product = amplitude * draw;
                if (wide) dst[i] = to_type<O>(double(in[i]) + double(product));
                else dst[i] = to_type<O>(float(float(in[i]) + product));
            }
        });
    });
    return out;
}

namespace {

// The -D options of the noise kernel for data of type t.
std::string noise_options(ValueType t, const NoiseOptions& opt) {
    std::string options = type_options(t);
    if (opt.kind == NoiseKind::gaussian) options += " -DGAUSSIAN";
    const bool wide = is_wide(t);
    if (wide) options += " -DNOISE_DOUBLE -DFP64";
    if (opt.keep_type) options += " " + defines({{"OUT_T", opencl_type_name(t)}});
    if (opt.keep_type && is_integer(t)) {
        // The range as literals of the noisy value's type (every integer type's bounds are exact).
        const auto literal = [&](double x) {
            char buf[40];
            std::snprintf(buf, sizeof buf, wide ? "%.1f" : "%.1ff", x);
            return std::string(buf);
        };
        options += " -DKEEP_TYPE " + defines({{"OUT_MIN", literal(type_min(t))}, {"OUT_MAX", literal(type_max(t))}});
    }
    return options;
}

// The noisy values of `in` into `out` (same dims), whose first vertex is vertex `first` of
// the volume.
void noise_on_device(const DeviceVolume& in, const DeviceVolume& out, std::size_t first, const NoiseOptions& opt) {
    Context& ctx = in.context();
    // kernels/noise.cl add_noise(in, out, first, mixed_seed, amplitude).
    KernelCall<cl::Buffer, cl::Buffer, cl_ulong, cl_ulong, cl_float> kernel(ctx, "noise", "add_noise",
                                                                           noise_options(in.type(), opt));
    kernel(cl::NDRange(in.vertices()), cl::NullRange, in.buffer(), out.buffer(), cl_ulong(first),
           cl_ulong(splitmix64_mix(opt.seed)), cl_float(float(opt.amplitude)));
}

ValueType noisy_type(ValueType t, const NoiseOptions& opt) { return opt.keep_type ? t : ValueType::float32; }

}  // namespace

Volume add_noise(Context& ctx, const Volume& v, const NoiseOptions& opt) {
    check_amplitude(opt.amplitude);
    const ValueType out_type = noisy_type(v.type(), opt);
    Volume out(v.dims(), out_type, v.name);
    out.spacing = v.spacing;
    const Dims d = v.dims();
    const std::size_t slice = d.nx * d.ny;
    const std::size_t in_bytes = value_size(v.type()), out_bytes = value_size(out_type);
    // Slabs of at most 256 MiB per buffer: the input and the noisy output.
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = slice * in_bytes;
    need.slice_bytes = slice * (in_bytes + out_bytes);
    need.largest_slice_bytes = slice * std::max(in_bytes, out_bytes);
    need.largest_bytes = std::size_t(256) << 20;
    need.memory_divisor = 1;
    need.forced = opt.slab_slices;
    const auto* src = static_cast<const unsigned char*>(v.data());
    auto* dst = static_cast<unsigned char*>(out.data());
    // Each vertex's noise depends on its index alone, so any slab depth gives the same values.
    with_smaller_slabs(plan_slab(ctx, need, d), [&](std::size_t slab) {
        with_cl_errors([&] {
            for (std::size_t z0 = 0; z0 < d.nz; z0 += slab) {
                const Dims sd{d.nx, d.ny, std::min(slab, d.nz - z0)};
                const DeviceVolume in(ctx, src + z0 * slice * in_bytes, sd, v.type());
                const DeviceVolume res = DeviceVolume::output(ctx, dst + z0 * slice * out_bytes, sd, out_type);
                noise_on_device(in, res, z0 * slice, opt);
                res.download(dst + z0 * slice * out_bytes);
            }
        });
    });
    return out;
}

DeviceVolume add_noise(const DeviceVolume& v, const NoiseOptions& opt) {
    check_amplitude(opt.amplitude);
    DeviceVolume out = allocate_like(v, noisy_type(v.type(), opt));
    with_cl_errors([&] { noise_on_device(v, out, 0, opt); });
    return out;
}

// ------------------------------------------------------------------ the experiment

Volume noise_experiment_volume(const std::string& shape, std::size_t n, int points, std::uint64_t seed) {
    SyntheticOptions opt;
    opt.size = n;
    opt.points = points;
    opt.seed = seed;
    if (shape == "points") return make_synthetic("points", opt);
    if (shape == "circle") return make_synthetic("torus", opt);
    throw InputError("--shape " + shape + ": must be points or circle");
}

std::vector<float> default_noise_isovalues(const std::string& shape, std::size_t n) {
    // Away from the kink of the distance field at the points (or the circle), by more than
    // the largest default noise (4) plus the gradient, and below the distances where most
    // spheres (tubes) have merged or left the grid; scaled with N from the N = 128 values.
    const double scale = double(n) / 128.0;
    const std::vector<double> base = shape == "circle" ? std::vector<double>{8, 10, 12, 14, 16}
                                                       : std::vector<double>{10, 12, 14, 16, 18, 20};
    std::vector<float> iso;
    for (double b : base) {
        const float s = float(b * scale);
        if (iso.empty() || s > iso.back()) iso.push_back(s);
    }
    return iso;
}

namespace {

// Calls f(a, b) with the span [a, b] of every grid edge (all three axes), as doubles.
template <class F> void for_each_edge(const Volume& v, const F& f) {
    const Dims d = v.dims();
    visit(v, [&](const auto* p) {
        const std::size_t step[3] = {1, d.nx, d.nx * d.ny};
        for (std::size_t z = 0; z < d.nz; ++z)
            for (std::size_t y = 0; y < d.ny; ++y)
                for (std::size_t x = 0; x < d.nx; ++x) {
                    const std::size_t i = x + d.nx * (y + d.ny * z);
                    const bool inside[3] = {x + 1 < d.nx, y + 1 < d.ny, z + 1 < d.nz};
                    for (int axis = 0; axis < 3; ++axis) {
                        if (!inside[axis]) continue;
                        const double f0 = double(p[i]), f1 = double(p[i + step[axis]]);
                        f(std::min(f0, f1), std::max(f0, f1));
                    }
                }
    });
}

}  // namespace

double estimate_gamma(const Volume& v, double iso) {
    // The comparison of docs/definitions.md §3 (integers: a < s <= b iff a < ceil(s) <= b).
    const double s = IsovalueSet::single(v.type(), iso).value(0);
    std::vector<double> spans;
    for_each_edge(v, [&](double a, double b) {
        if (a < s && s <= b) spans.push_back(b - a);
    });
    if (spans.empty()) throw InputError("--iso " + std::to_string(iso) + ": no edge of " + v.name + " is intersected");
    const std::size_t mid = spans.size() / 2;
    std::nth_element(spans.begin(), spans.begin() + mid, spans.end());
    double gamma = std::sqrt(2.0) * spans[mid];
    for (int it = 0; it < 50 && gamma > 0; ++it) {
        double sum = 0;
        std::size_t n = 0;
        for_each_edge(v, [&](double a, double b) {
            if (std::abs(a - iso) <= gamma) sum += b - a, ++n;
        });
        const double next = n ? 2 * sum / double(n) : 0;
        const bool done = std::abs(next - gamma) <= 1e-3 * gamma;
        gamma = next;
        if (done) break;
    }
    if (!(gamma > 0)) throw InputError("--iso " + std::to_string(iso) + ": the values of " + v.name + " near it are flat; give --gamma");
    return gamma;
}

std::vector<NoisePoint> noise_experiment(Context& ctx, const Volume& clean, const std::vector<float>& isovalues,
                                         const std::vector<double>& amplitudes, NoiseKind kind, double gamma,
                                         std::uint64_t seed, std::size_t box_samples,
                                         const std::function<void(const std::string&)>& progress) {
    if (!(gamma > 0) || !std::isfinite(gamma)) throw InputError("--gamma: must be a finite number > 0");
    std::vector<float> sorted = isovalues;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    const IsovalueSet iso = IsovalueSet::floats(sorted);
    std::vector<NoisePoint> result;
    for (double a : amplitudes) {
        check_amplitude(a);
        NoisePoint p;
        p.amplitude = a;
        p.r = a / gamma;
        NoiseOptions no;
        no.kind = kind;
        no.amplitude = a;
        no.seed = seed;
        const Volume noisy = add_noise(ctx, clean, no);
        SpanOptions so;
        so.kinds = {SpanKind::edges, SpanKind::cubes};
        const SpanResult spans = count_spans(ctx, noisy, iso, so);
        const FdCurve edges = fd_curve(ctx, spans, SpanKind::edges), cubes = fd_curve(ctx, spans, SpanKind::cubes);
        p.edge_fd = edges.fd;
        p.box_fd = cubes.fd;
        const auto mean = [](const std::vector<double>& v) {
            double s = 0;
            std::size_t n = 0;
            for (double x : v)
                if (!std::isnan(x)) s += x, ++n;
            return n ? s / double(n) : std::numeric_limits<double>::quiet_NaN();
        };
        p.measured_edge_fd = mean(p.edge_fd);
        p.measured_box_fd = mean(p.box_fd);
        p.formula = kind == NoiseKind::uniform ? expected_edge_dimension(p.r) : expected_edge_dimension(p.r, kind);
        p.model_box = expected_box_dimension(p.r, kind, box_samples);
        if (progress) progress(std::string(noise_kind_name(kind)) + " noise " + std::to_string(a) + ": edge FD " +
                               std::to_string(p.measured_edge_fd) + ", formula " + std::to_string(p.formula));
        result.push_back(std::move(p));
    }
    return result;
}

}  // namespace clfractal
