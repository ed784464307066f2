// Span histograms (docs/definitions.md §7 "Counts"): every cube (or grid edge) with span [a, b]
// adds +1 at bin first_isovalue_above(a) and -1 at first_isovalue_above(b); the
// prefix sum of the histogram is I(s) (or E(s)) for every isovalue at once.
//
// The input is one z-slab of nx * ny * nzs vertices. Cubes: every cube of the slab.
// Edges: x- and y-edges of slices [0, nzs - 1), plus those of slice nzs - 1 when
// LAST_SLAB is set (the next slab starts with that slice), and z-edges between
// consecutive slices.
//
// Two variants, chosen per device (Tuning::span_variant):
//  - *_private (CPUs): work-item i owns the four histogram rows 4i .. 4i + 3 of `partial`
//    and walks whole x-rows with plain increments, cube x into row 4i + x % 4 (four
//    independent chains of increments where neighbouring cubes hit the same bins; edges use
//    the first row only); cube min/max reuse the column min/max of the previous x. Run with
//    local size 1 and a few work-items per core.
//  - *_atomic (GPUs): one work-item per cube in a grid-stride loop; the work-group
//    accumulates with atomics in a local-memory histogram (`lh`, nbins * 4 bytes) and
//    writes it to its row of `partial`; with -DGLOBAL_HIST (too many bins for local
//    memory) it accumulates with global atomics straight into its row of `partial`,
//    which the host has zeroed.
// Partial counts are 32-bit: the host keeps a slab below 2^29 vertices.

#define ADD_SPAN(h, lo, hi)                                                  \
    do {                                                                     \
        int ba_ = first_isovalue_above((lo), vmin, iso, niso);              \
        int bb_ = first_isovalue_above((hi), vmin, iso, niso);              \
        if (ba_ != bb_) { h[ba_] += 1; h[bb_] -= 1; }                        \
    } while (0)

#ifdef GLOBAL_HIST
#define HIST_BEGIN __global int* hh = partial + get_group_id(0) * (size_t)nbins;
#define HIST_END
#else
#define HIST_BEGIN                                                           \
    for (int i = get_local_id(0); i < nbins; i += get_local_size(0)) lh[i] = 0; \
    barrier(CLK_LOCAL_MEM_FENCE);                                            \
    __local int* hh = lh;
#define HIST_END                                                             \
    barrier(CLK_LOCAL_MEM_FENCE);                                            \
    __global int* out = partial + get_group_id(0) * (size_t)nbins;          \
    for (int i = get_local_id(0); i < nbins; i += get_local_size(0)) out[i] = lh[i];
#endif

#define ADD_SPAN_ATOMIC(h, lo, hi)                                           \
    do {                                                                     \
        int ba_ = first_isovalue_above((lo), vmin, iso, niso);              \
        int bb_ = first_isovalue_above((hi), vmin, iso, niso);              \
        if (ba_ != bb_) { atomic_inc(&h[ba_]); atomic_dec(&h[bb_]); }        \
    } while (0)

// Cubes of one x-row are handled in chunks of CHUNK: column min/max of the 4 vertex
// rows first, then the cube spans' bins, then the histogram updates. The first two
// loops vectorise; keeping them apart from the scattered stores also spares reloads.
// (PoCL on a 2-core Xeon, 512^3 uint8: chunks of 256 cubes count 14% faster than of 64,
// 512 no faster.)
#define CHUNK 256
__kernel void count_cubes_private(__global const T* restrict vol, int nx, int ny, int nzs,
                                  long vmin, __global const ISO_T* restrict iso, int niso,
                                  int nbins, __global int* restrict partial) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    __global int* h = partial + 4 * item * (size_t)nbins;
    __global int* h1 = h + nbins;
    __global int* h2 = h1 + nbins;
    __global int* h3 = h2 + nbins;
    const size_t rows = (size_t)(ny - 1) * (size_t)(nzs - 1);
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
    const size_t slice = (size_t)nx * ny;
    T mn[CHUNK + 1], mx[CHUNK + 1];
    int lo[CHUNK], hi[CHUNK];
    for (size_t r = r0; r < r1; ++r) {
        const size_t y = r % (size_t)(ny - 1), z = r / (size_t)(ny - 1);
        __global const T* p00 = vol + z * slice + y * (size_t)nx;
        __global const T* p10 = p00 + nx;
        __global const T* p01 = p00 + slice;
        __global const T* p11 = p01 + nx;
        for (int x0 = 0; x0 < nx - 1; x0 += CHUNK) {
            const int n = min(CHUNK, nx - 1 - x0);
            for (int i = 0; i <= n; ++i) {
                const int x = x0 + i;
                mn[i] = min(min(p00[x], p10[x]), min(p01[x], p11[x]));
                mx[i] = max(max(p00[x], p10[x]), max(p01[x], p11[x]));
            }
            for (int i = 0; i < n; ++i) {
                lo[i] = first_isovalue_above(min(mn[i], mn[i + 1]), vmin, iso, niso);
                hi[i] = first_isovalue_above(max(mx[i], mx[i + 1]), vmin, iso, niso);
            }
            int i = 0;
            for (; i + 3 < n; i += 4) {
                if (lo[i] != hi[i]) {
                    h[lo[i]] += 1;
                    h[hi[i]] -= 1;
                }
                if (lo[i + 1] != hi[i + 1]) {
                    h1[lo[i + 1]] += 1;
                    h1[hi[i + 1]] -= 1;
                }
                if (lo[i + 2] != hi[i + 2]) {
                    h2[lo[i + 2]] += 1;
                    h2[hi[i + 2]] -= 1;
                }
                if (lo[i + 3] != hi[i + 3]) {
                    h3[lo[i + 3]] += 1;
                    h3[hi[i + 3]] -= 1;
                }
            }
            for (; i < n; ++i)
                if (lo[i] != hi[i]) {
                    h[lo[i]] += 1;
                    h[hi[i]] -= 1;
                }
        }
    }
}

