// Value histogram for the counting sort of the component sweeps (components.hpp).
// 8/16-bit data only: bin = value - vmin, nbins = vmax - vmin + 1 bins of 32-bit counts
// (the host uses this kernel only below 2^32 vertices).
//
// Each work-item counts a contiguous chunk of `chunk` values. With LOCAL_HIST (the
// histogram fits in local memory) a work-group first counts into local memory, then adds
// its histogram to the global one; otherwise every value is a global atomic increment.
// Global size: a multiple of the work-group size WG; hist must be zeroed. The local
// loops run a fixed number of rounds (PoCL's work-group loops want uniform trip counts
// around barriers).
__kernel void value_histogram(__global const T* restrict values, ulong n, ulong chunk, int vmin, uint nbins,
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
    for (ulong i = begin; i < end; ++i) atomic_inc(&local_hist[(int)values[i] - vmin]);
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint r = 0; r < (nbins + WG - 1) / WG; ++r) {
        const uint b = r * WG + lid;
        if (b < nbins && local_hist[b]) atomic_add(&hist[b], local_hist[b]);
    }
#else
    for (ulong i = begin; i < end; ++i) atomic_inc(&hist[(int)values[i] - vmin]);
#endif
}
