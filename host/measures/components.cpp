#include "clfractal/components.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <numeric>
#include <parallel/algorithm>
#include <type_traits>

#include "device/slab_plan.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "device/name_table.hpp"

namespace clfractal {

template <> struct detail::NameTable<Connectivity> {
    static constexpr const char* what = "--connectivity";
    static constexpr std::pair<Connectivity, const char*> names[] = {{Connectivity::cube, "cube"},
                                                                     {Connectivity::freudenthal, "freudenthal"}};
};
CLFRACTAL_NAME_TABLE(Connectivity)

Connectivity parse_connectivity(const std::string& name) { return parse_variant<Connectivity>(name); }

const char* connectivity_name(Connectivity c) { return variant_name(c); }

namespace {

struct Offset {
    int dx, dy, dz;
};

std::vector<Offset> neighbourhood(int adjacency) {
    std::vector<Offset> o;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
                if (n == 0) continue;
                bool keep = false;
                if (adjacency == 6) keep = n == 1;
                else if (adjacency == 26) keep = true;
                else  // 14: the Freudenthal edges, all offsets with non-mixed signs
                    keep = !(std::min({dx, dy, dz}) < 0 && std::max({dx, dy, dz}) > 0);
                if (keep) o.push_back({dx, dy, dz});
            }
    return o;
}

// Order-preserving 32-bit key of a value of at most 32 bits (floats: -0 and +0 equal, as the
// comparisons see them).
template <class T> inline std::uint32_t order_key(T f) {
    static_assert(sizeof(T) <= 4, "order_key: 32-bit values only");
    if constexpr (std::is_floating_point_v<T>) {
        if (f == 0.0f) f = 0.0f;
        std::uint32_t u;
        std::memcpy(&u, &f, 4);
        return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
    } else if constexpr (std::is_signed_v<T>) {
        return std::uint32_t(std::int64_t(f) - std::int64_t(std::numeric_limits<std::int32_t>::min()));
    } else {
        return std::uint32_t(f);
    }
}

// Integer value ranges up to this many values are sorted by counting.
constexpr long counting_sort_values = long(1) << 20;

// Counts of the values of integer data, bins vmin..vmax, on the device (32-bit counts:
// called below 2^32 vertices only).
std::vector<std::uint64_t> value_histogram_device(const DeviceVolume& v, long vmin, long vmax) {
    Context& ctx = v.context();
    const std::size_t nbins = std::size_t(vmax - vmin + 1), n = v.vertices();
    // Work-group histograms in local memory where they fit (Tuning::local_hist_bytes, as span counting).
    const bool local_hist = nbins * 4 <= std::min(ctx.tuning.local_hist_bytes, ctx.local_mem() / 2);
    const std::size_t wg = std::min<std::size_t>(64, ctx.max_work_group());
    std::string options = type_options(v.type()) + defines({{"WG", std::to_string(wg)}});
    if (local_hist) options += " -DLOCAL_HIST";
    std::vector<std::uint32_t> h32(nbins);
    with_cl_errors([&] {
        const std::size_t items = ctx.is_cpu() ? wg * std::max(1u, ctx.compute_units()) : wg * 1024;
        const std::size_t chunk = std::max<std::size_t>(1, (n + items - 1) / items);
        Buffer<std::uint32_t> hist(ctx, nbins);
        hist.fill(ctx.queue(), 0u);
        // kernels/components.cl value_histogram(values, n, chunk, vmin, nbins, hist[, local_hist]).
        using Global = KernelCall<cl::Buffer, cl_ulong, cl_ulong, cl_long, cl_uint, cl::Buffer>;
        using Local = KernelCall<cl::Buffer, cl_ulong, cl_ulong, cl_long, cl_uint, cl::Buffer, cl::LocalSpaceArg>;
        const cl::NDRange global(items), local(wg);
        if (local_hist)
            Local(ctx, "components", "value_histogram", options)(global, local, v.buffer(), cl_ulong(n), cl_ulong(chunk),
                                                                 cl_long(vmin), cl_uint(nbins), hist.get(),
                                                                 cl::Local(nbins * 4));
        else
            Global(ctx, "components", "value_histogram", options)(global, local, v.buffer(), cl_ulong(n),
                                                                  cl_ulong(chunk), cl_long(vmin), cl_uint(nbins),
                                                                  hist.get());
        hist.read(ctx.queue(), h32.data(), nbins);  // blocking: the kernel is done with the values
    });
    return std::vector<std::uint64_t>(h32.begin(), h32.end());
}

// The vertex indices ordered by (value, index).
template <class T, class I>
std::vector<I> sorted_vertices(const Volume& v, const DeviceVolume* dv) {
    const std::size_t n = v.vertices();
    const T* f = v.as<T>();
    std::vector<I> order(n);
    const ValueRange r = value_range(v);
    if (std::is_integral<T>::value && r.max - r.min < double(counting_sort_values)) {
        // Counting sort: histogram (device), exclusive prefix, stable scatter (host).
        const long vmin = long(r.min), vmax = long(r.max);
        std::vector<std::uint64_t> hist;
        // On the device when the volume is there (32-bit counts: below 2^32 vertices).
        if (dv && n < (std::size_t(1) << 32)) {
            hist = value_histogram_device(*dv, vmin, vmax);
        } else {
            hist.assign(std::size_t(vmax - vmin + 1), 0);
            for (std::size_t i = 0; i < n; ++i) ++hist[std::size_t(long(f[i]) - vmin)];
        }
        std::uint64_t sum = 0;
        for (auto& c : hist) {
            const std::uint64_t x = c;
            c = sum;
            sum += x;
        }
        if (sum != n) throw std::logic_error("value histogram does not add up to the vertex count");
        // Stable scatter by two threads: the first half forwards from each value's first
        // slot, the second half backwards from its last, so neither needs the other's counts.
        std::vector<std::uint64_t> end(hist.size());
        for (std::size_t b = 0; b < hist.size(); ++b) end[b] = b + 1 < hist.size() ? hist[b + 1] : n;
        const std::size_t half = n / 2;
#pragma omp parallel sections num_threads(2)
        {
#pragma omp section
            for (std::size_t i = 0; i < half; ++i) order[hist[std::size_t(long(f[i]) - vmin)]++] = I(i);
#pragma omp section
            for (std::size_t i = n; i-- > half;) order[--end[std::size_t(long(f[i]) - vmin)]] = I(i);
        }
    } else {
        bool sorted = false;
        if constexpr (sizeof(T) <= 4) {
            if (n < (std::size_t(1) << 32)) {
                // (key, index) packed in 64 bits: one parallel integer sort.
                std::vector<std::uint64_t> keys(n);
#pragma omp parallel for
                for (long long i = 0; i < (long long)n; ++i)
                    keys[std::size_t(i)] = (std::uint64_t(order_key(f[i])) << 32) | std::uint64_t(i);
                // Threads pay off only on large volumes (and spin badly on a loaded machine).
                if (n >= (std::size_t(1) << 22)) __gnu_parallel::sort(keys.begin(), keys.end());
                else std::sort(keys.begin(), keys.end());
#pragma omp parallel for
                for (long long i = 0; i < (long long)n; ++i)
                    order[std::size_t(i)] = I(keys[std::size_t(i)] & 0xffffffffu);
                sorted = true;
            }
        }
        if (!sorted) {
            std::iota(order.begin(), order.end(), I(0));
            __gnu_parallel::sort(order.begin(), order.end(), [f](I a, I b) {
                return f[a] < f[b] || (f[a] == f[b] && a < b);
            });
        }
    }
    return order;
}

// The neighbour masks of kernels/components.cl (neighbour_masks), on the host: used when
// the volume or the masks exceed the device's largest allocation.
template <class T>
void neighbour_masks_host(const T* f, const Dims& d, const std::vector<Offset>& a, const std::vector<Offset>& c,
                          std::uint32_t* mask) {
    const long nx = long(d.nx), ny = long(d.ny), nz = long(d.nz);
#pragma omp parallel for
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y)
            for (long x = 0; x < nx; ++x) {
                const std::size_t v = std::size_t(x + nx * (y + ny * z));
                const T fv = f[v];
                std::uint32_t m = 0;
                auto lower = [&](const Offset& o, bool& inside) {
                    inside = x + o.dx >= 0 && x + o.dx < nx && y + o.dy >= 0 && y + o.dy < ny && z + o.dz >= 0 &&
                             z + o.dz < nz;
                    if (!inside) return false;
                    const long off = o.dx + nx * (o.dy + ny * o.dz);
                    const T fu = f[std::size_t(long(v) + off)];
                    return fu < fv || (fu == fv && off < 0);
                };
                bool inside = false;
                for (std::size_t q = 0; q < a.size(); ++q)
                    if (lower(a[q], inside)) m |= std::uint32_t(1) << q;
                for (std::size_t q = 0; q < c.size(); ++q)
                    if (!lower(c[q], inside) && inside) m |= std::uint32_t(1) << (a.size() + q);
                mask[v] = m;
            }
}

