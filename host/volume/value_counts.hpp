// The count of every value of 8- and 16-bit integer data, from which its value range, its
// isovalue histogram at any isovalue set (analysis.cpp) and its summary (summarize_values)
// follow exactly, in one pass over the volume.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/volume.hpp"

namespace clfractal::detail {

/// How many vertices of `v` (8- or 16-bit integer data) hold each value of the type, indexed
/// by the value's bits (a signed value's two's complement): 256 or 65,536 counts, on every core.
std::vector<std::uint64_t> value_counts(const Volume& v);
/// The value whose bits are u, in type t (8 or 16 bits).
long long value_of_bits(std::size_t u, ValueType t);
/// The smallest and largest value counted ({} when none is).
ValueStats stats_of_counts(const std::vector<std::uint64_t>& counts, ValueType t);

}  // namespace clfractal::detail
