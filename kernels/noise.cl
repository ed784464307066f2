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

// splitmix64's output function (as host/volume/counter_rng.hpp).
inline ulong splitmix64_mix(ulong z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9UL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBUL;
    return z ^ (z >> 31);
}

// Draw `counter` of the stream whose scrambled seed is `mixed_seed` = splitmix64_mix(seed).
inline ulong noise_bits(ulong mixed_seed, ulong counter) {
    return splitmix64_mix(mixed_seed + (counter + 1) * 0x9E3779B97F4A7C15UL);
}

// Box-Muller from two 24-bit integers, k1 in [1, 2^24] (u1 = k1 2^-24 in (0, 1]) and k2 in
// [0, 2^24) (u2 = k2 2^-24): sqrt(-2 ln u1) cos(2 pi u2), with float additions and
// multiplications only (polynomials, a Newton square root), so that every IEEE device and
// the host (host/measures/noise.cpp, the same operations in the same order) give the same bits.
//   ln u1 = (e - 24) ln 2 + ln m, k1 = m 2^e with m in [sqrt(1/2), sqrt(2)] (exact scaling),
//           ln m = s P(s), s = m - 1 (exact), P a degree-10 fit of ln(1 + s) / s;
//   sqrt x = x y, y = 1 / sqrt(x) from the bit-pattern guess and three Newton steps;
//   cos(2 pi u2): quadrant q = k2 >> 22 and f = (k2 & (2^22 - 1)) 2^-22 (exact), then
//           cos(pi/2 f) = C(f^2) and sin(pi/2 f) = f S(f^2), degree-6 fits.
// Error against double precision: below 3e-6 (tested).
inline float box_muller(uint k1, uint k2) {
    int e = 31 - (int)clz(k1);
    float m = (float)k1 * as_float((uint)(127 - e) << 23);
    if (m > 0x1.6a09e6p+0f) {
        m = m * 0.5f;
        e = e + 1;
    }
    const float s = m - 1.0f;
    float lp = 0x1.141484p-4f;
    lp = lp * s + -0x1.e058fp-4f;
    lp = lp * s + 0x1.e8676ap-4f;
    lp = lp * s + -0x1.fbdf4p-4f;
    lp = lp * s + 0x1.2313p-3f;
    lp = lp * s + -0x1.555c8cp-3f;
    lp = lp * s + 0x1.99a71cp-3f;
    lp = lp * s + -0x1.00001p-2f;
    lp = lp * s + 0x1.55554p-2f;
    lp = lp * s + -0x1p-1f;
    lp = lp * s + 0x1p+0f;
    const float ln_u1 = (float)(e - 24) * 0x1.62e43p-1f + s * lp;
    const float x = -2.0f * ln_u1;
    float y = as_float(0x5f3759dfu - (as_uint(x) >> 1));
    for (int i = 0; i < 3; ++i) y = y * (1.5f - 0.5f * x * y * y);
    const float radius = x * y;
    const uint q = k2 >> 22;
    const float f = (float)(k2 & 0x3fffffu) * 0x1p-22f;
    const float t = f * f;
    float cp = 0x1.e259a6p-22f;
    cp = cp * t + -0x1.a651ccp-16f;
    cp = cp * t + 0x1.e1f24ep-11f;
    cp = cp * t + -0x1.55d3cp-6f;
    cp = cp * t + 0x1.03c1fp-2f;
    cp = cp * t + -0x1.3bd3ccp+0f;
    cp = cp * t + 0x1p+0f;
    float sp = 0x1.d5467cp-25f;
    sp = sp * t + -0x1.e29c04p-19f;
    sp = sp * t + 0x1.507712p-13f;
    sp = sp * t + -0x1.32d2cap-8f;
    sp = sp * t + 0x1.466bc6p-4f;
    sp = sp * t + -0x1.4abbcep-1f;
    sp = sp * t + 0x1.921fb6p+0f;
    const float sine = sp * f;
    const float c = q == 0 ? cp : q == 1 ? -sine : q == 2 ? -cp : sine;
    return radius * c;
}

inline float noise_draw(ulong mixed_seed, ulong index) {
#ifdef GAUSSIAN
    const ulong c = 0x4000000000000000UL + 2 * index;  // 2^62 + 2 index, 2^62 + 2 index + 1
    return box_muller((uint)(noise_bits(mixed_seed, c) >> 40) + 1u, (uint)(noise_bits(mixed_seed, c + 1) >> 40));
#else
    return (float)((int)(noise_bits(mixed_seed, index) >> 40) - 0x800000) * 0x1p-23f;  // [-1, 1)
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
