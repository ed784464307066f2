#include "clfractal/components.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <numeric>
#include <omp.h>
#include <parallel/algorithm>
#include <type_traits>

#include "components_slab.hpp"
#include "target_clones.hpp"
#include "measures/row_mask.hpp"
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

// The neighbour masks of a row's inner vertices (neighbour_masks_host): for each neighbour q
// of `inside` (bit q), one vectorised comparison a vertex. On x86-64 also compiled for AVX2
// and chosen at load time (MASK_CLONES, target_clones.hpp): the baseline's SSE2 widens 8- and
// 16-bit comparisons to the masks' 32 bits a few lanes at a time (the bonsai's components,
// interleaved: 1.03-1.07 s to 0.92-1.03 s, the same curve). GCC only: Clang does not
// multiversion function templates.
#if !defined(__AVX2__) && !defined(__clang__)
#define MASK_CLONES CLFRACTAL_CLONES("avx2")
#else
#define MASK_CLONES
#endif
template <class T>
MASK_CLONES void mask_row(const T* p, std::uint32_t* m, std::size_t n, const long* lin, std::size_t count,
                          std::size_t a_count, std::uint32_t inside) {
    std::fill(m, m + n, 0u);
    for (std::size_t q = 0; q < count; ++q) {
        if (!((inside >> q) & 1u)) continue;
        const T* u = p + lin[q];
        const std::uint32_t bit = std::uint32_t(1) << q;
        // A's bits: the neighbour precedes (lower); C's: it follows (not lower).
        const bool before = lin[q] < 0, want_lower = q < a_count;
        if (before && want_lower)
            for (std::size_t i = 0; i < n; ++i) m[i] |= u[i] <= p[i] ? bit : 0u;
        else if (want_lower)
            for (std::size_t i = 0; i < n; ++i) m[i] |= u[i] < p[i] ? bit : 0u;
        else if (before)
            for (std::size_t i = 0; i < n; ++i) m[i] |= u[i] > p[i] ? bit : 0u;
        else
            for (std::size_t i = 0; i < n; ++i) m[i] |= u[i] >= p[i] ? bit : 0u;
    }
}

