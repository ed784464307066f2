// Plain C++ definitions of the 4D fractal dimension and its local field (docs/definitions.md
// §24 "4D fractal dimension"), written for obviousness, not speed: every B_q computed by the
// formula in double from the cube's span, every window summed cube by cube.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/volume.hpp"

namespace ref {

/// B_q(a, b) = floor((b - vmin)/q) - floor((a - vmin)/q) + 1 of every cube of `v` (span
/// [a, b] of its 8 values), (nx-1)(ny-1)(nz-1) entries, x fastest.
std::vector<std::uint64_t> cube_bins(const clfractal::Volume& v, double vmin, double q);

struct Fd4 {
    std::uint64_t i4 = 0, i4_sub = 0;  ///< I4(G, q), I4(G', 2q)
    double d4 = 0;                     ///< log2(i4 / i4_sub), NaN where either is 0
};
/// I4 and D4 of `v` for bin width q, vmin = the smallest value of v.
Fd4 fd4(const clfractal::Volume& v, double q);

/// The default bin width: 1 for integer data, (vmax - vmin)/256 for float data (1 when 0).
double default_q(const clfractal::Volume& v);

/// LD4 of every vertex for bin width q and window k: B_q over the cubes of W in G and B_2q
/// over the cubes of W' in G' (the windows of local_reference.hpp), summed one by one.
std::vector<double> local_dimension_4d_brute(const clfractal::Volume& v, double q, int k);

}  // namespace ref
