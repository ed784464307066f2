// Denoising filters (docs/definitions.md §16 "Filters", §17 "Fractal-targeted filtering";
// thesis chapter 4 and §6.3).
//
// Every filter reads its input and writes a new volume of the same dims, type and spacing
// (never in place), clamp-to-edge at the borders: a neighbour outside the grid takes the
// value of the nearest border vertex (scipy's mode='nearest').
//   - median: the median of the 27 values of the 3×3×3 neighbourhood (exact, any type);
//   - Gaussian: separable, radius r = ceil(3 sigma), normalised weights
//     exp(-i^2 / (2 sigma^2)), i = -r..r, accumulation along z, then y, then x;
//     integer outputs rounded to nearest (ties to even) and clamped to the type's range;
//   - bilateral: over the cube of radius r = ceil(2 sigma_s),
//     out(v) = sum_w ws(w) wr(w) f(w) / sum_w ws(w) wr(w) with the spatial weight
//     ws = exp(-|w - v|^2 / (2 sigma_s^2)) and the range weight
//     wr = exp(-(f(w) - f(v))^2 / (2 sigma_r^2)); integer outputs rounded and clamped as
//     for the Gaussian. (The radius 2 sigma_s keeps the cube at 125 neighbours for
//     sigma_s = 1.)
// Accumulation (weights, sums, the Gaussian's temporaries): float32 for the types a float32
// holds exactly (8/16-bit integers, float32); double for int32, uint32 and float64, whose
// values a float32 would round by up to 2^-24 of their magnitude (128 for an int32 near 2^31)
// before any filtering. These need cl_khr_fp64 (else an InputError suggesting --as float32).
//
// Fractal-targeted filtering (thesis §4.3): the filter's value only where the local fractal
// dimension LD(v) (local.hpp) for isovalue s and window k is > h (NaN never qualifies), the
// input value elsewhere. The result reports the share of vertices selected and changed. The
// median kernels compute only the blocks of 16 columns that hold a selected vertex, the
// bilateral kernels only the selected vertices; the Gaussian's separable passes run in full
// and the last one selects.
//
// LD-guided bilateral filter (thesis §6.3: "could we improve [bilateral filtering] by using
// the fractal dimension instead of the gradient?"): the bilateral filter above with a range
// scale that follows the local fractal dimension of the centre vertex,
//     sigma_r(v) = sigma_r * min(LD(v) - 2, 1)   where LD(v) > 2,
// and out(v) = f(v) where LD(v) <= 2 or is undefined. Smooth parts of the isosurface
// (LD near 2) keep their values and edges; the rougher the surface around v, the more the
// range term lets through, up to the plain bilateral filter with sigma_r at LD >= 3.
//
// Volumes larger than the device's largest allocation (or Tuning::slab_bytes when set) are
// filtered in z-slabs with a halo of the radius; the results are identical to the in-core
// run. The LD field of the targeted filters is computed in-core (local.hpp).
//
// Kernels (kernels/filter.cl) follow Tuning::filter_variant: "rows" (CPUs: whole x-rows per
// work-item, 16 columns at a time in vector types), "vertices" (one work-item per vertex,
// neighbours through the caches) or "tiled" (GPUs: the median through local-memory tiles of
// 16 x 8 x 3 plus border; Gaussian and bilateral as "vertices").
#pragma once
#include <cstddef>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

enum class FilterKind { median, gaussian, bilateral };

/// A filter and its parameters.
struct FilterSpec {
    FilterKind kind = FilterKind::median;
    double sigma = 1;    ///< Gaussian
    double sigma_s = 1;  ///< bilateral, spatial (voxels)
    double sigma_r = 1;  ///< bilateral, range (value units)

    static FilterSpec median() { return {}; }
    static FilterSpec gaussian(double sigma) { return {FilterKind::gaussian, sigma, 1, 1}; }
    static FilterSpec bilateral(double sigma_s, double sigma_r) { return {FilterKind::bilateral, 1, sigma_s, sigma_r}; }