// The neighbour masks of kernels/components.cl (neighbour_masks), on the host: used when
// the volume or the masks exceed the device's largest allocation, and for z-slabs. Every row
// takes each neighbour inside the grid across its inner vertices at once, one vectorised
// comparison a vertex, and its first and last vertex one at a time. (Border rows a vertex at
// a time made the masks a quarter of the 640^3 phantom's curve: its z-slabs of 5 slices are
// two-fifths border.)
template <class T>
void neighbour_masks_host(const T* f, const Dims& d, const std::vector<Offset>& a, const std::vector<Offset>& c,
                          std::uint32_t* mask) {
    const long nx = long(d.nx), ny = long(d.ny), nz = long(d.nz);
    std::vector<Offset> all(a);
    all.insert(all.end(), c.begin(), c.end());
    std::vector<long> lin(all.size());
    for (std::size_t q = 0; q < all.size(); ++q) lin[q] = all[q].dx + nx * (all[q].dy + ny * all[q].dz);
    // Neighbour q of vertex v (inside): whether it precedes v in (value, index) order.
    auto vertex = [&](long x, long y, long z) {
        const std::size_t v = std::size_t(x + nx * (y + ny * z));
        const T fv = f[v];
        std::uint32_t m = 0;
        for (std::size_t q = 0; q < all.size(); ++q) {
            const Offset& o = all[q];
            if (x + o.dx < 0 || x + o.dx >= nx || y + o.dy < 0 || y + o.dy >= ny || z + o.dz < 0 || z + o.dz >= nz)
                continue;
            const T fu = f[std::size_t(long(v) + lin[q])];
            const bool lower = fu < fv || (fu == fv && lin[q] < 0);
            if (lower == (q < a.size())) m |= std::uint32_t(1) << q;
        }
        mask[v] = m;
    };
#pragma omp parallel for
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y) {
            if (nx < 3) {
                for (long x = 0; x < nx; ++x) vertex(x, y, z);
                continue;
            }
            const std::size_t row = std::size_t(1 + nx * (y + ny * z)), n = std::size_t(nx - 2);
            // Rows on the y or z border: neighbours outside the grid keep their bit clear.
            std::uint32_t inside = 0;
            for (std::size_t q = 0; q < all.size(); ++q) {
                const long yq = y + all[q].dy, zq = z + all[q].dz;
                if (yq >= 0 && yq < ny && zq >= 0 && zq < nz) inside |= std::uint32_t(1) << q;
            }
            mask_row(f + row, mask + row, n, lin.data(), all.size(), a.size(), inside);
            vertex(0, y, z);
            vertex(nx - 1, y, z);
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

// Union-find sweeps in (value, index) order (forward: increasing; backward: decreasing),
// fed a run of vertices at a time. For each vertex v of a run, `bits` are its neighbours
// (in `nbrs`) already swept. `met(k, v)` (v the k-th of the run) gets the number of distinct
// components among them,
// then v joins them all: v becomes a leaf of the first one met, whose root also takes the
// roots of the others; paths are halved on every find. Swept neighbours that are connected
// through swept neighbours are already in one component, so only one of each such group is
// looked up (group: with 26-connectivity usually one or two finds instead of ~13; the cube
// connectivity's join sweep, whose 6 face neighbours never touch each other, groups them by
// 6-paths through the swept cells of v's whole cube: 0.47 finds a vertex instead of 2.81 on
// a 256^3 crop of the 640^3 uint16 phantom). `joined(v, child, root)` hears of every union at
// the sweep of v (first v itself joining a root, then the roots that join v's). A vertex
// that meets one group, and whose joining is told to nobody (all but a slab's boundary
// vertices), takes its neighbour's parent instead of a find: the same roots, so the same
// counts and links, without the chain's reads. The loop is bound by memory latency: parents
// of vertices a few steps ahead are prefetched.
// neighbourhood(6)'s faces in the 3x3x3 cube's layout (bit x + 3 y + 9 z).
constexpr int face_cell[6] = {4, 10, 12, 14, 16, 22};

template <class I> class Sweeper {
public:
    // `parent`: the forest, one entry for each of the grid's `vertices`.
    Sweeper(const Dims& d, const std::vector<Offset>& nbrs, I* parent, std::size_t vertices)
        : parent_(parent), vertices_(vertices), m_(nbrs.size()), lin_(m_), adj_(m_, 0) {
        const std::size_t nx = d.nx, ny = d.ny;
        for (std::size_t q = 0; q < m_; ++q) {
            lin_[q] = std::ptrdiff_t(nbrs[q].dx) + std::ptrdiff_t(nx) * (nbrs[q].dy + std::ptrdiff_t(ny) * nbrs[q].dz);
            for (std::size_t r = 0; r < m_; ++r)
                for (const Offset& o : nbrs)
                    if (nbrs[r].dx - nbrs[q].dx == o.dx && nbrs[r].dy - nbrs[q].dy == o.dy &&
                        nbrs[r].dz - nbrs[q].dz == o.dz)
                        adj_[q] |= std::uint32_t(1) << r;
        }
    }
    std::uint32_t bits() const { return m_ == 32 ? ~0u : ((std::uint32_t(1) << m_) - 1); }
    // The swept neighbours (bits of `swept`, q among them) in neighbour q's group: connected to
    // it through swept neighbours, or, given the swept cells of the cube (`cube`, the cube
    // connectivity's join sweep: preceding_cube), through those.
    std::uint32_t group(int q, std::uint32_t swept, std::uint32_t cube) const {
        if ((swept & (swept - 1)) == 0) return swept;
        return cube ? face_group(q, cube) : group_of(q, swept);
    }
    // Whether the swept neighbours (bits of `swept`, at least one) form one group (group).
    bool one_group(std::uint32_t swept, std::uint32_t cube) const {
        if ((swept & (swept - 1)) == 0) return true;
        const int q = __builtin_ctz(swept);
        if (!cube) return (swept & ~group_of(q, swept)) == 0;
        const std::uint32_t faces = cube & face_cells;
        return (face_flood(q, cube) & faces) == faces;
    }
    // The neighbours' index offsets.
    const std::vector<std::ptrdiff_t>& offsets() const { return lin_; }

    // Sweeps `count` vertices: at(k) the k-th, swept(k) its swept-neighbour bits.
    template <class At, class Swept, class Cube, class P, class F, class U>
    void run(std::size_t count, At&& at, Swept&& swept_bits, Cube&& cube_swept, P&& prefetch_value, F&& met,
             U&& joined) {
        // Three stages ahead: the vertex and its value, its swept neighbours' parents, and
        // then (those parents now in cache) their parents, where the finds go next. The second
        // takes the first and the last swept neighbour only: their parents' lines hold most of
        // the others' (a neighbourhood spans 9 rows), and a prefetch for each of up to 26
        // neighbours filled the line buffers instead (384^3 uint16 phantom's curve, three
        // interleaved runs each: 7.4-8.1 s against 6.0-7.5 s; the same curves). The third
        // only for a forest far beyond the caches: below, its loop costs more than it saves
        // (noisy sphere 256^3 uint8, 64 MiB: 3.2 s against 3.3 s; CT-like phantom 400^3
        // uint16, 256 MiB: 16.4 s against 17.3 s).
        constexpr std::size_t far = 24, near = 8, next = 4;
        I* const parent = parent_;
        const bool chase = vertices_ * sizeof(I) > (std::size_t(128) << 20);
        for (std::size_t k = 0; k < count; ++k) {
            if (k + far < count) {
                const I w = at(k + far);
                __builtin_prefetch(&parent[w], 1);
                prefetch_value(w);
            }
            if (k + near < count) {
                const I w = at(k + near);
                if (const std::uint32_t ahead = swept_bits(k + near)) {
                    __builtin_prefetch(&parent[std::ptrdiff_t(w) + lin_[__builtin_ctz(ahead)]], 1);
                    __builtin_prefetch(&parent[std::ptrdiff_t(w) + lin_[31 - __builtin_clz(ahead)]], 1);
                }
            }
            if (chase && k + next < count) {
                const I w = at(k + next);
                for (std::uint32_t ahead = swept_bits(k + next); ahead; ahead &= ahead - 1)
                    __builtin_prefetch(&parent[parent[std::ptrdiff_t(w) + lin_[__builtin_ctz(ahead)]]], 1);
            }
            const I v = at(k);
            parent[v] = v;
            std::uint32_t swept = swept_bits(k);
            const std::uint32_t cube = cube_swept(k);
            int found = 0;
            I root = v;  // the root of v's component: v itself, or the first component met
            while (swept) {
                const int q = __builtin_ctz(swept);
                swept &= ~group(q, swept, cube);
                const I u = I(std::ptrdiff_t(v) + lin_[q]);
                if (found == 0 && !swept && !joined.told(v)) {
                    // One component met, and nobody to tell its root: v takes the parent of
                    // its neighbour u (as deep as u) without a find.
                    parent[v] = parent[u];
                    found = 1;
                    break;
                }
                const I r = find(u);
                if (found == 0) {
                    // v joins the first component as a leaf: old trees do not grow deeper.
                    parent[v] = root = r;
                    ++found;
                    joined(v, v, r);
                } else if (r != root) {
                    parent[r] = root;
                    ++found;
                    joined(v, r, root);
                }
            }
            met(k, v, found);
        }
    }

private:
    // The face neighbours (neighbourhood(6)'s bits) connected to face neighbour q by 6-paths
    // through the swept cells of v's cube (`cube`: the cube's layout, bit x + 3 y + 9 z).
    static std::uint32_t face_group(int q, std::uint32_t cube) {
        const std::uint32_t g = face_flood(q, cube);
        std::uint32_t faces = 0;
        for (int f = 0; f < 6; ++f) faces |= ((g >> face_cell[f]) & 1u) << f;
        return faces;
    }
    // The cells of `cube` that 6-paths through it join to face neighbour q's, grown until
    // they stop or hold every face cell of `cube`.
    static std::uint32_t face_flood(int q, std::uint32_t cube) {
        const std::uint32_t faces_swept = cube & face_cells;
        std::uint32_t g = std::uint32_t(1) << face_cell[q];
        for (std::uint32_t n = dilate6(g) & cube; n != g && (g & faces_swept) != faces_swept; n = dilate6(g) & cube)
            g = n;
        return g;
    }
    static constexpr std::uint32_t face_cells = (1u << 4) | (1u << 10) | (1u << 12) | (1u << 14) | (1u << 16) | (1u << 22);
    // The cube's cells within one step of c's along one axis.
    static std::uint32_t dilate6(std::uint32_t c) {
        constexpr std::uint32_t x0 = 0111111111u, x2 = x0 << 2, y0 = 0007007007u, y2 = y0 << 6, all = 0x7ffffffu;
        return (c | ((c << 1) & ~x0) | ((c >> 1) & ~x2) | ((c << 3) & ~y0) | ((c >> 3) & ~y2) | (c << 9) | (c >> 9)) &
               all;
    }
    // The swept neighbours (bits of `swept`) connected to neighbour q through swept neighbours.
    std::uint32_t group_of(int q, std::uint32_t swept) const {
        if (m_ == 26) {
            // In the cube's own layout (bit x + 3 y + 9 z, the centre 13 never set), 26-adjacency
            // is one step along each axis at once: a group grows by whole dilations.
            const std::uint32_t s = cube_bits(swept);
            std::uint32_t g = std::uint32_t(1) << (q < 13 ? q : q + 1);
            // Grown until it stops, or holds every swept neighbour.
            for (std::uint32_t n = dilate(g) & s; n != g && g != s; n = dilate(g) & s) g = n;
            return neighbour_bits(g);
        }
        std::uint32_t group = std::uint32_t(1) << q, frontier = group;
        while (frontier) {
            std::uint32_t reach = 0;
            for (std::uint32_t b = frontier; b; b &= b - 1) reach |= adj_[__builtin_ctz(b)];
            frontier = reach & swept & ~group;
            group |= frontier;
        }
        return group;
    }
    // The 26 neighbours' bits (neighbourhood(26)'s order: the cube's without its centre) in
    // the cube's layout and back.
    static std::uint32_t cube_bits(std::uint32_t b) { return (b & 0x1fffu) | ((b >> 13) << 14); }
    static std::uint32_t neighbour_bits(std::uint32_t c) { return (c & 0x1fffu) | ((c >> 14) << 13); }
    // The cube's cells within one step of c's, along every axis at once.
    static std::uint32_t dilate(std::uint32_t c) {
        constexpr std::uint32_t x0 = 0111111111u, x2 = x0 << 2;  // x = 0, x = 2
        constexpr std::uint32_t y0 = 0007007007u, y2 = y0 << 6;  // y = 0, y = 2
        constexpr std::uint32_t cube = 0x7ffffffu;  // shifts past the cube must not come back
        c |= ((c << 1) & ~x0 & cube) | ((c >> 1) & ~x2);
        c |= ((c << 3) & ~y0 & cube) | ((c >> 3) & ~y2);
        return (c | (c << 9) | (c >> 9)) & cube;
    }
    // Path halving, without the stores that would not change a parent (a child of a root).
    I find(I x) {
        I* const parent = parent_;
        for (I p = parent[x]; p != x; p = parent[x]) {
            const I g = parent[p];
            if (g == p) return p;
            parent[x] = g;
            x = g;
        }
        return x;
    }
    I* parent_;
    std::size_t vertices_;
    std::size_t m_;
    std::vector<std::ptrdiff_t> lin_;
    std::vector<std::uint32_t> adj_;  // adj_[q]: the neighbours adjacent to neighbour q
};

// The 26 neighbours' bits (neighbourhood(26)'s order) in the cube's layout (bit x + 3 y + 9 z).
inline std::uint32_t cube_layout(std::uint32_t b) { return (b & 0x1fffu) | ((b >> 13) << 14); }

// The cells of a vertex's cube (its layout, the centre clear) that precede it, from its mask
// word of the cube connectivity (neighbour_masks: the 6 that precede in bits 0..5, the 26 that
// follow in bits 6..31): the cells inside the grid that do not follow it; a face neighbour
// lies outside the grid where it neither precedes nor follows, and so does its side's slice of
// the cube.
inline std::uint32_t preceding_cube(std::uint32_t w) {
    const std::uint32_t after = cube_layout(w >> 6);
    constexpr std::uint32_t x0 = 0111111111u, y0 = 0007007007u, z0 = 0x1ffu;
    constexpr std::uint32_t side[6] = {z0, y0, x0, x0 << 2, y0 << 6, z0 << 18};  // neighbourhood(6)'s faces
    std::uint32_t inside = 0x7ffffffu & ~(1u << 13), faces = w & 0x3fu;
    for (int q = 0; q < 6; ++q) faces |= ((after >> face_cell[q]) & 1u) << q;
    if (faces != 0x3fu)  // a vertex on the grid's border
        for (int q = 0; q < 6; ++q)
            if (!((faces >> q) & 1u)) inside &= ~side[q];
    return inside & ~after;
}

// The swept-neighbour bits of vertex v = (x, y, z): bit q set when nbrs[q] is inside the grid
// and precedes v in (value, index) order (`precede`), or follows it (!precede); the bits of
// neighbour_masks, one neighbourhood at a time.
struct SweptNeighbours {
    const std::vector<Offset>& nbrs;
    std::vector<std::ptrdiff_t> lin;
    bool precede;

    SweptNeighbours(const Dims& d, const std::vector<Offset>& n, bool forward) : nbrs(n), lin(n.size()), precede(forward) {
        for (std::size_t q = 0; q < n.size(); ++q)
            lin[q] = std::ptrdiff_t(n[q].dx) + std::ptrdiff_t(d.nx) * (n[q].dy + std::ptrdiff_t(d.ny) * n[q].dz);
    }
    template <class T>
    std::uint32_t operator()(const T* f, const Dims& d, std::size_t v, long x, long y, long z) const {
        const T fv = f[v];
        std::uint32_t m = 0;
        const bool interior = x > 0 && y > 0 && z > 0 && x + 1 < long(d.nx) && y + 1 < long(d.ny) && z + 1 < long(d.nz);
        for (std::size_t q = 0; q < nbrs.size(); ++q) {
            if (!interior) {
                const Offset& o = nbrs[q];
                if (x + o.dx < 0 || x + o.dx >= long(d.nx) || y + o.dy < 0 || y + o.dy >= long(d.ny) || z + o.dz < 0 ||
                    z + o.dz >= long(d.nz))
                    continue;
            }
            const T fu = f[std::size_t(std::ptrdiff_t(v) + lin[q])];
            const bool lower = fu < fv || (fu == fv && lin[q] < 0);
            if (lower == precede) m |= std::uint32_t(1) << q;
        }
        return m;
    }
};

// Bit k: whether lo <= p[k] <= hi, for k < n <= 64: one unsigned comparison a value, in a
// type as wide as needed (row_mask).
template <class T> std::uint64_t in_window(const T* p, std::size_t n, long lo, long hi) {
    using W = std::conditional_t<(sizeof(T) < 4), std::uint32_t, std::uint64_t>;
    const W base = W(lo), span = W(hi - lo);
    return row_mask(p, n, [base, span](T x) { return W(W(x) - base) <= span; });
}

// The (value, index) order of integer data built a window at a time, so that memory is
// O(window) instead of O(vertices). The grid is cut into index segments with one value
// histogram each; a window is a run of whole values over every segment, or one value over a
// run of segments (a value with more vertices than a window). Within a window a counting
// sort by value scatters each segment's vertices in index order.
template <class T> class WindowedOrder {
public:
    struct Window {
        std::size_t b0, b1;  // bins (value - vmin) b0..b1
        std::size_t s0, s1;  // segments [s0, s1)
        std::size_t count;
    };

    WindowedOrder(const T* f, std::size_t n, long vmin, long vmax, std::size_t window) : f_(f), n_(n), vmin_(vmin) {
        nbins_ = std::size_t(vmax - vmin + 1);
        // Segment histograms of at most 64 MiB in all; a segment is never larger than a window.
        segments_ = std::clamp<std::size_t>((std::size_t(16) << 20) / nbins_, 1, 64);
        seg_len_ = (n + segments_ - 1) / segments_;
        window_ = std::max(window, seg_len_);
        hist_.assign(segments_ * nbins_, 0);
#pragma omp parallel for schedule(dynamic, 1)
        for (long long s = 0; s < (long long)segments_; ++s) {
            std::uint32_t* h = &hist_[std::size_t(s) * nbins_];
            const std::size_t i1 = std::min(n, std::size_t(s + 1) * seg_len_);
            for (std::size_t i = std::size_t(s) * seg_len_; i < i1; ++i) ++h[std::size_t(long(f[i]) - vmin)];
        }
        plan();
    }

    const std::vector<Window>& windows() const { return windows_; }
    std::size_t largest() const { return largest_; }

    // The vertices of window w in (value, index) order, into out[0, count), and their
    // swept-neighbour bits into swept[0, count) (read in index order: the neighbours are
    // in cache).
    template <class I>
    void collect(const Window& w, const Dims& d, const SweptNeighbours& bits, I* out, std::uint32_t* swept) const {
        const std::size_t nb = w.b1 - w.b0 + 1, ns = w.s1 - w.s0;
        std::vector<std::size_t> next(ns * nb);  // next slot of (segment, bin)
        std::size_t slot = 0;
        for (std::size_t b = 0; b < nb; ++b)
            for (std::size_t s = 0; s < ns; ++s) {
                next[s * nb + b] = slot;
                slot += hist_[(w.s0 + s) * nbins_ + w.b0 + b];
            }
        const long lo = vmin_ + long(w.b0), hi = vmin_ + long(w.b1);
#pragma omp parallel for schedule(dynamic, 1)
        for (long long s = 0; s < (long long)ns; ++s) {
            std::size_t* nxt = &next[std::size_t(s) * nb];
            const std::size_t seg = w.s0 + std::size_t(s);
            const std::size_t i1 = std::min(n_, (seg + 1) * seg_len_);
            std::size_t i = seg * seg_len_;
            long x = long(i % d.nx), y = long((i / d.nx) % d.ny), z = long(i / (d.nx * d.ny));
            // Row by row (x, y, z follow without a division), 64 vertices at a time: which of
            // them the window holds is one comparison each, vectorised into a mask, so that the
            // scan does not branch on every vertex (a window holds a few of them, unpredictably).
            while (i < i1) {
                const std::size_t row_end = std::min(i1, i + (d.nx - std::size_t(x)));
                for (std::size_t c = i; c < row_end; c += 64) {
                    for (std::uint64_t m = in_window(f_ + c, std::min<std::size_t>(64, row_end - c), lo, hi); m; m &= m - 1) {
                        const std::size_t b = std::size_t(__builtin_ctzll(m)), v = c + b;
                        const std::size_t slot = nxt[std::size_t(long(f_[v]) - lo)]++;
                        out[slot] = I(v);
                        swept[slot] = bits(f_, d, v, x + long(c - i + b), y, z);
                    }
                }
                i = row_end, x = 0;
                if (++y == long(d.ny)) y = 0, ++z;
            }
        }
    }

private:
    void plan() {
        Window cur{0, 0, 0, segments_, 0};
        bool open = false;
        auto close = [&] {
            if (open && cur.count) windows_.push_back(cur), largest_ = std::max(largest_, cur.count);
            open = false;
        };
        for (std::size_t b = 0; b < nbins_; ++b) {
            std::size_t total = 0;
            for (std::size_t s = 0; s < segments_; ++s) total += hist_[s * nbins_ + b];
            if (total == 0) continue;
            if (total > window_) {
                // One value over runs of segments.
                close();
                Window part{b, b, 0, 0, 0};
                for (std::size_t s = 0; s < segments_; ++s) {
                    const std::size_t c = hist_[s * nbins_ + b];
                    if (part.count + c > window_) {
                        part.s1 = s;
                        if (part.count) windows_.push_back(part), largest_ = std::max(largest_, part.count);
                        part.s0 = s;
                        part.count = 0;
                    }
                    part.count += c;
                }
                part.s1 = segments_;
                if (part.count) windows_.push_back(part), largest_ = std::max(largest_, part.count);
                continue;
            }
            if (open && cur.count + total > window_) close();
            if (!open) cur = Window{b, b, 0, segments_, 0}, open = true;
            cur.b1 = b;
            cur.count += total;
        }
        close();
    }

    const T* f_;
    std::size_t n_;
    long vmin_;
    std::size_t nbins_ = 0, segments_ = 1, seg_len_ = 0, window_ = 0, largest_ = 0;
    std::vector<std::uint32_t> hist_;  // segments_ x nbins_
    std::vector<Window> windows_;
};

// The links of one sweep between the boundary vertices of a slab (components_slab.hpp): the
// roots that hold a boundary vertex (one bit a vertex), the representative boundary vertex of
// each (an array over the vertices, read at held roots only: with a hash map, a node
// allocated per entry, the 384^3 phantom's slabs of 3.5 Mi vertices took 25.6 CPU seconds
// instead of 17.7), and a link whenever a union joins two
// roots that both hold one. Inactive without an output.
template <class I> class BoundaryLinks {
public:
    BoundaryLinks(const Dims& d, bool first, bool last, std::vector<BoundaryLink>* out)
        : out_(out), first_(first), nxy_(d.nx * d.ny), last_(last ? d.vertices() - nxy_ : std::numeric_limits<std::size_t>::max()) {
        if (!out) return;
        held_.assign((d.vertices() + 63) / 64, 0);
        rep_.resize(d.vertices());
        auto hold = [&](std::size_t i) {
            held_[i / 64] |= std::uint64_t(1) << (i % 64);
            rep_[I(i)] = I(i);
        };
        if (first)
            for (std::size_t i = 0; i < nxy_; ++i) hold(i);
        for (std::size_t i = last_; i < d.vertices(); ++i) hold(i);
    }
    explicit operator bool() const { return out_ != nullptr; }
    // Whether v, not yet swept, holds a boundary vertex: v is one (false without an output).
    bool holds(I v) const { return out_ && ((first_ && std::size_t(v) < nxy_) || std::size_t(v) >= last_); }
    // At the sweep of a vertex of bin `bin()`, the root `child` joins the root `root`.
    template <class Bin> void operator()(I child, I root, Bin&& bin) {
        if (!held(child)) return;
        const I a = rep_[child];
        if (!held(root)) {
            held_[std::size_t(root) / 64] |= std::uint64_t(1) << (std::size_t(root) % 64);
            rep_[root] = a;
        } else {
            out_->push_back({node(a), node(rep_[root]), std::uint32_t(bin())});
        }
    }

private:
    bool held(I v) const { return (held_[std::size_t(v) / 64] >> (std::size_t(v) % 64)) & 1; }
    std::uint32_t node(I v) const {
        return std::uint32_t(std::size_t(v) >= last_ ? nxy_ + (std::size_t(v) - last_) : std::size_t(v));
    }
    std::vector<BoundaryLink>* out_;
    bool first_;
    std::size_t nxy_, last_;
    std::vector<std::uint64_t> held_;
    std::vector<I> rep_;
};

// What a sweep tells its BoundaryLinks (Sweeper::run's `joined`): every union at the sweep of
// a vertex of bin `bin(at)`; told(v): whether v joining its first component must be told with
// that component's root (v a boundary vertex of a slab with links).
template <class I, class Bin> struct LinkHook {
    BoundaryLinks<I>& links;
    Bin& bin;
    void operator()(I at, I child, I root) const {
        if (links) links(child, root, [&] { return bin(at); });
    }
    bool told(I v) const { return links.holds(v); }
};

// Whether the windowed sweeps of `v` may run at once (Tuning::component_sweeps_together):
// when two forests and two window buffers of `largest` vertices (sizeof(I) + 4 bytes each)
// stay within what the whole order may take (sweep_window).
template <class I> bool sweeps_together(bool allowed, const Volume& v, std::size_t largest) {
    if (!allowed) return false;
    const double n = double(v.vertices()), vb = double(v.size_bytes());
    return 2 * double(sizeof(I)) * n + 2 * double(sizeof(I) + 4) * double(largest) + vb <= 3 * vb + double(128 << 20);
}

// Runs a() and b() on two threads and rethrows the first failure.
template <class A, class B> void on_two_threads(A&& a, B&& b) {
    std::exception_ptr failed[2];
#pragma omp parallel sections num_threads(2)
    {
#pragma omp section
        try {
            a();
        } catch (...) {
            failed[0] = std::current_exception();
        }
#pragma omp section
        try {
            b();
        } catch (...) {
            failed[1] = std::current_exception();
        }
    }
    for (const auto& e : failed)
        if (e) std::rethrow_exception(e);
}

// Both sweeps over a windowed order: one after the other with one union-find forest (memory 4
// or 8 bytes per vertex plus a window buffer), or, `together` and where memory allows
// (sweeps_together), at once on two threads with a forest and a window buffer each, the
// split sweep's differences into `delta_split`.
// `join_links` / `split_links` hear of the unions of each (Sweeper::run's `joined`).
template <class T, class I, class Bin, class J, class S>
void windowed_sweeps(const Volume& v, long vmin, long vmax, std::size_t window, bool together,
                     const std::vector<Offset>& a_nbrs, const std::vector<Offset>& c_nbrs, Bin&& bin,
                     std::vector<std::int64_t>& delta, std::vector<std::int64_t>& delta_split, J&& join_links,
                     S&& split_links) {
    const T* f = v.as<T>();
    const Dims d = v.dims();
    const WindowedOrder<T> order(f, v.vertices(), vmin, vmax, window);
    auto prefetch_value = [f](I i) { __builtin_prefetch(&f[i]); };
    auto pass = [&](bool forward, const std::vector<Offset>& nbrs, int sign, std::vector<I>& parent,
                    std::vector<std::int64_t>& out, auto&& joined) {
        std::vector<I> buffer(order.largest());
        std::vector<std::uint32_t> swept(order.largest());
        Sweeper<I> s(d, nbrs, parent.data(), parent.size());
        const SweptNeighbours bits(d, nbrs, forward);
        const auto& ws = order.windows();
        for (std::size_t j = 0; j < ws.size(); ++j) {
            const auto& w = ws[forward ? j : ws.size() - 1 - j];
            order.collect(w, d, bits, buffer.data(), swept.data());
            const std::size_t m = w.count;
            auto at = [&](std::size_t k) { return buffer[forward ? k : m - 1 - k]; };
            s.run(m, at, [&](std::size_t k) { return swept[forward ? k : m - 1 - k]; },
                  [](std::size_t) { return 0u; }, prefetch_value,
                  [&](std::size_t, I i, int found) { out[bin(i)] += sign * found; }, joined);
        }
    };
    // Join sweep: A = {f < s} grows with s; down(v) enters with a minus sign. Split sweep:
    // C = {f >= s} grows as s falls; up(v) enters with a plus sign.
    std::vector<I> parent(v.vertices());
    if (!sweeps_together<I>(together, v, order.largest())) {
        pass(true, a_nbrs, -1, parent, delta, join_links);
        pass(false, c_nbrs, +1, parent, delta, split_links);
        return;
    }
    std::vector<I> split_parent(v.vertices());
    on_two_threads([&] { pass(true, a_nbrs, -1, parent, delta, join_links); },
                   [&] { pass(false, c_nbrs, +1, split_parent, delta_split, split_links); });
}

// `list` (vertex indices in increasing order) and `bins` (theirs) into (value, index) order:
// a stable counting sort by value for 8- and 16-bit integers, one integer sort of (value key,
// index) for other values of at most 32 bits, else a comparison sort. The values are read in
// index order only.
template <class T, class I> void sort_by_value(const T* f, std::vector<I>& list, std::vector<std::uint32_t>& bins) {
    const std::size_t n = list.size();
    if constexpr (std::is_integral<T>::value && sizeof(T) <= 2) {
        constexpr long lowest = long(std::numeric_limits<T>::min());
        std::vector<std::uint32_t> next(std::size_t(1) << (8 * sizeof(T)), 0);
        for (const I i : list) ++next[std::size_t(long(f[i]) - lowest)];
        std::uint32_t sum = 0;
        for (auto& c : next) {
            const std::uint32_t x = c;
            c = sum;
            sum += x;
        }
        std::vector<I> out(n);
        std::vector<std::uint32_t> out_bins(n);
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t slot = next[std::size_t(long(f[list[k]]) - lowest)]++;
            out[slot] = list[k];
            out_bins[slot] = bins[k];
        }
        list.swap(out);
        bins.swap(out_bins);
    } else {
        // (key, index, bin), the key a value's order-preserving 32 bits where it has at most 32.
        struct Entry {
            std::uint64_t key;
            I index;
            std::uint32_t bin;
        };
        std::vector<Entry> e(n);
        for (std::size_t k = 0; k < n; ++k) {
            std::uint64_t key = 0;
            if constexpr (sizeof(T) <= 4) key = order_key(f[list[k]]);
            e[k] = {key, list[k], bins[k]};
        }
        auto by_key = [](const Entry& a, const Entry& b) { return a.key < b.key || (a.key == b.key && a.index < b.index); };
        auto by_value = [f](const Entry& a, const Entry& b) { return f[a.index] < f[b.index]; };
        if constexpr (sizeof(T) <= 4) {
            if (n >= (std::size_t(1) << 22)) __gnu_parallel::sort(e.begin(), e.end(), by_key);
            else std::sort(e.begin(), e.end(), by_key);
        } else {
            std::stable_sort(e.begin(), e.end(), by_value);
        }
        for (std::size_t k = 0; k < n; ++k) list[k] = e[k].index, bins[k] = e[k].bin;
    }
}