// Bins of the spans of the n edges (a[i], b[i]), i < n, then the histogram updates.
#define ADD_EDGE_CHUNK(a, b, n)                                                  \
    do {                                                                         \
        for (int i = 0; i < (n); ++i) {                                          \
            lo[i] = first_isovalue_above(min((a)[i], (b)[i]), vmin, iso, niso);  \
            hi[i] = first_isovalue_above(max((a)[i], (b)[i]), vmin, iso, niso);  \
        }                                                                        \
        for (int i = 0; i < (n); ++i)                                            \
            if (lo[i] != hi[i]) {                                                \
                h[lo[i]] += 1;                                                   \
                h[hi[i]] -= 1;                                                   \
            }                                                                    \
    } while (0)

__kernel void count_edges_private(__global const T* restrict vol, int nx, int ny, int nzs, int last_slab,
                                  long vmin, __global const ISO_T* restrict iso, int niso,
                                  int nbins, __global int* restrict partial) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    __global int* h = partial + 4 * item * (size_t)nbins;
    const size_t zrows = last_slab ? (size_t)nzs : (size_t)(nzs - 1);
    const size_t rows = (size_t)ny * zrows;
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
    const size_t slice = (size_t)nx * ny;
    int lo[CHUNK], hi[CHUNK];
    for (size_t r = r0; r < r1; ++r) {
        const size_t y = r % (size_t)ny, z = r / (size_t)ny;
        __global const T* p = vol + z * slice + y * (size_t)nx;
        const bool has_y = y + 1 < (size_t)ny, has_z = z + 1 < (size_t)nzs;
        for (int x0 = 0; x0 < nx; x0 += CHUNK) {
            const int n = min(CHUNK, nx - x0);
            __global const T* c = p + x0;
            ADD_EDGE_CHUNK(c, c + 1, min(n, nx - 1 - x0));
            if (has_y) ADD_EDGE_CHUNK(c, c + nx, n);
            if (has_z) ADD_EDGE_CHUNK(c, c + slice, n);
        }
    }
}

__kernel void count_cubes_atomic(__global const T* vol, int nx, int ny, int nzs,
                                long vmin, __global const ISO_T* iso, int niso,
                                int nbins, __global int* partial, __local int* lh) {
    HIST_BEGIN
    const size_t cx = (size_t)(nx - 1), cy = (size_t)(ny - 1);
    const size_t cubes = cx * cy * (size_t)(nzs - 1);
    const size_t slice = (size_t)nx * ny;
    for (size_t c = get_global_id(0); c < cubes; c += get_global_size(0)) {
        const size_t x = c % cx, t = c / cx, y = t % cy, z = t / cy;
        __global const T* p = vol + z * slice + y * (size_t)nx + x;
        T a = min(min(min(p[0], p[1]), min(p[nx], p[nx + 1])),
                  min(min(p[slice], p[slice + 1]), min(p[slice + nx], p[slice + nx + 1])));
        T b = max(max(max(p[0], p[1]), max(p[nx], p[nx + 1])),
                  max(max(p[slice], p[slice + 1]), max(p[slice + nx], p[slice + nx + 1])));
        ADD_SPAN_ATOMIC(hh, a, b);
    }
    HIST_END
}

__kernel void count_edges_atomic(__global const T* vol, int nx, int ny, int nzs, int last_slab,
                                long vmin, __global const ISO_T* iso, int niso,
                                int nbins, __global int* partial, __local int* lh) {
    HIST_BEGIN
    const size_t zrows = last_slab ? (size_t)nzs : (size_t)(nzs - 1);
    const size_t slice = (size_t)nx * ny;
    const size_t vertices = slice * zrows;
    for (size_t v = get_global_id(0); v < vertices; v += get_global_size(0)) {
        const size_t x = v % (size_t)nx, t = v / (size_t)nx, y = t % (size_t)ny, z = t / (size_t)ny;
        __global const T* p = vol + v;
        const T f = p[0];
        if (x + 1 < (size_t)nx) ADD_SPAN_ATOMIC(hh, min(f, p[1]), max(f, p[1]));
        if (y + 1 < (size_t)ny) ADD_SPAN_ATOMIC(hh, min(f, p[nx]), max(f, p[nx]));
        if (z + 1 < (size_t)nzs) ADD_SPAN_ATOMIC(hh, min(f, p[slice]), max(f, p[slice]));
    }
    HIST_END
}

// hist[i] += sum over the `rows` rows of partial[row][i]; one work-item per bin.
__kernel void accumulate_partials(__global const int* partial, int rows, int nbins,
                                  __global long* hist) {
    const int i = get_global_id(0);
    if (i >= nbins) return;
    long s = 0;
    for (int r = 0; r < rows; ++r) s += partial[(size_t)r * nbins + i];
    hist[i] += s;
}
