// The OpenMP span counter: what a careful multi-threaded C++ loop does. It is the
// baseline the device kernels are measured against (same counts, same algorithm and the
// same tuning as the CPU kernel: per-thread histograms, four of them taken in turn along x
// so that neighbouring cubes hitting one bin do not wait on each other's stores, x-rows
// with column min/max reused between neighbouring cubes, bins of 8/16-bit data in int).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <type_traits>

#include "baselines.hpp"

namespace clfractal {

namespace {

// Integer sets bin by value; lists compare in double, exact for every value type and for
// float32 and float64 isovalues alike.
template <class T> struct Binner {
    std::int64_t vmin = 0;
    const double* iso = nullptr;
    int niso = 0;
    bool integer = true;
    int operator()(T v) const {
        if (integer) return int(std::clamp<std::int64_t>(std::int64_t(v) - vmin + 1, 0, niso));
        return int(std::upper_bound(iso, iso + niso, double(v)) - iso);
    }
};

// An integer set on 8/16-bit data whose first isovalue is within 2^20: every bin in int.
template <class T> struct NarrowBinner {
    int vmin = 0, niso = 0;
    int operator()(T v) const { return std::clamp(int(v) - vmin + 1, 0, niso); }
};

template <class T>
void add(std::int64_t* h, const Binner<T>& bin, T a, T b) {
    int ba = bin(a), bb = bin(b);
    if (ba != bb) {
        ++h[ba];
        --h[bb];
    }
}

// Per x-row of cubes: column min/max of the 4 vertices (y, z), (y+1, z), (y, z+1),
// (y+1, z+1) into small arrays (vectorised), then the spans and histogram updates.
// Working from local arrays also keeps the compiler from reloading the volume after
// every histogram store (uint8 data may alias anything).
template <class T, class Bin>
void count_cubes(const T* v, const Dims& d, const Bin& bin, std::int64_t* h, std::size_t nbins) {
    if (d.nx < 2 || d.ny < 2 || d.nz < 2) return;
    const std::size_t slice = d.nx * d.ny, nx = d.nx;
    const long long rows = (long long)(d.ny - 1) * (long long)(d.nz - 1);
    std::vector<T> cmin(nx), cmax(nx);
    std::vector<int> lo(nx), hi(nx);
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
        const std::size_t y = std::size_t(r) % (d.ny - 1), z = std::size_t(r) / (d.ny - 1);
        const T* __restrict p00 = v + z * slice + y * nx;
        const T* __restrict p10 = p00 + nx;
        const T* __restrict p01 = p00 + slice;
        const T* __restrict p11 = p01 + nx;
        T* __restrict mn = cmin.data();
        T* __restrict mx = cmax.data();
        for (std::size_t x = 0; x < nx; ++x) {
            mn[x] = std::min(std::min(p00[x], p10[x]), std::min(p01[x], p11[x]));
            mx[x] = std::max(std::max(p00[x], p10[x]), std::max(p01[x], p11[x]));
        }
        int* __restrict l = lo.data();
        int* __restrict u = hi.data();
        for (std::size_t x = 0; x + 1 < nx; ++x) {
            l[x] = bin(std::min(mn[x], mn[x + 1]));
            u[x] = bin(std::max(mx[x], mx[x + 1]));
        }
        std::int64_t* __restrict h1 = h + nbins;
        std::int64_t* __restrict h2 = h1 + nbins;
        std::int64_t* __restrict h3 = h2 + nbins;
        std::size_t x = 0;
        for (; x + 4 < nx; x += 4) {
            if (l[x] != u[x]) ++h[l[x]], --h[u[x]];
            if (l[x + 1] != u[x + 1]) ++h1[l[x + 1]], --h1[u[x + 1]];
            if (l[x + 2] != u[x + 2]) ++h2[l[x + 2]], --h2[u[x + 2]];
            if (l[x + 3] != u[x + 3]) ++h3[l[x + 3]], --h3[u[x + 3]];
        }
        for (; x + 1 < nx; ++x)
            if (l[x] != u[x]) ++h[l[x]], --h[u[x]];
    }
}

template <class T>
void count_edges(const T* v, const Dims& d, const Binner<T>& bin, std::int64_t* h) {
    const std::size_t slice = d.nx * d.ny;
    const long long rows = (long long)d.ny * (long long)d.nz;
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
        const std::size_t y = std::size_t(r) % d.ny, z = std::size_t(r) / d.ny;
        const T* p = v + z * slice + y * d.nx;
        for (std::size_t x = 0; x + 1 < d.nx; ++x) add(h, bin, std::min(p[x], p[x + 1]), std::max(p[x], p[x + 1]));
        if (y + 1 < d.ny)
            for (std::size_t x = 0; x < d.nx; ++x) add(h, bin, std::min(p[x], p[x + d.nx]), std::max(p[x], p[x + d.nx]));
        if (z + 1 < d.nz)
            for (std::size_t x = 0; x < d.nx; ++x) add(h, bin, std::min(p[x], p[x + slice]), std::max(p[x], p[x + slice]));
    }
}

}  // namespace

SpanResult count_spans_openmp(const Volume& v, const IsovalueSet& iso, const SpanOptions& opt) {
    if (opt.levels < 1 || opt.levels > 16) throw InputError("--levels must be between 1 and 16");
    if (!iso.matches(v.type()))
        throw std::logic_error("count_spans_openmp: isovalue set does not match the value type");
    auto t0 = std::chrono::steady_clock::now();
    const std::size_t nbins = iso.size() + 1;
    SpanResult r;
    r.isovalues = iso;
    r.slabs = 1;
    for (SpanKind k : opt.kinds) r.curves.push_back(SpanCurves{k, {}, {}});

    Volume sub;  // the current level when l > 0
    for (int l = 0; l < opt.levels; ++l) {
        if (l > 0) sub = subsample(l == 1 ? v : sub);
        const Volume& cur = l == 0 ? v : sub;
        for (auto& c : r.curves) {
            std::vector<std::int64_t> total(nbins, 0);
            visit(cur, [&](const auto* data) {
                using T = std::remove_const_t<std::remove_pointer_t<decltype(data)>>;
                Binner<T> bin;
                bin.integer = iso.integer();
                bin.vmin = iso.first();
                bin.iso = iso.list().data();
                bin.niso = int(iso.size());
                const bool narrow = std::is_integral_v<T> && sizeof(T) <= 2 && iso.integer() &&
                                    std::llabs(iso.first()) <= (1 << 20);
#pragma omp parallel
                {
                    std::vector<std::int64_t> h(4 * nbins, 0);  // cubes: four in turn; edges: the first
                    if (c.kind == SpanKind::cubes && narrow)
                        count_cubes(data, cur.dims(), NarrowBinner<T>{int(iso.first()), int(iso.size())}, h.data(), nbins);
                    else if (c.kind == SpanKind::cubes)
                        count_cubes(data, cur.dims(), bin, h.data(), nbins);
                    else
                        count_edges(data, cur.dims(), bin, h.data());
#pragma omp critical
                    for (std::size_t i = 0; i < nbins; ++i) total[i] += h[i] + h[nbins + i] + h[2 * nbins + i] + h[3 * nbins + i];
                }
            });
            std::vector<std::uint64_t> counts(iso.size());
            std::int64_t run = 0;
            for (std::size_t j = 0; j < iso.size(); ++j) counts[j] = std::uint64_t(run += total[j]);
            c.level_dims.push_back(cur.dims());
            c.counts.push_back(std::move(counts));
        }
    }
    r.seconds = seconds_since(t0);
    return r;
}

}  // namespace clfractal
