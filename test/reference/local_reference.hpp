// Plain C++ definitions of the summed-area tables (thesis eq. 2.8) and of the local
// fractal dimension (docs/definitions.md §13 "Local fractal dimension", thesis eq. 2.6),
// written for obviousness, not speed.
// Values and isovalues are compared in double: exact for the four value types, with the
// isovalue rounded to float32 first for float data, as the definition says.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/volume.hpp"

namespace ref {

using clfractal::Dims;
using clfractal::Volume;

/// Inclusive 3D summed-area table by the recurrence of eq. 2.8 (C wraps like the device).
template <class C> std::vector<C> summed_area_table(const std::vector<C>& values, const Dims& d);
/// The same by the definition: every entry summed over its whole box (tiny grids only).
template <class C> std::vector<C> summed_area_table_direct(const std::vector<C>& values, const Dims& d);

/// 1 where cube (x, y, z) of `v` has span [a, b] with a < s <= b, for every cube
/// ((nx-1)(ny-1)(nz-1) entries, x fastest).
std::vector<std::uint8_t> cube_indicator(const Volume& v, double iso);

/// The cubes [lo, hi) of one axis in window W (G, n vertices) or W' (G', m vertices) of
/// the vertex at coordinate x for window k (docs/definitions.md §13, revision 2: W is W''s
/// region in G).
struct Range {
    long lo = 0, hi = 0;
};
Range window(long x, long n, int k);
Range window_sub(long x, long m, int k);

/// LD of every vertex (NaN where undefined), counting the intersected cubes of each window
/// one by one: no summed-area table. O(N k^3).
std::vector<double> local_dimension_brute(const Volume& v, double iso, int k);

/// The same with host summed-area tables of the unpadded indicators, queried with explicit
/// border cases (O(N), for the larger volumes; checked against the brute force).
std::vector<double> local_dimension_sat(const Volume& v, double iso, int k);

}  // namespace ref
