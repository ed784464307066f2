// The count of every value of 8- and 16-bit data (volume/value_counts.hpp).
#include "volume/value_counts.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cstring>

namespace clfractal::detail {
namespace {

// How many of the m bytes at p hold each of the 256 byte values, on every core. Each thread
// reads a word of 8 bytes at a time into four tables of 32-bit counts (4 KiB, in L1): the
// increments of one table follow each other a quarter as often as with one, so runs of
// equal values wait less on the store before. The tables go into 64-bit counts every 2^31
// bytes, before a count can overflow.
std::array<std::uint64_t, 256> byte_counts(const unsigned char* p, std::size_t m) {
    constexpr std::size_t block = std::size_t(1) << 20, flush_every = 2048;
    const std::size_t blocks = (m + block - 1) / block;
    const int threads = int(std::max<std::size_t>(1, std::min<std::size_t>(std::size_t(omp_get_max_threads()), blocks)));
    std::vector<std::array<std::uint64_t, 256>> part(std::size_t(threads), std::array<std::uint64_t, 256>{});
#pragma omp parallel num_threads(threads)
    {
        std::uint32_t c[4][256] = {};
        std::array<std::uint64_t, 256>& out = part[std::size_t(omp_get_thread_num())];
        const auto flush = [&] {
            for (std::size_t b = 0; b < 256; ++b) {
                out[b] += std::uint64_t(c[0][b]) + c[1][b] + c[2][b] + c[3][b];
                c[0][b] = c[1][b] = c[2][b] = c[3][b] = 0;
            }
        };
        std::size_t since = 0;
#pragma omp for schedule(static)
        for (std::size_t k = 0; k < blocks; ++k) {
            const unsigned char* q = p + k * block;
            const std::size_t len = std::min(block, m - k * block);
            std::size_t i = 0;
            for (; i + 8 <= len; i += 8) {
                std::uint64_t w;
                std::memcpy(&w, q + i, 8);
                ++c[0][w & 255];
                ++c[1][(w >> 8) & 255];
                ++c[2][(w >> 16) & 255];
                ++c[3][(w >> 24) & 255];
                ++c[0][(w >> 32) & 255];
                ++c[1][(w >> 40) & 255];
                ++c[2][(w >> 48) & 255];
                ++c[3][w >> 56];
            }
            for (; i < len; ++i) ++c[0][q[i]];
            if (++since == flush_every) {  // 2^31 bytes: at most 2^29 increments of a count
                flush();
                since = 0;
            }
        }
        flush();
    }
    std::array<std::uint64_t, 256> total{};
    for (const auto& h : part)
        for (std::size_t b = 0; b < 256; ++b) total[b] += h[b];
    return total;
}

// How many of the m 16-bit values at p hold each of the 65,536 values (indexed by their bits),
// on every core: four tables of 32-bit counts a thread (1 MiB, in L2), the values taken in
// turn, so that runs of equal values wait less on the store before (as byte_counts); into
// 64-bit counts every 2^31 values, before a count can overflow.
std::vector<std::uint64_t> word_counts(const std::uint16_t* p, std::size_t m) {
    constexpr std::size_t values = std::size_t(1) << 16, block = std::size_t(1) << 20, flush_every = 2048;
    const std::size_t blocks = (m + block - 1) / block;
    const int threads = int(std::max<std::size_t>(1, std::min<std::size_t>(std::size_t(omp_get_max_threads()), blocks)));
    std::vector<std::uint64_t> total(values, 0);
#pragma omp parallel num_threads(threads)
    {
        std::vector<std::uint32_t> tables(4 * values, 0);
        std::uint32_t* __restrict c0 = tables.data();
        std::uint32_t* __restrict c1 = c0 + values;
        std::uint32_t* __restrict c2 = c1 + values;
        std::uint32_t* __restrict c3 = c2 + values;
        std::vector<std::uint64_t> out(values, 0);
        const auto flush = [&] {
            for (std::size_t b = 0; b < values; ++b) out[b] += std::uint64_t(c0[b]) + c1[b] + c2[b] + c3[b];
            std::fill(tables.begin(), tables.end(), 0u);
        };
        std::size_t since = 0;
#pragma omp for schedule(static)
        for (std::size_t k = 0; k < blocks; ++k) {
            const std::uint16_t* q = p + k * block;
            const std::size_t len = std::min(block, m - k * block);
            std::size_t i = 0;
            for (; i + 4 <= len; i += 4) {
                ++c0[q[i]];
                ++c1[q[i + 1]];
                ++c2[q[i + 2]];
                ++c3[q[i + 3]];
            }
            for (; i < len; ++i) ++c0[q[i]];
            if (++since == flush_every) {  // 2^31 values: at most 2^29 increments of a count
                flush();
                since = 0;
            }
        }
        flush();
#pragma omp critical
        for (std::size_t b = 0; b < values; ++b) total[b] += out[b];
    }
    return total;
}

}  // namespace

std::vector<std::uint64_t> value_counts(const Volume& v) {
    if (value_size(v.type()) == 1) {
        const std::array<std::uint64_t, 256> b = byte_counts(static_cast<const unsigned char*>(v.data()), v.vertices());
        return std::vector<std::uint64_t>(b.begin(), b.end());
    }
    return word_counts(static_cast<const std::uint16_t*>(v.data()), v.vertices());
}

long long value_of_bits(std::size_t u, ValueType t) {
    switch (t) {
    case ValueType::int8: return (long long)std::int8_t(std::uint8_t(u));
    case ValueType::int16: return (long long)std::int16_t(std::uint16_t(u));
    default: return (long long)u;
    }
}

ValueStats stats_of_counts(const std::vector<std::uint64_t>& counts, ValueType t) {
    ValueStats s;
    bool any = false;
    for (std::size_t u = 0; u < counts.size(); ++u) {
        if (!counts[u]) continue;
        const double x = double(value_of_bits(u, t));
        s.min = any ? std::min(s.min, x) : x;
        s.max = any ? std::max(s.max, x) : x;
        any = true;
    }
    return s;
}

}  // namespace clfractal::detail
