// Reproducible noise (include/clfractal/noise.hpp): every vertex's draw is a pure function
// of the seed and its global index, so every device, slab split and run gives the same
// values. One work-item per vertex of a slab; `first` is the global index of the slab's
// first vertex; the global size is the slab's vertex count.
//
// Defines: T (input type); GAUSSIAN (Box-Muller) or uniform; KEEP_TYPE with OUT_T, OUT_MIN,
// OUT_MAX (round half away from zero, clamp, convert) or float32 output.
//
// The result is float(value) + amplitude * draw, one float multiply and one float add,
// each correctly rounded (IEEE); contraction into a fused multiply-add is switched off so
// the host reproduces the uniform case bit for bit.
#pragma OPENCL FP_CONTRACT OFF

#ifndef OUT_T
#define OUT_T float
#endif

// splitmix64's output function (as host/synthetic.cpp).
inline ulong splitmix64_mix(ulong z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9UL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBUL;
    return z ^ (z >> 31);
}

// Draw `counter` of the stream whose scrambled seed is `mixed_seed` = splitmix64_mix(seed).
inline ulong noise_bits(ulong mixed_seed, ulong counter) {
    return splitmix64_mix(mixed_seed + (counter + 1) * 0x9E3779B97F4A7C15UL);
}

inline float noise_draw(ulong mixed_seed, ulong index) {
#ifdef GAUSSIAN
    const ulong c = 0x4000000000000000UL + 2 * index;  // 2^62 + 2 index, 2^62 + 2 index + 1
    const float u1 = (float)((uint)(noise_bits(mixed_seed, c) >> 40) + 1u) * 0x1p-24f;  // (0, 1]
    const float u2 = (float)(uint)(noise_bits(mixed_seed, c + 1) >> 40) * 0x1p-24f;     // [0, 1)
    return sqrt(-2.0f * log(u1)) * cospi(2.0f * u2);
#else
    return (float)((int)(noise_bits(mixed_seed, index) >> 40) - 0x800000) * 0x1p-23f;  // [-1, 1)
#endif
}

__kernel void add_noise(__global const T* restrict in, __global OUT_T* restrict out, ulong first,
                        ulong mixed_seed, float amplitude) {
    const size_t i = get_global_id(0);
    const float noisy = (float)in[i] + amplitude * noise_draw(mixed_seed, first + i);
#ifdef KEEP_TYPE
    out[i] = (OUT_T)clamp(round(noisy), (float)OUT_MIN, (float)OUT_MAX);
#else
    out[i] = noisy;
#endif
}