// Both sweeps of the whole volume (in one piece), each over its critical vertices only. A
// vertex whose swept neighbours form one group (Sweeper::group) meets one component: it
// changes no count, and, unless a slab's boundary links must hear of it (told), it needs no
// find. Such regular vertices are linked in index order before the sweep, each to a swept
// neighbour (to that neighbour's parent where the neighbour came earlier in index order, so
// that chains stay short), and counted by bin. Every link points to a vertex earlier in the
// sweep, so a swept vertex's chain leads only through swept vertices, into its component.
// The sweep then takes the others (no swept neighbour, several groups, or told) in (value,
// index) order, sorted with their bins (their values read in index order only). The two
// sweeps run on two threads, each with its own forest (4 bytes a vertex), beside the masks
// (4 bytes a vertex, index order) and the critical vertices (12 bytes each). Of the bonsai's
// vertices, 88% are regular in each sweep; of the 384^3 uint16 phantom's, 51% in the join
// sweep and 63% in the split sweep (its slabs' boundary vertices, 2 slices in 9, all critical).
template <class T, class I, class Bin, class J, class S>
void critical_sweeps(const Volume& v, const DeviceVolume* dv, Connectivity mode, Bin&& bin,
                     std::vector<std::int64_t>& delta, std::vector<std::int64_t>& delta_split, J&& join_links,
                     S&& split_links) {
    const int a_adj = mode == Connectivity::cube ? 6 : 14, c_adj = mode == Connectivity::cube ? 26 : 14;
    const std::vector<Offset> a_nbrs = neighbourhood(a_adj), c_nbrs = neighbourhood(c_adj);
    const std::vector<std::uint32_t> mask = neighbour_masks<T>(v, dv, a_adj, c_adj);
    const T* f = v.as<T>();
    const std::size_t n = v.vertices();
    if (delta.size() > std::numeric_limits<std::uint32_t>::max())  // the sorted vertices' bins are 32-bit
        throw InputError("components: at most 2^32 - 2 isovalues");
    auto pass = [&](bool forward, const std::vector<Offset>& nbrs, int shift, int sign, std::vector<std::int64_t>& out,
                    auto&& joined) {
        const std::unique_ptr<I[]> parent(new I[n]);  // every entry set below, in index order
        Sweeper<I> s(v.dims(), nbrs, parent.get(), n);
        const std::uint32_t bits = s.bits();
        const bool cube = forward && mode == Connectivity::cube;  // the join's groups through the cube
        const std::vector<std::ptrdiff_t>& lin = s.offsets();
        std::vector<std::int64_t> regular(out.size(), 0);
        std::vector<I> critical;
        std::vector<std::uint32_t> critical_bins;
        for (std::size_t i = 0; i < n; ++i) {
            const std::uint32_t w = mask[i], swept = (w >> shift) & bits;
            if (swept && !joined.told(I(i))) {
                const int q = __builtin_ctz(swept);
                if (s.one_group(swept, cube ? preceding_cube(w) : 0u)) {
                    const std::size_t u = std::size_t(std::ptrdiff_t(i) + lin[q]);
                    parent[i] = lin[q] < 0 ? parent[u] : I(u);
                    ++regular[bin(I(i))];
                    continue;
                }
            }
            parent[i] = I(i);
            critical.push_back(I(i));
            critical_bins.push_back(std::uint32_t(bin(I(i))));
        }
        sort_by_value(f, critical, critical_bins);
        const std::size_t m = critical.size();
        std::vector<std::uint32_t> words(m);
        for (std::size_t k = 0; k < m; ++k) words[k] = mask[critical[k]];
        auto pos = [&](std::size_t k) { return forward ? k : m - 1 - k; };
        s.run(
            m, [&](std::size_t k) { return critical[pos(k)]; },
            [&](std::size_t k) { return (words[pos(k)] >> shift) & bits; },
            [&](std::size_t k) { return cube ? preceding_cube(words[pos(k)]) : 0u; }, [](I) {},
            [&](std::size_t k, I, int found) { out[critical_bins[pos(k)]] += sign * found; }, joined);
        for (std::size_t b = 0; b < out.size(); ++b) out[b] += sign * regular[b];
    };
    // Join sweep: A = {f < s} grows with s; down(v) enters with a minus sign. Split sweep:
    // C = {f >= s} grows as s falls; up(v) enters with a plus sign.
    on_two_threads([&] { pass(true, a_nbrs, 0, -1, delta, join_links); },
                   [&] { pass(false, c_nbrs, int(a_nbrs.size()), +1, delta_split, split_links); });
}

