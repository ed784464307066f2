// The local-dimension field on the host with OpenMP threads, by the algorithm of the CPU
// kernels: the CPU baseline of the LD benchmark and a second reference of the tests.
#include <omp.h>

#include <cmath>
#include <limits>
#include <memory>
#include <type_traits>

#include "baselines.hpp"
#include "clfractal/pyramid.hpp"
#include "device/type_options.hpp"

namespace clfractal {

namespace {

// The padded indicator of `v` (see kernels/local.cl) and its summed-area table: per z-slice
// each x-row is filled with the indicator (a loop the compiler vectorises), scanned and added
// to the row before it; then the slices are accumulated along z. Every entry is written
// once, so the table is allocated without a zero fill.
template <class C, class T, class Iso>
std::unique_ptr<C[]> indicator_table(const T* v, const Dims& d, Iso hit) {
    std::unique_ptr<C[]> table(new C[d.vertices()]);
    C* S = table.get();
    const std::size_t row = d.nx, slice = d.nx * d.ny;
#pragma omp parallel for schedule(static)
    for (long long z = 0; z < (long long)d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y) {
            C* s = S + std::size_t(z) * slice + y * row;
            s[0] = 0;
            if (z == 0 || y == 0) {
                std::fill(s + 1, s + row, C(0));
                continue;
            }
            const T* p00 = v + (std::size_t(z) - 1) * slice + (y - 1) * row;
            const T* p10 = p00 + row;
            const T* p01 = p00 + slice;
            const T* p11 = p01 + row;
            for (std::size_t x = 1; x < d.nx; ++x) {
                const T a = std::min(std::min(std::min(p00[x - 1], p00[x]), std::min(p10[x - 1], p10[x])),
                                     std::min(std::min(p01[x - 1], p01[x]), std::min(p11[x - 1], p11[x])));
                const T b = std::max(std::max(std::max(p00[x - 1], p00[x]), std::max(p10[x - 1], p10[x])),
                                     std::max(std::max(p01[x - 1], p01[x]), std::max(p11[x - 1], p11[x])));
                s[x] = C(hit(a, b));
            }
            const C* above = s - row;
            C run = 0;
            for (std::size_t x = 1; x < d.nx; ++x) {
                run += s[x];
                s[x] = run + above[x];
            }
        }
#pragma omp parallel for schedule(static)
    for (long long y = 1; y < (long long)d.ny; ++y)
        for (std::size_t z = 2; z < d.nz; ++z) {
            C* s = S + z * slice + std::size_t(y) * row;
            const C* below = s - slice;
            for (std::size_t x = 0; x < d.nx; ++x) s[x] += below[x];
        }
    return table;
}

template <class C> Volume field_openmp(const Volume& v, double iso, int window) {
    const Dims d = v.dims();
    const Volume sub = subsample(v);
    const Dims ds = sub.dims();
    std::unique_ptr<C[]> S, Ssub;
    visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_integral_v<T>) {
            const std::int64_t s = integer_isovalue(iso);
            auto hit = [s](T a, T b) { return std::int64_t(a) < s && s <= std::int64_t(b); };
            S = indicator_table<C>(p, d, hit);
            Ssub = indicator_table<C>(sub.as<T>(), ds, hit);
        } else {
            const T s = T(iso);  // float32 data: s rounded to float; float64 data: s
            auto hit = [s](T a, T b) { return a < s && s <= b; };
            S = indicator_table<C>(p, d, hit);
            Ssub = indicator_table<C>(sub.as<T>(), ds, hit);
        }
    });
    const std::vector<LocalWindow> wx = local_windows(d.nx, window), wy = local_windows(d.ny, window),
                                   wz = local_windows(d.nz, window);
    Volume out(d, ValueType::float32, v.name);
    out.spacing = v.spacing;
    float* ld = out.as<float>();
    const std::size_t row = d.nx, slice = d.nx * d.ny, row_sub = ds.nx, slice_sub = ds.nx * ds.ny;
    // Per x-row: the y-z part of the inclusion-exclusion for every column, then two lookups
    // per vertex and grid (as kernels/local.cl local_dimension_rows).
    auto columns = [](const C* S, std::size_t row, std::size_t slice, int y0, int y1, int z0, int z1, std::size_t n,
                      C* col) {
        const C* a00 = S + z0 * slice + y0 * row;
        const C* a01 = S + z0 * slice + y1 * row;
        const C* a10 = S + z1 * slice + y0 * row;
        const C* a11 = S + z1 * slice + y1 * row;
        for (std::size_t x = 0; x < n; ++x) col[x] = (a11[x] - a10[x]) - (a01[x] - a00[x]);
    };
#pragma omp parallel
    {
        std::vector<C> col(d.nx), col_sub(ds.nx);
#pragma omp for schedule(static)
        for (long long r = 0; r < (long long)(d.ny * d.nz); ++r) {
            const std::size_t y = std::size_t(r) % d.ny, z = std::size_t(r) / d.ny;
            columns(S.get(), row, slice, wy[y].lo, wy[y].hi, wz[z].lo, wz[z].hi, d.nx, col.data());
            columns(Ssub.get(), row_sub, slice_sub, wy[y].lo_sub, wy[y].hi_sub, wz[z].lo_sub, wz[z].hi_sub, ds.nx,
                    col_sub.data());
            float* o = ld + z * slice + y * row;
            for (std::size_t x = 0; x < d.nx; ++x) {
                const C a = col[wx[x].hi] - col[wx[x].lo], b = col_sub[wx[x].hi_sub] - col_sub[wx[x].lo_sub];
                o[x] = a && b ? float(std::log2(double(a) / double(b))) : std::numeric_limits<float>::quiet_NaN();
            }
        }
    }
    return out;
}

}  // namespace

Volume local_fractal_dimension_openmp(const Volume& v, double iso, int window) {
    check_local_arguments(iso, window);
    return v.dims().cubes() > 0xffffffffu ? field_openmp<std::uint64_t>(v, iso, window)
                                          : field_openmp<std::uint32_t>(v, iso, window);
}

}  // namespace clfractal