// For every vertex, bit q < |a|: neighbour a[q] precedes it in (value, index) order; bit
// |a| + q: neighbour c[q] follows it. On the device (one work-item per vertex) when it fits.
template <class T>
std::vector<std::uint32_t> neighbour_masks(const Volume& v, const DeviceVolume* dv, int adj_a, int adj_c) {
    const std::vector<Offset> a = neighbourhood(adj_a), c = neighbourhood(adj_c);
    const Dims d = v.dims();
    std::vector<std::uint32_t> mask(v.vertices());
    if (!dv || v.vertices() * 4 > dv->context().max_alloc()) {
        neighbour_masks_host(v.as<T>(), d, a, c, mask.data());
        return mask;
    }
    Context& ctx = dv->context();
    with_cl_errors([&] {
        const std::string options = type_options(v.type()) + defines({{"ADJ_A", std::to_string(adj_a)},
                                             {"ADJ_C", std::to_string(adj_c)},
                                             {"A_COUNT", std::to_string(a.size())}});
        // kernels/components.cl neighbour_masks(f, nx, ny, nz, mask).
        KernelCall<cl::Buffer, cl_int, cl_int, cl_int, cl::Buffer> k(ctx, "components", "neighbour_masks", options);
        const std::size_t wg = std::min<std::size_t>(64, ctx.max_work_group());
        const DeviceVolume out = DeviceVolume::output(ctx, mask.data(), d, ValueType::uint32);
        const cl::NDRange global((d.nx + wg - 1) / wg * wg, d.ny, d.nz), local(wg, 1, 1);
        k(global, local, dv->buffer(), cl_int(d.nx), cl_int(d.ny), cl_int(d.nz), out.buffer());
        out.download(mask.data());
    });
    return mask;
}

