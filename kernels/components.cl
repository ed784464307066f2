// Value histogram for the counting sort of the component sweeps (components.hpp).
// Integer data only: bin = value - vmin, nbins = vmax - vmin + 1 bins of 32-bit counts
// (the host uses this kernel only below 2^32 vertices).
//
// Each work-item counts a contiguous chunk of `chunk` values. With LOCAL_HIST (the
// histogram fits in local memory) a work-group first counts into local memory, then adds
// its histogram to the global one; otherwise every value is a global atomic increment.
// Global size: a multiple of the work-group size WG; hist must be zeroed. The local
// loops run a fixed number of rounds (PoCL's work-group loops want uniform trip counts
// around barriers).
__kernel void value_histogram(__global const T* restrict values, ulong n, ulong chunk, long vmin, uint nbins,
                              __global volatile uint* restrict hist
#ifdef LOCAL_HIST
                              , __local volatile uint* restrict local_hist
#endif
                              ) {
    const ulong begin = get_global_id(0) * chunk;
    const ulong end = min(n, begin + chunk);
#ifdef LOCAL_HIST
    const uint lid = get_local_id(0);
    for (uint r = 0; r < (nbins + WG - 1) / WG; ++r) {
        const uint b = r * WG + lid;
        if (b < nbins) local_hist[b] = 0;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (ulong i = begin; i < end; ++i) atomic_inc(&local_hist[(long)values[i] - vmin]);
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint r = 0; r < (nbins + WG - 1) / WG; ++r) {
        const uint b = r * WG + lid;
        if (b < nbins && local_hist[b]) atomic_add(&hist[b], local_hist[b]);
    }
#else
    for (ulong i = begin; i < end; ++i) atomic_inc(&hist[(long)values[i] - vmin]);
#endif
}

// Neighbourhood gathering for the two sweeps: for every vertex v, which neighbours come
// before it in the join sweep (A's neighbourhood, (f(u), u) < (f(v), v)) and which in the
// split sweep (C's neighbourhood, (f(u), u) > (f(v), v)). Bit q < A_COUNT: the q-th offset
// of A's neighbourhood; bit A_COUNT + q: the q-th offset of C's. Offsets are enumerated
// dz, dy, dx = -1..1 (x fastest), exactly as the host enumerates them. Adjacency per set:
// ADJ_A, ADJ_C in {6, 14, 26}; A_COUNT + C_COUNT <= 32.
// Global size (nx rounded up to the work-group width, ny, nz). Built only with A_COUNT.
#if defined(A_COUNT) || defined(LABEL_A)
// Whether offset (dx, dy, dz) joins two vertices of a set whose adjacency is `adj`.
inline bool in_adjacency(int adj, int dx, int dy, int dz) {
    const int n = abs(dx) + abs(dy) + abs(dz);
    if (adj == 6) return n == 1;
    if (adj == 26) return true;
    return !(min(dx, min(dy, dz)) < 0 && max(dx, max(dy, dz)) > 0);  // 14: no mixed signs
}
#endif

#ifdef A_COUNT
__kernel void neighbour_masks(__global const T* restrict f, int nx, int ny, int nz,
                              __global uint* restrict mask) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    if (x >= nx) return;
    const ulong v = (ulong)x + (ulong)nx * ((ulong)y + (ulong)ny * (ulong)z);
    const T fv = f[v];
    uint m = 0;
    int qa = 0, qc = A_COUNT;
#pragma unroll
    for (int dz = -1; dz <= 1; ++dz)
#pragma unroll
        for (int dy = -1; dy <= 1; ++dy)
#pragma unroll
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0 && dz == 0) continue;
                const bool in_a = in_adjacency(ADJ_A, dx, dy, dz), in_c = in_adjacency(ADJ_C, dx, dy, dz);
                if (!in_a && !in_c) continue;
                const bool inside = x + dx >= 0 && x + dx < nx && y + dy >= 0 && y + dy < ny &&
                                    z + dz >= 0 && z + dz < nz;
                bool lower = false;
                if (inside) {
                    const long o = (long)dx + (long)nx * ((long)dy + (long)ny * (long)dz);
                    const T fu = f[(ulong)((long)v + o)];
                    lower = fu < fv || (fu == fv && o < 0);
                    if (in_a && lower) m |= 1u << qa;
                    if (in_c && !lower) m |= 1u << qc;
                }
                qa += in_a;
                qc += in_c;
            }
    mask[v] = m;
}
#endif  // A_COUNT

