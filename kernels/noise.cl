// Reproducible noise (include/clfractal/noise.hpp): every vertex's draw is a pure function
// of the seed and its global index, so every device, slab split and run gives the same
// values. One work-item per vertex of a slab; `first` is the global index of the slab's
// first vertex; the global size is the slab's vertex count.
//
// Defines: T (input type); GAUSSIAN (Box-Muller) or uniform; KEEP_TYPE with OUT_T, OUT_MIN,
// OUT_MAX (round half away from zero, clamp, convert) or float32 output.
//
// The result is float(value) + amplitude * draw, one float multiply and one float add,
// each correctly rounded (IEEE); with -DNOISE_DOUBLE (int32, uint32 and float64 input,
// whose values a float does not hold) the add is double(value) + double(amplitude * draw).
// Contraction into fused multiply-adds is switched off so that the host reproduces every
// value bit for bit.
#pragma OPENCL FP_CONTRACT OFF

#ifndef OUT_T
#define OUT_T float
#endif

// splitmix64_mix, counter_bits, box_muller, uniform_draw and gaussian_draw, shared with the
// host (host/measures/noise.cpp, host/volume/synthetic.cpp); put in place by
// cmake/embed_kernels.cmake.
#include "counter_rng.h"

inline float noise_draw(ulong mixed_seed, ulong index) {
#ifdef GAUSSIAN
    return gaussian_draw(mixed_seed, index);
#else
    return uniform_draw(mixed_seed, index);
#endif
}

__kernel void add_noise(__global const T* restrict in, __global OUT_T* restrict out, ulong first,
                        ulong mixed_seed, float amplitude) {
    const size_t i = get_global_id(0);
#ifdef NOISE_DOUBLE
    const float product = amplitude * noise_draw(mixed_seed, first + i);
    const double noisy = (double)in[i] + (double)product;
#else
    const float noisy = (float)in[i] + amplitude * noise_draw(mixed_seed, first + i);
#endif
#ifdef KEEP_TYPE
    out[i] = (OUT_T)clamp(round(noisy), OUT_MIN, OUT_MAX);
#else
    out[i] = noisy;
#endif
}
