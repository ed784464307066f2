#include "reference/local_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/span_reference.hpp"

namespace ref {

template <class C> std::vector<C> summed_area_table(const std::vector<C>& values, const Dims& d) {
    std::vector<C> sat(values.size());
    // sat at a coordinate of -1 is 0.
    auto at = [&](long x, long y, long z) -> C {
        if (x < 0 || y < 0 || z < 0) return 0;
        return sat[std::size_t(x) + d.nx * (std::size_t(y) + d.ny * std::size_t(z))];
    };
    for (long z = 0; z < long(d.nz); ++z)
        for (long y = 0; y < long(d.ny); ++y)
            for (long x = 0; x < long(d.nx); ++x) {
                const std::size_t i = std::size_t(x) + d.nx * (std::size_t(y) + d.ny * std::size_t(z));
                sat[i] = values[i] + at(x - 1, y, z) + at(x, y - 1, z) + at(x, y, z - 1) - at(x - 1, y - 1, z) -
                         at(x, y - 1, z - 1) - at(x - 1, y, z - 1) + at(x - 1, y - 1, z - 1);
            }
    return sat;
}

template <class C> std::vector<C> summed_area_table_direct(const std::vector<C>& values, const Dims& d) {
    std::vector<C> sat(values.size());
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) {
                C s = 0;
                for (std::size_t k = 0; k <= z; ++k)
                    for (std::size_t j = 0; j <= y; ++j)
                        for (std::size_t i = 0; i <= x; ++i) s += values[i + d.nx * (j + d.ny * k)];
                sat[x + d.nx * (y + d.ny * z)] = s;
            }
    return sat;
}

template std::vector<std::uint32_t> summed_area_table(const std::vector<std::uint32_t>&, const Dims&);
template std::vector<std::uint64_t> summed_area_table(const std::vector<std::uint64_t>&, const Dims&);
template std::vector<std::uint32_t> summed_area_table_direct(const std::vector<std::uint32_t>&, const Dims&);
template std::vector<std::uint64_t> summed_area_table_direct(const std::vector<std::uint64_t>&, const Dims&);

std::vector<std::uint8_t> cube_indicator(const Volume& v, double iso) {
    const double s = clfractal::is_integer(v.type()) ? iso : double(float(iso));
    const Dims d = v.dims();
    const Dims c{d.nx - 1, d.ny - 1, d.nz - 1};
    if (d.cubes() == 0) return {};
    std::vector<std::uint8_t> in(c.vertices());
    for (std::size_t z = 0; z < c.nz; ++z)
        for (std::size_t y = 0; y < c.ny; ++y)
            for (std::size_t x = 0; x < c.nx; ++x) {
                double a = v.value(v.index(x, y, z)), b = a;
                for (int k = 0; k < 8; ++k) {
                    double f = v.value(v.index(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2)));
                    a = std::min(a, f);
                    b = std::max(b, f);
                }
                in[x + c.nx * (y + c.ny * z)] = a < s && s <= b;
            }
    return in;
}

// Revision 2: W' first, then W covers exactly W''s region of G (vertex 2u of G is vertex u
// of G', so G' cube u spans G cubes 2u and 2u + 1).
Range window_sub(long x, long m, int k) {
    const long c0 = long(std::floor(double(x - k / 2) / 2.0));
    return {std::max(0L, c0), std::min(m - 1, c0 + k / 2)};
}

Range window(long x, long n, int k) {
    const Range w = window_sub(x, (n - 1) / 2 + 1, k);
    return {2 * w.lo, 2 * w.hi};
}

