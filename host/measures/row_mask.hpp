// Up to 64 values' comparisons as the bits of one word, for the labellings that take a row
// 64 vertices at a time (components_at.cpp: which vertices are in A; components.cpp: which
// vertices a window of the (value, index) order holds).
#pragma once
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <cstddef>
#include <cstdint>
#include <cstring>

#if !defined(__SSE2__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "row_mask packs bytes assuming a little-endian layout"
#endif

namespace clfractal {

// Bit k: less(p[k]), for k < n <= 64. The comparisons go to bytes (a loop the compiler
// vectorises), packed sixteen at a time from their sign bits on x86-64, else eight at a time by
// one multiplication: byte i (0 or 1) of w lands on bit 56 + i of w * 0x0102040810204080, and
// no other product reaches bits 56..63.
template <class T, class Less> std::uint64_t row_mask(const T* p, std::size_t n, Less less) {
    alignas(16) std::uint8_t in[64] = {};
    if (n == 64)
        for (std::size_t k = 0; k < 64; ++k) in[k] = less(p[k]);
    else
        for (std::size_t k = 0; k < n; ++k) in[k] = less(p[k]);
    std::uint64_t m = 0;
#ifdef __SSE2__
    for (unsigned q = 0; q < 4; ++q) {
        const __m128i v = _mm_slli_epi16(_mm_load_si128(reinterpret_cast<const __m128i*>(in + 16 * q)), 7);
        m |= std::uint64_t(unsigned(_mm_movemask_epi8(v))) << (16 * q);
    }
#else
    for (unsigned q = 0; q < 8; ++q) {
        std::uint64_t w;
        std::memcpy(&w, in + 8 * q, 8);
        m |= ((w * 0x0102040810204080ull) >> 56) << (8 * q);
    }
#endif
    return m;
}

}  // namespace clfractal