// Whether the windowed sweeps take integer data of range [vmin, vmax]: when forced
// (Tuning::component_window), or when the critical-vertex sweeps at their largest (the masks
// and two forests, and every vertex sorted by both sweeps: 36 bytes a vertex) would pass 4
// volumes + 128 MiB beside the caller's volume.
template <class T> std::size_t sweep_window(const Context& ctx, const Volume& v, const ValueRange& r) {
    if (!std::is_integral<T>::value || !(r.max - r.min < double(counting_sort_values))) return 0;
    if (ctx.tuning.component_window) return ctx.tuning.component_window;
    const double n = double(v.vertices()), vb = double(v.size_bytes());
    if ((4 + 2 * double(sizeof(std::uint32_t)) + 2 * 12) * n + vb <= 3 * vb + double(128 << 20)) return 0;
    // Windows of an eighth of the volume (a scan of the volume each), 1 Mi to 16 Mi vertices.
    return std::clamp<std::size_t>(v.vertices() / 8, std::size_t(1) << 20, std::size_t(1) << 24);
}

// Where a slab's links and last bins go (count_slab_components); none for a whole volume.
struct SlabOutput {
    SlabComponents* out = nullptr;
    bool first = false, last = false;
};

template <class T, class I>
std::vector<std::int64_t> component_counts(const Context& ctx, const Volume& v, const DeviceVolume* dv,
                                           const IsovalueSet& iso, Connectivity mode, const SlabOutput& slab) {
    const T* f = v.as<T>();
    const std::size_t K = iso.size();
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
    std::vector<std::int64_t> delta(K + 1, 0), delta_split(K + 1, 0);
    // A slab's links (none for a whole volume: the test is all the sweeps pay then).
    SlabComponents* out = slab.out;
    BoundaryLinks<I> join_links(v.dims(), slab.first, slab.last, out ? &out->links.join : nullptr);
    BoundaryLinks<I> split_links(v.dims(), slab.first, slab.last, out ? &out->links.split : nullptr);
    auto hook = [&bin](BoundaryLinks<I>& links) { return LinkHook<I, decltype(bin)>{links, bin}; };
    const ValueRange range = value_range(v);
    if (const std::size_t window = sweep_window<T>(ctx, v, range)) {
        const int a_adj = mode == Connectivity::cube ? 6 : 14, c_adj = mode == Connectivity::cube ? 26 : 14;
        windowed_sweeps<T, I>(v, long(range.min), long(range.max), window, ctx.tuning.component_sweeps_together,
                              neighbourhood(a_adj), neighbourhood(c_adj), bin, delta, delta_split, hook(join_links),
                              hook(split_links));
    } else {
        critical_sweeps<T, I>(v, dv, mode, bin, delta, delta_split, hook(join_links), hook(split_links));
    }
    if (out && slab.last)
        for (std::size_t i = v.vertices() - v.dims().nx * v.dims().ny; i < v.vertices(); ++i)
            out->links.last_bins.push_back(std::uint32_t(bin(I(i))));
    std::vector<std::int64_t> c(K);
    std::int64_t sum = 0;
    for (std::size_t j = 0; j < K; ++j) c[j] = sum += delta[j] + delta_split[j];
    return c;
}


