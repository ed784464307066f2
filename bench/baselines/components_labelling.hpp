// The per-isovalue peer of count_components (clfractal/components.hpp): labelling by
// breadth-first search, the obvious alternative to the sweeps. The components benchmark
// times it, `clfractal components --verify` and the tests check the curve against it. Not
// part of the installed library.
#pragma once
#include <cstdint>

#include "clfractal/components.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// components(s) at one isovalue by labelling: breadth-first search over A = {f < s} and
/// over C = {f >= s} with the mode's neighbourhoods (cube: 6 in A, 26 in C; freudenthal: the
/// 14 Freudenthal edges in both), b0(A) + b0(C) - 1 (0 when either is empty). O(N) per
/// isovalue, 1 byte per vertex.
std::int64_t count_components_by_labelling(const Volume& v, double isovalue, Connectivity mode = Connectivity::cube);

}  // namespace clfractal