    /// The neighbourhood radius: 1 (median), ceil(3 sigma) (Gaussian), ceil(2 sigma_s)
    /// (bilateral).
    int radius() const;
    /// "median", "gaussian sigma 1.5", "bilateral sigma_s 1 sigma_r 20".
    std::string describe() const;
    /// Throws InputError unless the parameters are finite and > 0 and the radius is at most
    /// 32 (Gaussian) or 10 (bilateral; its spatial weights live in constant memory).
    void check() const;
};

/// The 3×3×3 median of every vertex.
Volume median_filter(Context& ctx, const Volume& v);
/// The separable Gaussian, radius ceil(3 sigma).
Volume gaussian_filter(Context& ctx, const Volume& v, double sigma);
/// The bilateral filter, radius ceil(2 sigma_s).
Volume bilateral_filter(Context& ctx, const Volume& v, double sigma_s, double sigma_r);
/// Any of the three.
Volume apply_filter(Context& ctx, const Volume& v, const FilterSpec& spec);
/// Any of the three on a volume already on the device, in one piece (no slabs, no
/// upload); the result stays on the device.
DeviceVolume apply_filter(const DeviceVolume& v, const FilterSpec& spec);

/// The threshold as the device compares it: the largest float32 <= h, so that for every
/// float32 LD, (LD > h) == (LD > float_threshold(h)). Throws InputError when h is NaN.
float float_threshold(double h);

/// Result of a fractal-targeted or LD-guided filter.
struct TargetedResult {
    Volume volume;              ///< the filtered volume (input type)
    std::size_t selected = 0;   ///< vertices with LD > h (targeted) or LD > 2 (LD-guided)
    std::size_t changed = 0;    ///< vertices whose value differs from the input
    double selected_share = 0;  ///< selected / vertices
    double changed_share = 0;   ///< changed / vertices
    double ld_seconds = 0;      ///< LD field (upload and kernels)
    double filter_seconds = 0;  ///< the masked filter and the download
};

/// The filter applied only where LD(v) > h, for isovalue `iso` and window `window` (even,
/// >= 2). The values stay on the device between the LD field and the filter.
TargetedResult targeted_filter(Context& ctx, const Volume& v, const FilterSpec& spec, double iso, double h,
                               int window = 8);

/// The same with `v` already on the device as `on_device` (the same dims, type and values,
/// in the context it runs in): no upload; the result, counts and timings as above.
TargetedResult targeted_filter(const DeviceVolume& on_device, const Volume& v, const FilterSpec& spec, double iso,
                               double h, int window = 8);

/// The same on a volume already on the device, in one piece: the LD field and the filter
/// read the same device values, and the result stays on the device.
DeviceVolume targeted_filter(const DeviceVolume& v, const FilterSpec& spec, double iso, double h, int window = 8);

/// The filter applied only where a given field (float32, the volume's dims) is > h, NaN
/// never qualifying: the targeted filter for any precomputed mask field, e.g. the LD4 field
/// of fd4.hpp (`clfractal filter --fractal4`). ld_seconds stays 0.
TargetedResult targeted_filter(Context& ctx, const Volume& v, const FilterSpec& spec, const Volume& field, double h);

/// The LD-guided bilateral filter (see above) for isovalue `iso` and window `window`.
TargetedResult ld_bilateral_filter(Context& ctx, const Volume& v, double sigma_s, double sigma_r, double iso,
                                   int window = 8);

/// The same masked filters with a given LD field (float32, same dims): targeted where
/// ld > h; LD-guided when `ld_guided` (h unused). Used by the slab path and the tests.
Volume masked_filter(Context& ctx, const Volume& v, const FilterSpec& spec, const Volume& ld, double h,
                     bool ld_guided = false);

}  // namespace clfractal
