// 4D fractal dimension (docs/definitions.md §24 "4D fractal dimension"; thesis §6.4, beyond
// the thesis).
//
// The graph of f is a hypersurface in (x, y, z, value). The value axis is cut into bins
// [vmin + j q, vmin + (j + 1) q); a cube with span [a, b] touches
//     B_q(a, b) = floor((b - vmin) / q) - floor((a - vmin) / q) + 1
// bins (computed in double). With vmin the volume's smallest value:
//     I4(G, q) = sum over the cubes of G of B_q,
//     D4 = log2( I4(G, q) / I4(G', 2 q) )        (G' = pyramid level 1, same vmin),
// one number per grid, independent of any isovalue: 3 for a smooth field, towards 4 for
// noise. Default q: 1 for integer data, (vmax - vmin) / 256 otherwise (and 1 for a constant
// float volume, where every q > 0 gives one bin per cube). For integer data with q = 1,
// I4(G, 1) = sum_s I_G(s) + cubes(G) (every bin a cube touches but its lowest is an isovalue
// a < s <= b).
//
// Local 4D field: LD4(v) = log2( I4_W / I4_W' ) with the windows W, W' of the local
// dimension (local.hpp, local_windows, revision 2), I4_W summing B_q over the cubes of W in
// G and I4_W' summing B_2q over the cubes of W' in G'; NaN where I4_W' is 0 (then W is empty
// too: every cube touches at least one bin). Both sums are box queries on 3D summed-area
// tables (sat.hpp) of the per-cube bin counts, read by local.cl's query kernels.
//
// Where B_q is computed: on the device in double when it has cl_khr_fp64 (and
// Tuning::use_fp64 is set, the default); otherwise the host computes every vertex's bin
// floor((f - vmin) / q) in double, and the device takes B_q = max - min + 1 of the cube's
// bins, which is the same number: x -> floor((x - vmin) / q) is non-decreasing in
// floating point (correctly rounded subtraction and division by q > 0 are monotone), so
// the bins of the span's ends are the extreme bins of its vertices. Sums are 64-bit; a q so
// small that bins or sums could exceed 2^62 is refused.
#pragma once
#include <cstdint>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// The default bin width of `v`: 1 for integer data, (vmax - vmin) / 256 for float data
/// (1 when that is 0).
double default_bin_width(const Volume& v);

/// Checks a bin width (finite, > 0, and not so small that the bins of `v`'s value range or
/// their sum over its cubes overflow); throws InputError naming --q otherwise.
void check_bin_width(const Volume& v, double q);

struct Fd4Result {
    double q = 0;             ///< bin width at level 0 (G' uses 2 q)
    double vmin = 0;          ///< bin origin: the smallest value of the volume
    std::uint64_t i4 = 0;     ///< I4(G, q)
    std::uint64_t i4_sub = 0; ///< I4(G', 2 q)
    double d4 = 0;            ///< log2(i4 / i4_sub); NaN where either is 0
    double seconds = 0;       ///< device time (upload, kernels, download)
};

/// I4 of G and G' and D4 of `v` with bin width `q` (0: default_bin_width). The sums are
/// per-row reductions on the device, added on the host. Throws InputError for a bad q.
Fd4Result fractal_dimension_4d(Context& ctx, const Volume& v, double q = 0);
/// The same for a volume already on the device: with the bins computed on the device (fp64)
/// the kernels read it there (no upload); the value range and the finiteness check read a
/// download, as does the host-binned path.
Fd4Result fractal_dimension_4d(const DeviceVolume& v, double q = 0);

/// The LD4 field of `v` (float32, same dims and spacing; NaN where undefined) for bin width
/// `q` (0: default) and even window `window` >= 2. Tables are 32-bit when the largest
/// possible total (cubes × the bins of the value range) is at most Tuning::sat_max_32bit,
/// else 64-bit; the query kernels follow Tuning::local_variant. In-core only: a volume
/// whose tables exceed the device's largest allocation is refused with InputError.
Volume local_fractal_dimension_4d(Context& ctx, const Volume& v, double q = 0, int window = 8);
/// The same for a volume already on the device; the field stays there (no upload; the
/// range reads a download, as above).
DeviceVolume local_fractal_dimension_4d(const DeviceVolume& v, double q = 0, int window = 8);

}  // namespace clfractal