// Whether component_counts would take the windowed sweeps (no device steps then).
bool windowed(const Context& ctx, const Volume& v) {
    return visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        return sweep_window<T>(ctx, v, value_range(v)) != 0;
    });
}

// The links of one sweep of two consecutive runs P and Q (SlabRun) taken in bin order
// (`increasing` for the join sweep) through a union-find over P's first slice (nodes [0, nxy)),
// the shared slice ([nxy, 2 nxy)) and Q's last slice ([2 nxy, 3 nxy)): P's boundary ids are its
// nodes, Q's are shifted by nxy. Each link adds 1 to `diff` at its bin, each union that joins
// two components takes 1 away; the links of P Q as one slab (between its first and last
// slices, `first` / `last`: whether they are shared) come back.
class SeamJoin {
public:
    explicit SeamJoin(std::size_t nxy) : nxy_(nxy), parent_(3 * nxy), rep_(3 * nxy) {}

    std::vector<BoundaryLink> operator()(const std::vector<BoundaryLink>& p, const std::vector<BoundaryLink>& q,
                                         bool increasing, bool first, bool last, std::vector<std::int64_t>& diff) {
        std::iota(parent_.begin(), parent_.end(), std::uint32_t(0));
        // The representative boundary vertex of each root that holds one (none: ~0).
        std::fill(rep_.begin(), rep_.end(), none);
        for (std::uint32_t x = 0; x < nxy_; ++x) {
            if (first) rep_[x] = x;
            if (last) rep_[2 * nxy_ + x] = std::uint32_t(2 * nxy_ + x);
        }
        const auto earlier = [increasing](const BoundaryLink& x, const BoundaryLink& y) {
            return increasing ? x.bin < y.bin : x.bin > y.bin;
        };
        // A sweep gives its links in bin order; anything else is sorted here.
        const std::vector<BoundaryLink>& ps = in_order(p, earlier, p_sorted_);
        const std::vector<BoundaryLink>& qs = in_order(q, earlier, q_sorted_);
        std::vector<BoundaryLink> out;
        std::size_t i = 0, j = 0;
        while (i < ps.size() || j < qs.size()) {
            const bool from_p = j == qs.size() || (i < ps.size() && !earlier(qs[j], ps[i]));
            const BoundaryLink& l = from_p ? ps[i++] : qs[j++];
            const std::uint32_t shift = from_p ? 0 : std::uint32_t(nxy_);
            std::uint32_t ra = find(l.a + shift), rb = find(l.b + shift);
            if (ra == rb) {
                ++diff[l.bin];  // a link whose union the seam already made
                continue;
            }
            if (ra < rb) std::swap(ra, rb);
            parent_[ra] = rb;
            if (rep_[ra] == none) continue;
            if (rep_[rb] == none) rep_[rb] = rep_[ra];
            else out.push_back({node(rep_[ra]), node(rep_[rb]), l.bin});
        }
        return out;
    }

private:
    static constexpr std::uint32_t none = ~std::uint32_t(0);
    template <class Earlier>
    static const std::vector<BoundaryLink>& in_order(const std::vector<BoundaryLink>& links, Earlier&& earlier,
                                                     std::vector<BoundaryLink>& sorted) {
        if (std::is_sorted(links.begin(), links.end(), earlier)) return links;
        sorted = links;
        std::stable_sort(sorted.begin(), sorted.end(), earlier);
        return sorted;
    }
    std::uint32_t find(std::uint32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    // The id of a node of P's first or Q's last slice as a boundary vertex of P Q.
    std::uint32_t node(std::uint32_t x) const { return x < nxy_ ? x : x - std::uint32_t(nxy_); }
    std::size_t nxy_;
    std::vector<std::uint32_t> parent_, rep_;
    std::vector<BoundaryLink> p_sorted_, q_sorted_;
};

}  // namespace

