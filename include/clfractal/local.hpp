// Local fractal dimension (docs/definitions.md §13 "Local fractal dimension", §14 "Colour
// map"; thesis §2.4, eq. 2.6 and eq. 2.8).
//
// For isovalue s and even window k, at vertex v = (x, y, z), per axis with n vertices in
// G and n' = (n - 1) / 2 + 1 in G' (pyramid level 1) — revision 2 of the definition:
//   - window W' in G': cubes [b0, b1) = [max(0, c0), min(n' - 1, c0 + k/2)),
//     c0 = floor((x - k/2) / 2)
//   - window W in G:   cubes [2 b0, 2 b1), exactly the region of W' (thesis: "W' covers the
//     same region as W"), so W is centred on v to within one cube
//   - LD(v) = log2( I_W / I_W' ), NaN where either count is 0,
// where I counts the intersected cubes (span [a, b] with a < s <= b) in the window. Both
// counts are box queries on 3D summed-area tables (sat.hpp) of the 0/1 "cube intersected"
// indicator of G and of G', so the field costs O(N) whatever k is.
//
// The comparison a < s <= b is made in the data's type (docs/definitions.md §3): float32 data
// with s rounded to float32, float64 data with s in double, integer data with the integer
// ceil(s) (so s = 99.5 on uint8 data selects the same cubes as s = 100).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// The windows of one coordinate along one axis: cubes [lo, hi) of G (window W) and
/// [lo_sub, hi_sub) of G' (window W'), with lo = 2 lo_sub and hi = 2 hi_sub (revision 2).
/// Laid out as an OpenCL int4, so the kernels read the tables as they are.
struct LocalWindow {
    std::int32_t lo = 0, hi = 0, lo_sub = 0, hi_sub = 0;
    bool operator==(const LocalWindow& o) const {
        return lo == o.lo && hi == o.hi && lo_sub == o.lo_sub && hi_sub == o.hi_sub;
    }
};

/// The window of every coordinate 0..n-1 of an axis of n vertices for window k: the one
/// place the window bounds are written. The host builds these tables (x, then y, then z)
/// and the kernels only read them. Throws InputError unless k is even and at least 2.
std::vector<LocalWindow> local_windows(std::size_t n, int window);

/// What is wrong with a window k: "" when k is even and at least 2, else "the window must be
/// even and at least 2" (the one window check: the library's and the CLI's messages).
std::string window_problem(int window);

/// Checks a window (window_problem) and an isovalue (finite); throws InputError naming
/// the option (--window, --iso) otherwise.
void check_local_arguments(double iso, int window);

/// The LD field of `v` for isovalue `iso` and window `window`: a float32 volume of the same
/// dims and spacing, NaN where LD is undefined. Throws InputError if the window is odd or
/// below 2, or the isovalue is not finite. The tables are 32-bit when the grid has at most
/// ctx.tuning.sat_max_32bit (2^32 - 1) cubes, else 64-bit; the kernels follow
/// ctx.tuning.local_variant and sat_variant; with ctx.tuning.zero_copy (CPU devices) the
/// volume is read and the field written in place in host memory. The device holds the
/// values, the field and both tables of one z-slab at once: a volume whose tables exceed
/// the device's largest allocation, or whose run exceeds a third of its memory, or whose
/// values exceed ctx.tuning.slab_bytes (tests force tiny slabs this way), is processed in
/// z-slabs with a halo of k/2 slices, with results identical to the in-core run.
Volume local_fractal_dimension(Context& ctx, const Volume& v, double iso, int window = 8);

/// The same for a volume already on the device, in one piece (no slabs, no upload); the
/// field (float32, the volume's dims and spacing) stays on the device for the stages that
/// follow.
DeviceVolume local_fractal_dimension(const DeviceVolume& v, double iso, int window = 8);

/// Thesis §2.4 colour map: LD <= ld_blue is blue, LD >= ld_red is red, linear in between.
constexpr double ld_blue = 2.2;
constexpr double ld_red = 2.5;

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
    bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
};

/// The colour of a local fractal dimension: (0, 0, 255) up to ld_blue, (255, 0, 0) from
/// ld_red, and in between (r, 0, 255 - r) with r = round(255 t), t = (ld - 2.2) / 0.3;
/// NaN (undefined) is grey (128, 128, 128).
Rgb ld_colour(double ld);

/// Summary of an LD field.
struct LocalSummary {
    std::size_t vertices = 0;   ///< all vertices of the field
    std::size_t defined = 0;    ///< vertices where LD is defined ("near the surface")
    double above_blue = 0;      ///< share of the defined vertices with LD > ld_blue (2.2)
    double above_red = 0;       ///< share of the defined vertices with LD > ld_red (2.5)
    double mean = 0;            ///< mean LD over the defined vertices (NaN when none)
};
/// Summarises a float32 LD field; throws std::logic_error for other types.
LocalSummary summarize_local(const Volume& ld);

}  // namespace clfractal