// One union-find sweep over `order` (forward: increasing (value, index); backward:
// decreasing). The neighbours of v already swept are the bits [shift, shift + |nbrs|) of
// mask[v] (neighbour_masks). `met(v)` gets the number of distinct components among them,
// then v joins them all: v becomes a leaf of the first one met, whose root also takes the
// roots of the others; paths are halved on every find. Swept
// neighbours that are adjacent to each other are already in one component, so only one of
// each such group is looked up (with 26-connectivity usually one or two finds instead of
// ~13). The loop is bound by memory latency: masks and parents of vertices a few steps
// ahead are prefetched.
template <bool forward, class I, class P, class F>
void sweep(const Dims& d, const std::vector<I>& order, const std::vector<std::uint32_t>& mask, int shift,
           const std::vector<Offset>& nbrs, std::vector<I>& parent, P&& prefetch_value, F&& met) {
    const std::size_t n = order.size(), nx = d.nx, ny = d.ny;
    const std::size_t m = nbrs.size();
    const std::uint32_t bits = m == 32 ? ~0u : ((std::uint32_t(1) << m) - 1);
    std::vector<std::ptrdiff_t> lin(m);
    std::vector<std::uint32_t> adj(m, 0);  // adj[q]: the neighbours adjacent to neighbour q
    for (std::size_t q = 0; q < m; ++q) {
        lin[q] = std::ptrdiff_t(nbrs[q].dx) + std::ptrdiff_t(nx) * (nbrs[q].dy + std::ptrdiff_t(ny) * nbrs[q].dz);
        for (std::size_t r = 0; r < m; ++r)
            for (const Offset& o : nbrs)
                if (nbrs[r].dx - nbrs[q].dx == o.dx && nbrs[r].dy - nbrs[q].dy == o.dy && nbrs[r].dz - nbrs[q].dz == o.dz)
                    adj[q] |= std::uint32_t(1) << r;
    }
    auto find = [&](I x) {
        while (parent[x] != x) {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        return x;
    };
    auto at = [&](std::size_t k) { return order[forward ? k : n - 1 - k]; };
    constexpr std::size_t far = 24, near = 8;
    for (std::size_t k = 0; k < n; ++k) {
        if (k + far < n) {
            const I w = at(k + far);
            __builtin_prefetch(&mask[w]);
            __builtin_prefetch(&parent[w], 1);
            prefetch_value(w);
        }
        if (k + near < n) {
            const I w = at(k + near);
            std::uint32_t ahead = (mask[w] >> shift) & bits;
            for (; ahead; ahead &= ahead - 1) __builtin_prefetch(&parent[std::ptrdiff_t(w) + lin[__builtin_ctz(ahead)]], 1);
        }
        const I v = at(k);
        parent[v] = v;
        std::uint32_t swept = (mask[v] >> shift) & bits;
        int count = 0;
        I root = v;  // the root of v's component: v itself, or the first component met
        while (swept) {
            const int q = __builtin_ctz(swept);
            std::uint32_t group = std::uint32_t(1) << q, frontier = group;
            while (frontier) {
                std::uint32_t reach = 0;
                for (std::uint32_t b = frontier; b; b &= b - 1) reach |= adj[__builtin_ctz(b)];
                frontier = reach & swept & ~group;
                group |= frontier;
            }
            swept &= ~group;
            const I r = find(I(std::ptrdiff_t(v) + lin[q]));
            if (count == 0) {
                // v joins the first component as a leaf: old trees do not grow deeper.
                parent[v] = root = r;
                ++count;
            } else if (r != root) {
                parent[r] = root;
                ++count;
            }
        }
        met(v, count);
    }
}

template <class T, class I>
std::vector<std::int64_t> component_counts(const Volume& v, const DeviceVolume* dv, const IsovalueSet& iso,
                                           Connectivity mode) {
    const T* f = v.as<T>();
    const std::size_t K = iso.size();
    std::vector<I> order = sorted_vertices<T, I>(v, dv);
    // Bin of a vertex: the first isovalue index j with f(v) < s_j (K when none).
    auto bin = [&](I i) -> std::size_t {
        if (iso.integer()) {
            const std::int64_t b = std::int64_t(f[i]) - iso.first() + 1;
            return std::size_t(std::clamp<std::int64_t>(b, 0, std::int64_t(K)));
        }
        // Lists compare in double: exact for every value type and list type.
        const auto& s = iso.list();
        return std::size_t(std::upper_bound(s.begin(), s.end(), double(f[i])) - s.begin());
    };
    std::vector<std::int64_t> delta(K + 1, 0);
    const int a_adj = mode == Connectivity::cube ? 6 : 14, c_adj = mode == Connectivity::cube ? 26 : 14;
    const std::vector<Offset> a_nbrs = neighbourhood(a_adj), c_nbrs = neighbourhood(c_adj);
    const std::vector<std::uint32_t> mask = neighbour_masks<T>(v, dv, a_adj, c_adj);
    // The two sweeps are independent: each runs on its own core with its own union-find
    // forest and its own differences (4 bytes per vertex more than one after the other).
    std::vector<std::int64_t> delta_split(K + 1, 0);
    auto prefetch_value = [f](I i) { __builtin_prefetch(&f[i]); };
    // Join sweep: A = {f < s} grows with s; down(v) enters with a minus sign.
    auto join = [&] {
        std::vector<I> parent(v.vertices());
        sweep<true, I>(v.dims(), order, mask, 0, a_nbrs, parent, prefetch_value,
                       [&](I i, int down) { delta[bin(i)] -= down; });
    };
    // Split sweep: C = {f >= s} grows as s falls; up(v) enters with a plus sign.
    auto split = [&] {
        std::vector<I> parent(v.vertices());
        sweep<false, I>(v.dims(), order, mask, int(a_nbrs.size()), c_nbrs, parent, prefetch_value,
                        [&](I i, int up) { delta_split[bin(i)] += up; });
    };
    std::exception_ptr failed[2];
#pragma omp parallel sections num_threads(2)
    {
#pragma omp section
        try {
            join();
        } catch (...) {
            failed[0] = std::current_exception();
        }
#pragma omp section
        try {
            split();
        } catch (...) {
            failed[1] = std::current_exception();
        }
    }
    for (const auto& e : failed)
        if (e) std::rethrow_exception(e);
    std::vector<std::int64_t> c(K);
    std::int64_t sum = 0;
    for (std::size_t j = 0; j < K; ++j) c[j] = sum += delta[j] + delta_split[j];
    return c;
}

}  // namespace