SlabRun::SlabRun(std::size_t isovalues, std::size_t slice_vertices)
    : K_(isovalues), nxy_(slice_vertices), sum_(isovalues, 0), join_(isovalues + 1, 0), split_(isovalues + 1, 0) {}

void SlabRun::append(const std::vector<std::int64_t>& curve, SlabLinks links, bool first, bool last) {
    if (curve.size() != K_) throw std::logic_error("SlabRun: a curve of another isovalue set");
    SlabRun slab(K_, nxy_);
    slab.empty_ = false, slab.first_ = first, slab.last_ = last;
    slab.sum_ = curve;
    slab.links_ = std::move(links);
    append(std::move(slab));
}

void SlabRun::append(SlabRun&& q) {
    if (q.empty_) return;
    if (empty_) {
        *this = std::move(q);
        return;
    }
    if (!last_ || !q.first_ || links_.last_bins.size() != nxy_)
        throw std::logic_error("SlabRun: slabs that do not share a slice");
    for (std::size_t j = 0; j < K_; ++j) sum_[j] += q.sum_[j];
    for (std::size_t b = 0; b <= K_; ++b) join_[b] += q.join_[b], split_[b] += q.split_[b];
    seams_ += q.seams_ + 1;
    // Each shared vertex joins its two copies at its bin: a union in A and one in C.
    for (const std::uint32_t b : links_.last_bins) --join_[b], --split_[b];
    SeamJoin seam(nxy_);
    links_.join = seam(links_.join, q.links_.join, true, first_, q.last_, join_);
    links_.split = seam(links_.split, q.links_.split, false, first_, q.last_, split_);
    links_.last_bins = std::move(q.links_.last_bins);
    last_ = q.last_;
}

