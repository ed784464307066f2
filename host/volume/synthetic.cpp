// Synthetic volumes and the counter-based uniform noise shared with the device kernels
// (docs/definitions.md §22 "Noise injection and synthetic volumes").
#include "clfractal/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "kernels/counter_rng.h"

namespace clfractal {
namespace {

using detail::pi;
using detail::splitmix64_mix;

/// Rounds to nearest and clamps to the integer types' range; float32 is a plain cast.
template <class T> T convert(double value) {
    if constexpr (std::is_floating_point_v<T>) {
        return static_cast<T>(value);
    } else {
        const double lo = std::numeric_limits<T>::min();
        const double hi = std::numeric_limits<T>::max();
        return static_cast<T>(std::clamp(std::round(value), lo, hi));
    }
}

/// An N^3 volume of `type` with values field(x, y, z) + amplitude(x) * uniform_noise(seed, i),
/// i the linear vertex index, converted with convert<T>.
template <class Field, class Amplitude>
Volume generate(const std::string& name, std::size_t n, ValueType type, std::uint64_t seed,
                const Field& field, const Amplitude& amplitude) {
    Volume v({n, n, n}, type, "synthetic:" + name + ":" + std::to_string(n));
    visit(v, [&](auto* out) {
        using T = std::remove_pointer_t<decltype(out)>;
        const std::ptrdiff_t sn = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for collapse(2) schedule(static)
        for (std::ptrdiff_t z = 0; z < sn; ++z) {
            for (std::ptrdiff_t y = 0; y < sn; ++y) {
                std::size_t i = (static_cast<std::size_t>(z) * n + static_cast<std::size_t>(y)) * n;
                for (std::size_t x = 0; x < n; ++x, ++i) {
                    double f = field(x, static_cast<std::size_t>(y), static_cast<std::size_t>(z));
                    const double a = amplitude(x);
                    if (a != 0) f += a * uniform_noise(seed, i);
                    out[i] = convert<T>(f);
                }
            }
        }
    });
    return v;
}

/// The same for shape `name` of `opt` (size, seed, value type, `type` when opt has none).
template <class Field, class Amplitude>
Volume generate(const std::string& name, const SyntheticOptions& opt, ValueType type, const Field& field,
                const Amplitude& amplitude) {
    return generate(name, opt.size, opt.type.value_or(type), opt.seed, field, amplitude);
}

/// The same with noise of amplitude opt.noise everywhere.
template <class Field>
Volume generate(const std::string& name, const SyntheticOptions& opt, ValueType type, const Field& field) {
    const double mu = opt.noise;
    return generate(name, opt, type, field, [mu](std::size_t) { return mu; });
}

/// The centre of an n^3 grid on every axis.
double centre(std::size_t n) { return (n - 1) / 2.0; }

}  // namespace

// bits = mix(mix(seed) + (index + 1) * 0x9E3779B97F4A7C15)       (uint64 arithmetic, mod 2^64)
// mix(z): z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9; z = (z ^ (z >> 27)) * 0x94D049BB133111EB;
//         return z ^ (z >> 31)                                       (splitmix64's finalizer)
// result = ((int64)(bits >> 11) - 2^52) * 2^-52                      (exact in double, in [-1, 1))
// mix(seed) scrambles the seed so that nearby seeds give unrelated streams; kernels may
// compute it once on the host. The integer form lets devices without fp64 reproduce it.
double uniform_noise(std::uint64_t seed, std::uint64_t index) {
    const std::uint64_t bits = detail::counter_bits(splitmix64_mix(seed), index);
    const std::int64_t k = static_cast<std::int64_t>(bits >> 11) - (std::int64_t(1) << 52);
    return static_cast<double>(k) * 0x1p-52;
}

std::vector<SyntheticInfo> synthetic_catalog() {
    return {
        {"sphere", "uint8 255*(1 - d/(N/2)) clamped to [0,255], d the distance to the centre; "
                   "isosurfaces are spheres"},
        {"noisy-sphere", "the sphere plus uniform noise whose amplitude grows from 0 at x=0 to "
                         "mu at x=N-1 (mu = --noise, default 8); uint8"},
        {"torus", "float32 distance to a circle of radius N/4 around the centre in the plane "
                  "z = (N-1)/2; isosurfaces are tori"},
        {"points", "float32 distance to the nearest of P random points (gradient 1)"},
        {"marschner-lobb", "float32 Marschner-Lobb test function on [-1,1]^3 (fM = 6, "
                           "alpha = 0.25)"},
    };
}

namespace {

/// Rejects an unknown name and out-of-range options, in that order.
void check_synthetic(const std::string& name, const SyntheticOptions& opt) {
    const std::string what = "synthetic:" + name;
    const std::vector<SyntheticInfo> catalog = synthetic_catalog();
    if (std::none_of(catalog.begin(), catalog.end(),
                     [&](const SyntheticInfo& s) { return s.name == name; })) {
        std::string valid;
        for (const SyntheticInfo& s : catalog) valid += (valid.empty() ? "" : ", ") + s.name;
        throw InputError(what + ": unknown synthetic volume (valid: " + valid + ")");
    }
    const std::size_t n = opt.size;
    if (n < 2) throw InputError(what + ": size " + std::to_string(n) + " must be at least 2");
    if (!(opt.noise >= 0) || !std::isfinite(opt.noise))
        throw InputError(what + ": noise amplitude must be a finite number >= 0");
    if (opt.points < 1) throw InputError(what + ": number of points must be at least 1");
}

/// "sphere" and "noisy-sphere".
Volume make_sphere(const std::string& name, const SyntheticOptions& opt) {
    const std::size_t n = opt.size;
    const double c = centre(n), mu = opt.noise;
    const double radius = n / 2.0;
    const auto sphere = [c, radius](std::size_t x, std::size_t y, std::size_t z) {
        const double dx = x - c, dy = y - c, dz = z - c;
        const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
        return 255.0 * std::clamp(1.0 - d / radius, 0.0, 1.0);
    };
    if (name == "sphere") return generate(name, opt, ValueType::uint8, sphere);
    // Noise on one side only, so that local-dimension maps show a clean and a noisy half.
    const double max_amplitude = mu > 0 ? mu : 8.0;
    const auto growing_noise = [max_amplitude, n](std::size_t x) {
        return max_amplitude * static_cast<double>(x) / static_cast<double>(n - 1);
    };
    return generate(name, opt, ValueType::uint8, sphere, growing_noise);
}

/// "torus".
Volume make_torus(const std::string& name, const SyntheticOptions& opt) {
    const std::size_t n = opt.size;
    const double c = centre(n);
    const double ring = n / 4.0;
    const auto torus = [c, ring](std::size_t x, std::size_t y, std::size_t z) {
        const double dx = x - c, dy = y - c, dz = z - c;
        const double q = std::sqrt(dx * dx + dy * dy) - ring;
        return std::sqrt(q * q + dz * dz);
    };
    return generate(name, opt, ValueType::float32, torus);
}

/// "points".
Volume make_points(const std::string& name, const SyntheticOptions& opt) {
    const double c = centre(opt.size);
    // Positions use the same seed but counters from the top of the range, which vertex
    // indices never reach, so they are independent of the noise added to the vertices.
    std::vector<double> pos(3 * static_cast<std::size_t>(opt.points));
    for (std::size_t k = 0; k < pos.size(); ++k)
        pos[k] = c + c * uniform_noise(opt.seed, ~std::uint64_t(k));
    const auto points = [&pos](std::size_t x, std::size_t y, std::size_t z) {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < pos.size(); k += 3) {
            const double dx = x - pos[k], dy = y - pos[k + 1], dz = z - pos[k + 2];
            best = std::min(best, dx * dx + dy * dy + dz * dz);
        }
        return std::sqrt(best);
    };
    return generate(name, opt, ValueType::float32, points);
}

/// "marschner-lobb".
Volume make_marschner_lobb(const std::string& name, const SyntheticOptions& opt) {
    const std::size_t n = opt.size;
    // f = (1 - sin(pi z/2) + alpha (1 + rho(r))) / (2 (1 + alpha)),
    // rho(r) = cos(2 pi fM cos(pi r / 2)), r = sqrt(x^2 + y^2), coordinates in [-1, 1].
    // The xy and z terms are tabulated once: per vertex only a few additions remain.
    const double fm = 6.0, alpha = 0.25;
    const auto coord = [n](std::size_t i) { return -1.0 + 2.0 * i / static_cast<double>(n - 1); };
    std::vector<double> xy_term(n * n), z_term(n);
    for (std::size_t y = 0; y < n; ++y)
        for (std::size_t x = 0; x < n; ++x) {
            const double r = std::hypot(coord(x), coord(y));
            xy_term[y * n + x] = alpha * (1.0 + std::cos(2.0 * pi * fm * std::cos(pi * r / 2.0)));
        }
    for (std::size_t z = 0; z < n; ++z) z_term[z] = 1.0 - std::sin(pi * coord(z) / 2.0);
    const double scale = 1.0 / (2.0 * (1.0 + alpha));
    const auto marschner_lobb = [&, n](std::size_t x, std::size_t y, std::size_t z) {
        return (z_term[z] + xy_term[y * n + x]) * scale;
    };
    return generate(name, opt, ValueType::float32, marschner_lobb);
}

}  // namespace

Volume make_synthetic(const std::string& name, const SyntheticOptions& opt) {
    check_synthetic(name, opt);
    if (name == "sphere" || name == "noisy-sphere") return make_sphere(name, opt);
    if (name == "torus") return make_torus(name, opt);
    if (name == "points") return make_points(name, opt);
    return make_marschner_lobb(name, opt);  // the only name left
}

}  // namespace clfractal
