// The counter-based generator behind synthetic noise and noise injection (seed + vertex
// index -> the same value on every device and for every slab split), and the Box-Muller
// transform of the Gaussian noise: one text, compiled as C++ by the host (included as
// "kernels/counter_rng.h", in namespace clfractal::detail) and as OpenCL C by the kernels
// (cmake/embed_kernels.cmake puts it where kernels/noise.cl includes it), so that both give
// the same bits. The float operations are plain IEEE multiplies and adds in a fixed order,
// never contracted into fused multiply-adds (the host file that includes the Box-Muller is
// compiled with -ffp-contract=off, the kernels switch contraction off below).
#ifndef CLFRACTAL_COUNTER_RNG_H
#define CLFRACTAL_COUNTER_RNG_H

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#define CLF_FN inline
#define CLF_U32 uint
#define CLF_U64 ulong
#define CLF_U64_C(x) x##UL
#define CLF_CLZ(x) clz(x)
#define CLF_AS_FLOAT(x) as_float(x)
#define CLF_AS_U32(x) as_uint(x)
#else
#include <cstdint>
#include <cstring>
// Internal linkage: each translation unit keeps its own copy, compiled with its own
// floating-point options.
#define CLF_FN static inline
#define CLF_U32 std::uint32_t
#define CLF_U64 std::uint64_t
#define CLF_U64_C(x) x##ULL
#define CLF_CLZ(x) __builtin_clz(x)
#define CLF_AS_FLOAT(x) clfractal::detail::bits_to_float(x)
#define CLF_AS_U32(x) clfractal::detail::float_to_bits(x)
namespace clfractal::detail {
constexpr double pi = 3.14159265358979323846;
static inline float bits_to_float(std::uint32_t u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}
static inline std::uint32_t float_to_bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}
#endif

// splitmix64's output function (Steele, Lea, Flood 2014).
CLF_FN CLF_U64 splitmix64_mix(CLF_U64 z) {
    z = (z ^ (z >> 30)) * CLF_U64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * CLF_U64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

// Draw `counter` of the stream whose scrambled seed is `mixed_seed` = splitmix64_mix(seed).
CLF_FN CLF_U64 counter_bits(CLF_U64 mixed_seed, CLF_U64 counter) {
    return splitmix64_mix(mixed_seed + (counter + 1) * CLF_U64_C(0x9E3779B97F4A7C15));
}

// Box-Muller from two 24-bit integers, k1 in [1, 2^24] (u1 = k1 2^-24 in (0, 1]) and k2 in
// [0, 2^24) (u2 = k2 2^-24): sqrt(-2 ln u1) cos(2 pi u2), with float additions and
// multiplications only (polynomials, a Newton square root):
//   ln u1 = (e - 24) ln 2 + ln m, k1 = m 2^e with m in [sqrt(1/2), sqrt(2)] (exact scaling),
//           ln m = s P(s), s = m - 1 (exact), P a degree-10 fit of ln(1 + s) / s;
//   sqrt x = x y, y = 1 / sqrt(x) from the bit-pattern guess and three Newton steps;
//   cos(2 pi u2): quadrant q = k2 >> 22 and f = (k2 & (2^22 - 1)) 2^-22 (exact), then
//           cos(pi/2 f) = C(f^2) and sin(pi/2 f) = f S(f^2), degree-6 fits.
// Error against double precision: below 3e-6 (tested).
CLF_FN float box_muller(CLF_U32 k1, CLF_U32 k2) {
    int e = 31 - (int)CLF_CLZ(k1);
    float m = (float)k1 * CLF_AS_FLOAT((CLF_U32)(127 - e) << 23);
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
    float y = CLF_AS_FLOAT(0x5f3759dfu - (CLF_AS_U32(x) >> 1));
    for (int i = 0; i < 3; ++i) y = y * (1.5f - 0.5f * x * y * y);
    const float radius = x * y;
    const CLF_U32 q = k2 >> 22;
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

// Uniform noise draw `index` in [-1, 1): the top 24 bits of the counter's draw.
CLF_FN float uniform_draw(CLF_U64 mixed_seed, CLF_U64 index) {
    return (float)((int)(counter_bits(mixed_seed, index) >> 40) - 0x800000) * 0x1p-23f;
}

// Gaussian noise draw `index`: Box-Muller of the counters 2^62 + 2 index and 2^62 + 2 index + 1
// (a stream of its own beside the uniform draws).
CLF_FN float gaussian_draw(CLF_U64 mixed_seed, CLF_U64 index) {
    const CLF_U64 c = CLF_U64_C(0x4000000000000000) + 2 * index;
    return box_muller((CLF_U32)(counter_bits(mixed_seed, c) >> 40) + 1u,
                      (CLF_U32)(counter_bits(mixed_seed, c + 1) >> 40));
}

#ifndef __OPENCL_VERSION__
}  // namespace clfractal::detail
#endif

#undef CLF_FN
#undef CLF_U32
#undef CLF_U64
#undef CLF_U64_C
#undef CLF_CLZ
#undef CLF_AS_FLOAT
#undef CLF_AS_U32

#endif  // CLFRACTAL_COUNTER_RNG_H
