// Synthetic volumes, so that every command runs with no data at hand.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/volume.hpp"

namespace clfractal {

struct SyntheticOptions {
    std::size_t size = 128;              ///< N: the volume is N^3 vertices
    double noise = 0.0;                  ///< amplitude mu of uniform noise in [-mu, mu]
    std::uint64_t seed = 1;              ///< seed of the counter-based generator
    int points = 10;                     ///< P for "points"
    std::optional<ValueType> type;       ///< convert to this type (rounded, clamped)
};

/// Names accepted by make_synthetic, with a one-line description each.
struct SyntheticInfo { std::string name, description; };
std::vector<SyntheticInfo> synthetic_catalog();

/// Builds a synthetic volume. Throws InputError for an unknown name or a size < 2.
Volume make_synthetic(const std::string& name, const SyntheticOptions& opt = {});

/// Counter-based uniform noise in [-1, 1): a pure function of (seed, index), identical
/// on every device and for every slab split.
double uniform_noise(std::uint64_t seed, std::uint64_t index);

}  // namespace clfractal
