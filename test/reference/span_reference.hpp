// Plain C++ definitions of the span counts (docs/definitions.md §4-§7), written for
// obviousness, not speed. Every value is compared in double, which holds every value of the
// eight value types (int32 and uint32 included) and every float32 and float64 isovalue exactly,
// so `a < s <= b` is the comparison of the definition in the data's own type.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/span.hpp"

namespace ref {

using clfractal::IsovalueSet;
using clfractal::Volume;

/// Level l of the pyramid: the vertices whose coordinates are multiples of 2^l.
Volume level(const Volume& v, int l);

/// I(s) for every isovalue by testing every cube against every isovalue.
std::vector<std::uint64_t> cubes_brute(const Volume& v, const IsovalueSet& iso);
/// E(s) for every isovalue by testing every grid edge against every isovalue.
std::vector<std::uint64_t> edges_brute(const Volume& v, const IsovalueSet& iso);

/// The same counts by the one-pass difference histogram, for volumes too large for the
/// brute force (checked against it on small grids).
std::vector<std::uint64_t> cubes_histogram(const Volume& v, const IsovalueSet& iso);
std::vector<std::uint64_t> edges_histogram(const Volume& v, const IsovalueSet& iso);

}  // namespace ref
