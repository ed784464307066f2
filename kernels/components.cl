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
#ifdef A_COUNT
inline bool in_adjacency(int adj, int dx, int dy, int dz) {
    const int n = abs(dx) + abs(dy) + abs(dz);
    if (adj == 6) return n == 1;
    if (adj == 26) return true;
    return !(min(dx, min(dy, dz)) < 0 && max(dx, max(dy, dz)) > 0);  // 14: no mixed signs
}

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