// Labelling of A = {f < s} and C = {f >= s} at one isovalue s (count_components_at on the
// device): union-find over the runs of each set along x, in three kernels an isovalue.
//   label_runs   every vertex gets the index of the first vertex of its run (the run's root);
//   join_runs    each run is joined to the runs of the same set it touches in the rows before
//                it (dz = -1, or dz = 0 and dy = -1) under that set's adjacency (LABEL_A,
//                LABEL_C in {6, 14, 26}), by union-find on the run starts' labels;
//   count_roots  the roots left in A and in C: b0(A) and b0(C).
// Labels are vertex indices in uint (the host calls these kernels below 2^32 vertices). A
// label only ever falls, to a smaller index of the same component, so every run start's
// parent chain ends at its component's smallest run start, whatever order the unions take:
// the counts are deterministic. During join_runs only run starts' labels change, always
// through atomics (atomic_min to link, atomic_or(p, 0) to read), so there is no plain access
// to a label another work-item writes; the other labels are read plainly and never written.
// Launch: one work-item a row (y, z), row r = y + ny * z; global size rows rounded up to the
// work-group size (items past the rows return). Built with single_isovalue_options (iso_t).
#ifdef LABEL_A
inline bool in_a(T v, iso_t s) { return v < s; }

__kernel void label_runs(__global const T* restrict f, uint nx, uint rows, iso_t s, __global uint* restrict labels) {
    const uint r = get_global_id(0);
    if (r >= rows) return;
    const uint row = r * nx;  // below 2^32 vertices: no wrap
    uint start = row;
    bool set = in_a(f[row], s);
    for (uint x = 0; x < nx; ++x) {
        const bool here = in_a(f[row + x], s);
        if (here != set) start = row + x, set = here;
        labels[row + x] = start;
    }
}

// The label of run start x, read atomically (it may be changing).
inline uint label_of(volatile __global uint* labels, uint x) { return atomic_or(&labels[x], 0u); }

inline uint root_of(volatile __global uint* labels, uint x) {
    for (uint p = label_of(labels, x); p != x; p = label_of(labels, x)) x = p;
    return x;
}

// Joins the components of run starts a and b: the larger root is linked under the smaller by
// atomic_min. When another work-item linked that root first, atomic_min may have cut it from
// its new parent `old`, so the loop joins `old` with the smaller root in turn.
inline void unite(volatile __global uint* labels, uint a, uint b) {
    for (;;) {
        a = root_of(labels, a), b = root_of(labels, b);
        if (a == b) return;
        const uint lo = min(a, b), hi = max(a, b);
        const uint old = atomic_min(&labels[hi], lo);
        if (old == hi) return;
        a = lo, b = old;
    }
}

__kernel void join_runs(__global const T* restrict f, uint nx, uint ny, uint nz, iso_t s,
                        volatile __global uint* labels) {
    const uint r = get_global_id(0);
    if (r >= ny * nz) return;
    const int y = (int)(r % ny), z = (int)(r / ny);
    const uint row = r * nx;
    // Bit k of `met`: link k (the k-th backward offset) met the same set at x - 1. When it did
    // and this vertex continues the run of x - 1, the neighbour continues its run too: the two
    // runs are joined already.
    uint met = 0, start = row;
    bool set = in_a(f[row], s);
    for (uint x = 0; x < nx; ++x) {
        const uint v = row + x;
        const bool here = in_a(f[v], s);
        const bool continues = x > 0 && here == set;
        if (!continues) start = v;
        set = here;
        const int adj = here ? LABEL_A : LABEL_C;
        uint now = 0;
        int k = 0;
        for (int dz = -1; dz <= 0; ++dz)
            for (int dy = -1; dy <= 1; ++dy) {
                if (dz == 0 && dy >= 0) continue;
                const int yy = y + dy, zz = z + dz;
                const bool row_inside = yy >= 0 && yy < (int)ny && zz >= 0;
                for (int dx = -1; dx <= 1; ++dx, ++k) {
                    const int xx = (int)x + dx;
                    if (!row_inside || xx < 0 || xx >= (int)nx || !in_adjacency(adj, dx, dy, dz)) continue;
                    const uint u = ((uint)zz * ny + (uint)yy) * nx + (uint)xx;
                    if (in_a(f[u], s) != here) continue;
                    now |= 1u << k;
                    if (continues && (met >> k & 1)) continue;
                    // u's run start: u itself, else the label label_runs gave it (never changed).
                    const bool u_starts = xx == 0 || in_a(f[u - 1], s) != here;
                    unite(labels, start, u_starts ? u : ((__global const uint*)labels)[u]);
                }
            }
        met = now;
    }
}

// roots[2 j] += the roots of A in the rows, roots[2 j + 1] += those of C.
__kernel void count_roots(__global const T* restrict f, uint nx, uint rows, iso_t s,
                          __global const uint* restrict labels, volatile __global uint* roots, uint j) {
    const uint r = get_global_id(0);
    if (r >= rows) return;
    const uint row = r * nx;
    uint a = 0, c = 0;
    for (uint v = row; v < row + nx; ++v)
        if (labels[v] == v) {
            if (in_a(f[v], s)) ++a;
            else ++c;
        }
    if (a) atomic_add(&roots[2 * j], a);
    if (c) atomic_add(&roots[2 * j + 1], c);
}
#endif  // LABEL_A
