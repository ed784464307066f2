#include "reference/fd4_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/local_reference.hpp"

namespace ref {

using clfractal::Dims;
using clfractal::Volume;

namespace {

// G': the vertices with even coordinates.
Volume half(const Volume& v) {
    const Dims d = v.dims();
    const Dims s{(d.nx - 1) / 2 + 1, (d.ny - 1) / 2 + 1, (d.nz - 1) / 2 + 1};
    Volume out(s, v.type());
    clfractal::visit(out, [&](auto* dst) {
        using T = std::remove_pointer_t<decltype(dst)>;
        const T* src = v.as<T>();
        for (std::size_t z = 0; z < s.nz; ++z)
            for (std::size_t y = 0; y < s.ny; ++y)
                for (std::size_t x = 0; x < s.nx; ++x) dst[out.index(x, y, z)] = src[v.index(2 * x, 2 * y, 2 * z)];
    });
    return out;
}

double min_value(const Volume& v) {
    double m = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < v.vertices(); ++i) m = std::min(m, v.value(i));
    return m;
}

}  // namespace

std::vector<std::uint64_t> cube_bins(const Volume& v, double vmin, double q) {
    const Dims d = v.dims();
    std::vector<std::uint64_t> bins;
    if (d.cubes() == 0) return bins;
    for (std::size_t z = 0; z + 1 < d.nz; ++z)
        for (std::size_t y = 0; y + 1 < d.ny; ++y)
            for (std::size_t x = 0; x + 1 < d.nx; ++x) {
                double a = std::numeric_limits<double>::infinity(), b = -a;
                for (int c = 0; c < 8; ++c) {
                    const double f = v.value(v.index(x + (c & 1), y + (c >> 1 & 1), z + (c >> 2)));
                    a = std::min(a, f);
                    b = std::max(b, f);
                }
                bins.push_back(std::uint64_t(std::floor((b - vmin) / q) - std::floor((a - vmin) / q) + 1));
            }
    return bins;
}

Fd4 fd4(const Volume& v, double q) {
    const double vmin = min_value(v);
    Fd4 r;
    for (std::uint64_t b : cube_bins(v, vmin, q)) r.i4 += b;
    for (std::uint64_t b : cube_bins(half(v), vmin, 2 * q)) r.i4_sub += b;
    r.d4 = r.i4 && r.i4_sub ? std::log2(double(r.i4) / double(r.i4_sub)) : std::numeric_limits<double>::quiet_NaN();
    return r;
}

double default_q(const Volume& v) {
    if (clfractal::is_integer(v.type())) return 1;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < v.vertices(); ++i) {
        lo = std::min(lo, v.value(i));
        hi = std::max(hi, v.value(i));
    }
    return hi > lo ? (hi - lo) / 256 : 1;
}

std::vector<double> local_dimension_4d_brute(const Volume& v, double q, int k) {
    const Volume sub = half(v);
    const double vmin = min_value(v);
    const std::vector<std::uint64_t> bins = cube_bins(v, vmin, q), bins_sub = cube_bins(sub, vmin, 2 * q);
    const Dims d = v.dims(), m = sub.dims();
    const auto sum = [](const std::vector<std::uint64_t>& b, const Dims& g, Range x, Range y, Range z) {
        std::uint64_t s = 0;
        for (long c = z.lo; c < z.hi; ++c)
            for (long b2 = y.lo; b2 < y.hi; ++b2)
                for (long a = x.lo; a < x.hi; ++a) s += b[std::size_t(a + long(g.nx - 1) * (b2 + long(g.ny - 1) * c))];
        return s;
    };
    std::vector<double> out(v.vertices());
    for (long z = 0; z < long(d.nz); ++z)
        for (long y = 0; y < long(d.ny); ++y)
            for (long x = 0; x < long(d.nx); ++x) {
                const std::uint64_t w = sum(bins, d, window(x, long(d.nx), k), window(y, long(d.ny), k),
                                            window(z, long(d.nz), k));
                const std::uint64_t ws = sum(bins_sub, m, window_sub(x, long(m.nx), k), window_sub(y, long(m.ny), k),
                                             window_sub(z, long(m.nz), k));
                out[v.index(std::size_t(x), std::size_t(y), std::size_t(z))] =
                    ws ? std::log2(double(w) / double(ws)) : std::numeric_limits<double>::quiet_NaN();
            }
    return out;
}

}  // namespace ref