namespace {

// The curve of `v`, with the device steps on `dv` (the same values) when it is given.
ComponentCurve components_of(Context& ctx, const Volume& v, const DeviceVolume* dv, const IsovalueSet& iso,
                             Connectivity mode) {
    const ComputeTimer timer(ctx);
    ComponentCurve c;
    c.isovalues = iso;
    if (!iso.matches(v.type()))
        throw InputError("count_components: the isovalue set does not match the data type");
    if (iso.size() > 0 && v.vertices() > 0) {
        c.components = visit(v, [&](const auto* p) {
            using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
            return v.vertices() < std::size_t(0xffffffffu) ? component_counts<T, std::uint32_t>(v, dv, iso, mode)
                                                            : component_counts<T, std::uint64_t>(v, dv, iso, mode);
        });
    }
    c.components.resize(iso.size(), 0);
    c.seconds = timer.seconds();
    return c;
}

}  // namespace

ComponentCurve count_components(Context& ctx, const Volume& v, const IsovalueSet& iso, Connectivity mode) {
    // The device takes the volume in one piece when it fits one allocation (and
    // Tuning::slab_bytes, when set: tests lower it to force the host path).
    const Dims d = v.dims();
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = d.nx * d.ny * value_size(v.type());
    need.memory_divisor = 1;
    const bool fits = v.vertices() > 0 && int_axes(d) && slab_fit(ctx, need) >= d.nz;
    if (!fits || iso.size() == 0) return components_of(ctx, v, nullptr, iso, mode);
    try {
        const DeviceVolume dv(ctx, v);
        return components_of(ctx, v, &dv, iso, mode);
    } catch (const DeviceError& e) {
        // Out of device memory: the host steps, as for a volume larger than the device.
        if (!e.out_of_memory()) throw;
        return components_of(ctx, v, nullptr, iso, mode);
    }
}

ComponentCurve count_components(const DeviceVolume& v, const IsovalueSet& iso, Connectivity mode) {
    return components_of(v.context(), v.download(), &v, iso, mode);
}

std::int64_t count_components_at(Context& ctx, const Volume& v, double isovalue, Connectivity mode) {
    if (!std::isfinite(isovalue)) throw InputError("isovalue must be finite");
    // Integer data: f < s  <=>  f < ceil(s); the set's range only bounds the bins.
    return count_components(ctx, v, IsovalueSet::single(v.type(), isovalue), mode).components[0];
}

std::int64_t count_components_at(const DeviceVolume& v, double isovalue, Connectivity mode) {
    if (!std::isfinite(isovalue)) throw InputError("isovalue must be finite");
    return count_components(v, IsovalueSet::single(v.type(), isovalue), mode).components[0];
}

}  // namespace clfractal