namespace {

double log_ratio(std::uint64_t a, std::uint64_t b) {
    return a && b ? std::log2(double(a) / double(b)) : std::numeric_limits<double>::quiet_NaN();
}

// Calls f(vertex index, W ranges, W' ranges) for every vertex of v.
template <class F> void for_each_window(const Volume& v, int k, F f) {
    const Dims d = v.dims();
    const Dims m{(d.nx - 1) / 2 + 1, (d.ny - 1) / 2 + 1, (d.nz - 1) / 2 + 1};
    for (long z = 0; z < long(d.nz); ++z)
        for (long y = 0; y < long(d.ny); ++y)
            for (long x = 0; x < long(d.nx); ++x) {
                const Range w[3] = {window(x, long(d.nx), k), window(y, long(d.ny), k), window(z, long(d.nz), k)};
                const Range ws[3] = {window_sub(x, long(m.nx), k), window_sub(y, long(m.ny), k),
                                     window_sub(z, long(m.nz), k)};
                f(v.index(std::size_t(x), std::size_t(y), std::size_t(z)), w, ws);
            }
}

}  // namespace

std::vector<double> local_dimension_brute(const Volume& v, double iso, int k) {
    const Volume sub = level(v, 1);
    const std::vector<std::uint8_t> in = cube_indicator(v, iso), in_sub = cube_indicator(sub, iso);
    const Dims c{v.dims().nx - 1, v.dims().ny - 1, v.dims().nz - 1};
    const Dims cs{sub.dims().nx - 1, sub.dims().ny - 1, sub.dims().nz - 1};
    // Cubes of the box [r[0]) x [r[1]) x [r[2]) that are intersected, one by one.
    auto count = [](const std::vector<std::uint8_t>& ind, const Dims& cd, const Range* r) {
        std::uint64_t n = 0;
        for (long z = r[2].lo; z < r[2].hi; ++z)
            for (long y = r[1].lo; y < r[1].hi; ++y)
                for (long x = r[0].lo; x < r[0].hi; ++x) n += ind[std::size_t(x) + cd.nx * (std::size_t(y) + cd.ny * std::size_t(z))];
        return n;
    };
    std::vector<double> ld(v.vertices());
    for_each_window(v, k, [&](std::size_t i, const Range* w, const Range* ws) {
        ld[i] = log_ratio(count(in, c, w), count(in_sub, cs, ws));
    });
    return ld;
}

std::vector<double> local_dimension_sat(const Volume& v, double iso, int k) {
    const Volume sub = level(v, 1);
    auto table = [&](const Volume& g) {
        const std::vector<std::uint8_t> in = cube_indicator(g, iso);
        const Dims c{g.dims().nx - 1, g.dims().ny - 1, g.dims().nz - 1};
        return summed_area_table(std::vector<std::uint64_t>(in.begin(), in.end()), c);
    };
    const std::vector<std::uint64_t> S = table(v), Ssub = table(sub);
    const Dims c{v.dims().nx - 1, v.dims().ny - 1, v.dims().nz - 1};
    const Dims cs{sub.dims().nx - 1, sub.dims().ny - 1, sub.dims().nz - 1};
    // Sum over the box from the inclusive table: sat(hi - 1) minus the slabs below lo.
    auto count = [](const std::vector<std::uint64_t>& sat, const Dims& cd, const Range* r) -> std::uint64_t {
        if (r[0].lo >= r[0].hi || r[1].lo >= r[1].hi || r[2].lo >= r[2].hi) return 0;
        auto at = [&](long x, long y, long z) -> std::int64_t {
            if (x < 0 || y < 0 || z < 0) return 0;
            return std::int64_t(sat[std::size_t(x) + cd.nx * (std::size_t(y) + cd.ny * std::size_t(z))]);
        };
        const long x0 = r[0].lo - 1, x1 = r[0].hi - 1, y0 = r[1].lo - 1, y1 = r[1].hi - 1, z0 = r[2].lo - 1,
                   z1 = r[2].hi - 1;
        return std::uint64_t(at(x1, y1, z1) - at(x0, y1, z1) - at(x1, y0, z1) - at(x1, y1, z0) + at(x0, y0, z1) +
                             at(x0, y1, z0) + at(x1, y0, z0) - at(x0, y0, z0));
    };
    std::vector<double> ld(v.vertices());
    for_each_window(v, k, [&](std::size_t i, const Range* w, const Range* ws) {
        ld[i] = log_ratio(count(S, c, w), count(Ssub, cs, ws));
    });
    return ld;
}

}  // namespace ref