std::vector<std::int64_t> SlabRun::curve() const {
    // b0(A) = the slabs' b0(A ∩ S_r) summed + (links in A - unions in A), whose links at bin b
    // lie in A_j for j >= b; likewise C, whose links at bin b lie in C_j for j < b. Each seam
    // adds 1: the slabs' curves each subtract 1, the union's once.
    std::vector<std::int64_t> c(K_);
    std::int64_t below = 0, above = 0;
    for (std::size_t j = 0; j < K_; ++j) c[j] = sum_[j] + seams_ + (below += join_[j]);
    for (std::size_t j = K_; j-- > 0;) c[j] += above += split_[j + 1];
    return c;
}

namespace {

// The curve of `v`, with the device steps on `dv` (the same values) when it is given.
ComponentCurve components_of(Context& ctx, const Volume& v, const DeviceVolume* dv, const IsovalueSet& iso,
                             Connectivity mode, const SlabOutput& slab = {}) {
    const ComputeTimer timer(ctx);
    ComponentCurve c;
    c.isovalues = iso;
    if (!iso.matches(v.type()))
        throw InputError("count_components: the isovalue set does not match the data type");
    if (slab.out) *slab.out = SlabComponents{};
    if (iso.size() > 0 && v.vertices() > 0) {
        c.components = visit(v, [&](const auto* p) {
            using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
            return v.vertices() < std::size_t(0xffffffffu)
                       ? component_counts<T, std::uint32_t>(ctx, v, dv, iso, mode, slab)
                       : component_counts<T, std::uint64_t>(ctx, v, dv, iso, mode, slab);
        });
    }
    c.components.resize(iso.size(), 0);
    c.seconds = timer.seconds();
    return c;
}

// The curve of v in one piece, and its links as a slab into `slab` when it has an output.
ComponentCurve counted_whole(Context& ctx, const Volume& v, const IsovalueSet& iso, Connectivity mode,
                             const SlabOutput& slab) {
    // The device takes the volume in one piece when it fits one allocation (and
    // Tuning::slab_bytes, when set: tests lower it to force the host path).
    const Dims d = v.dims();
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = d.nx * d.ny * value_size(v.type());
    need.memory_divisor = 1;
    const bool fits = v.vertices() > 0 && int_axes(d) && slab_fit(ctx, need) >= d.nz;
    if (!fits || iso.size() == 0 || windowed(ctx, v)) return components_of(ctx, v, nullptr, iso, mode, slab);
    try {
        const DeviceVolume dv(ctx, v);
        return components_of(ctx, v, &dv, iso, mode, slab);
    } catch (const DeviceError& e) {
        // Out of device memory: the host steps, as for a volume larger than the device.
        if (!e.out_of_memory()) throw;
        return components_of(ctx, v, nullptr, iso, mode, slab);
    }
}

// Vertices a slab of the sliced sweeps aims at (slab_step): its order, masks and forest (12
// bytes a vertex, 12 MiB) within reach of the caches and TLB, and a shared slice in every few
// of its own. Measured on the 384^3 uint16 phantom (CPU seconds of the whole curve, 2 cores):
// 1.3 Mi vertices a slab 24.1, 2 Mi 17.7, 3.5 Mi 17.7, 8.3 Mi 18.1, the volume in one piece
// 28.4. 2^20 rather than the fastest 2^21..2^22: each thread's slab holds about 20 bytes a
// vertex beside what `report` holds, and that phantom's report (bound 688 MiB) read a peak of
// 695 MiB at 2^22 and 686 MiB at 2^21.
constexpr std::size_t slab_vertices = std::size_t(1) << 20;

// Slices between the starts of consecutive slabs of the sliced sweeps (each slab holds one
// more, shared with the next), 0 for the volume in one piece: Tuning::component_slab_slices
// when set, else slab_vertices / (nx ny), at least 8: a thinner slab repeats too much of its
// work on its shared slice and its boundary's links (640^3 uint16 phantom, 409,600 vertices a
// slice, two runs each: 4 slices 37.1 and 33.9 s, 8 slices 30.9 and 31.4 s, 16 slices 30.1
// and 35.1 s). One piece when the volume is no larger than two such slabs, has fewer than 3
// slices, or its slices or isovalues pass what the links number (2 nx ny and K + 1 below
// 2^32).
std::size_t slab_step(const Context& ctx, const Volume& v, const IsovalueSet& iso) {
    const Dims d = v.dims();
    const std::size_t nxy = d.nx * d.ny;
    if (d.nz < 3 || iso.size() == 0 || 2 * nxy >= (std::size_t(1) << 32) || iso.size() >= (std::size_t(1) << 32) - 1)
        return 0;
    std::size_t step = ctx.tuning.component_slab_slices;
    if (!step) {
        if (v.vertices() <= 2 * slab_vertices) return 0;
        step = std::max<std::size_t>(8, slab_vertices / nxy);
    }
    return step < d.nz - 1 ? step : 0;
}

// The curve of v (and its links as a slab into `slab`) from z-slabs `step` slices apart, each
// sharing its last slice with the next: counted on the host on every core, each slab's
// order, masks and forest small enough to stay in the caches (the whole volume's, far beyond
// them, make every find a miss), joined slab by slab into runs of consecutive slabs
// (SlabRun), the runs then in z order: exactly the curve of the volume in one piece.
ComponentCurve counted_in_slabs(Context& ctx, const Volume& v, const IsovalueSet& iso, Connectivity mode,
                                const SlabOutput& slab, std::size_t step) {
    const ComputeTimer timer(ctx);
    const Dims d = v.dims();
    const std::size_t nxy = d.nx * d.ny, slabs = (d.nz - 1 + step - 1) / step;
    // A few runs a thread, taken in turn, so that a slow core does not hold the others up.
    const std::size_t runs = std::min<std::size_t>(slabs, 4 * std::size_t(std::max(1, omp_get_max_threads())));
    std::vector<SlabRun> joined(runs, SlabRun(iso.size(), nxy));
    const std::size_t slice = nxy * value_size(v.type());
    auto* values = static_cast<char*>(const_cast<void*>(v.data()));  // read only
    std::exception_ptr failed;
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t k = 0; k < runs; ++k) {
        try {
            for (std::size_t r = slabs * k / runs; r < slabs * (k + 1) / runs; ++r) {
                const std::size_t z0 = r * step, z1 = std::min(d.nz - 1, z0 + step);
                const Volume part = Volume::wrap(values + z0 * slice, Dims{d.nx, d.ny, z1 - z0 + 1}, v.type());
                const bool first = r > 0 || slab.first, last = r + 1 < slabs || slab.last;
                SlabComponents s;
                // The host steps only: the context's queue is not shared between threads.
                const ComponentCurve c = components_of(ctx, part, nullptr, iso, mode, SlabOutput{&s, first, last});
                joined[k].append(c.components, std::move(s.links), first, last);
            }
        } catch (...) {
#pragma omp critical(components_slabs_failure)
            if (!failed) failed = std::current_exception();
        }
    }
    if (failed) std::rethrow_exception(failed);
    for (std::size_t k = 1; k < runs; ++k) joined[0].append(std::move(joined[k]));
    ComponentCurve c;
    c.isovalues = iso;
    c.components = joined[0].curve();
    if (slab.out) {
        *slab.out = SlabComponents{};
        slab.out->links = std::move(joined[0].links());
    }
    c.seconds = timer.seconds();
    return c;
}

