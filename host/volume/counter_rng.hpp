// Internal: the counter-based generator behind synthetic noise and noise injection
// (seed + vertex index -> the same value on every device and for every slab split).
#pragma once
#include <cstdint>

namespace clfractal::detail {

constexpr double pi = 3.14159265358979323846;

/// splitmix64's output function (Steele, Lea, Flood 2014).
constexpr std::uint64_t splitmix64_mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// Draw `counter` of the stream of a scrambled seed (splitmix64_mix(seed)).
constexpr std::uint64_t counter_bits(std::uint64_t mixed_seed, std::uint64_t counter) {
    return splitmix64_mix(mixed_seed + (counter + 1) * 0x9E3779B97F4A7C15ull);
}

}  // namespace clfractal::detail
