#include "reference/span_reference.hpp"

#include <algorithm>

namespace ref {

namespace {

std::vector<double> isovalues(const IsovalueSet& iso) {
    std::vector<double> s(iso.size());
    for (std::size_t j = 0; j < s.size(); ++j) s[j] = iso.value(j);
    return s;
}

// Calls f(a, b) with the span of every cube.
template <class F> void for_each_cube(const Volume& v, F f) {
    const auto d = v.dims();
    for (std::size_t z = 0; z + 1 < d.nz; ++z)
        for (std::size_t y = 0; y + 1 < d.ny; ++y)
            for (std::size_t x = 0; x + 1 < d.nx; ++x) {
                double a = v.value(v.index(x, y, z)), b = a;
                for (int c = 0; c < 8; ++c) {
                    double f8 = v.value(v.index(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2)));
                    a = std::min(a, f8);
                    b = std::max(b, f8);
                }
                f(a, b);
            }
}

// Calls f(a, b) with the span of every grid edge along x, y and z.
template <class F> void for_each_edge(const Volume& v, F f) {
    const auto d = v.dims();
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) {
                double u = v.value(v.index(x, y, z));
                if (x + 1 < d.nx) { double w = v.value(v.index(x + 1, y, z)); f(std::min(u, w), std::max(u, w)); }
                if (y + 1 < d.ny) { double w = v.value(v.index(x, y + 1, z)); f(std::min(u, w), std::max(u, w)); }
                if (z + 1 < d.nz) { double w = v.value(v.index(x, y, z + 1)); f(std::min(u, w), std::max(u, w)); }
            }
}

template <class Each> std::vector<std::uint64_t> brute(const Volume& v, const IsovalueSet& iso, Each each) {
    auto s = isovalues(iso);
    std::vector<std::uint64_t> n(s.size(), 0);
    each(v, [&](double a, double b) {
        for (std::size_t j = 0; j < s.size(); ++j)
            if (a < s[j] && s[j] <= b) ++n[j];
    });
    return n;
}

template <class Each> std::vector<std::uint64_t> histogram(const Volume& v, const IsovalueSet& iso, Each each) {
    auto s = isovalues(iso);
    std::vector<std::int64_t> h(s.size() + 1, 0);
    each(v, [&](double a, double b) {
        ++h[std::upper_bound(s.begin(), s.end(), a) - s.begin()];
        --h[std::upper_bound(s.begin(), s.end(), b) - s.begin()];
    });
    std::vector<std::uint64_t> n(s.size());
    std::int64_t run = 0;
    for (std::size_t j = 0; j < s.size(); ++j) n[j] = std::uint64_t(run += h[j]);
    return n;
}

}  // namespace

Volume level(const Volume& v, int l) {
    const std::size_t step = std::size_t(1) << l;
    const auto d = v.dims();
    clfractal::Dims out{(d.nx - 1) / step + 1, (d.ny - 1) / step + 1, (d.nz - 1) / step + 1};
    Volume r(out, v.type());
    const std::size_t vs = clfractal::value_size(v.type());
    auto* dst = static_cast<unsigned char*>(r.data());
    const auto* src = static_cast<const unsigned char*>(v.data());
    for (std::size_t z = 0; z < out.nz; ++z)
        for (std::size_t y = 0; y < out.ny; ++y)
            for (std::size_t x = 0; x < out.nx; ++x)
                std::copy_n(src + v.index(x * step, y * step, z * step) * vs, vs, dst + r.index(x, y, z) * vs);
    return r;
}

std::vector<std::uint64_t> cubes_brute(const Volume& v, const IsovalueSet& iso) {
    return brute(v, iso, [](const Volume& w, auto f) { for_each_cube(w, f); });
}
std::vector<std::uint64_t> edges_brute(const Volume& v, const IsovalueSet& iso) {
    return brute(v, iso, [](const Volume& w, auto f) { for_each_edge(w, f); });
}
std::vector<std::uint64_t> cubes_histogram(const Volume& v, const IsovalueSet& iso) {
    return histogram(v, iso, [](const Volume& w, auto f) { for_each_cube(w, f); });
}
std::vector<std::uint64_t> edges_histogram(const Volume& v, const IsovalueSet& iso) {
    return histogram(v, iso, [](const Volume& w, auto f) { for_each_edge(w, f); });
}

}  // namespace ref