// count_components, and a slab's links into `slab` when it has an output: in z-slabs on every
// core (slab_step), else in one piece.
ComponentCurve counted(Context& ctx, const Volume& v, const IsovalueSet& iso, Connectivity mode,
                       const SlabOutput& slab) {
    if (!iso.matches(v.type()))
        throw InputError("count_components: the isovalue set does not match the data type");
    if (const std::size_t step = slab_step(ctx, v, iso)) return counted_in_slabs(ctx, v, iso, mode, slab, step);
    return counted_whole(ctx, v, iso, mode, slab);
}

}  // namespace

ComponentCurve count_components(Context& ctx, const Volume& v, const IsovalueSet& iso, Connectivity mode) {
    return counted(ctx, v, iso, mode, {});
}

SlabComponents count_slab_components(Context& ctx, const Volume& slab, const IsovalueSet& iso, Connectivity mode,
                                     bool first, bool last) {
    const Dims d = slab.dims();
    if (first && last && d.nz < 2) throw std::logic_error("count_slab_components: one slice cannot be shared twice");
    if (2 * d.nx * d.ny >= (std::size_t(1) << 32) || iso.size() >= (std::size_t(1) << 32) - 1)
        throw InputError("components of slabs: at most 2^31 vertices a slice and 2^32 - 2 isovalues");
    SlabComponents s;
    const ComponentCurve c = counted(ctx, slab, iso, mode, SlabOutput{&s, first, last});
    s.components = c.components;
    s.seconds = c.seconds;
    return s;
}

std::vector<std::int64_t> join_slab_components(std::vector<std::int64_t> c, const std::vector<SlabLinks>& slabs,
                                               std::size_t nxy) {
    if (slabs.empty()) throw std::logic_error("join_slab_components: no slabs");
    // The slabs' curves enter as one sum: the first slab carries it, the others none.
    const std::vector<std::int64_t> zero(c.size(), 0);
    SlabRun run(c.size(), nxy);
    for (std::size_t r = 0; r < slabs.size(); ++r)
        run.append(r == 0 ? c : zero, slabs[r], r > 0, r + 1 < slabs.size());
    return run.curve();
}

ComponentCurve count_components(const DeviceVolume& v, const IsovalueSet& iso, Connectivity mode) {
    const Volume host = v.download();
    if (const std::size_t step = slab_step(v.context(), host, iso))
        return counted_in_slabs(v.context(), host, iso, mode, {}, step);
    return components_of(v.context(), host, &v, iso, mode);
}

}  // namespace clfractal
