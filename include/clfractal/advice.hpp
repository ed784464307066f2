// Answers to the user's questions from a fractal-dimension curve: which isovalues give clean
// surfaces (clean bands, docs/definitions.md §25), and how noisy the scan is (Theorem 1
// inverted, docs/definitions.md §23).
//
// Reading D(s) (thesis chapters 2-3): about 2 is a clean surface (a smooth surface has
// I ~ N^(2/3)); towards 3 the isosurface fills space, which is what noise does. The colour map
// of the local dimension puts the clean end at 2.2 (blue) and the noisy one at 2.5 (red).
#pragma once
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

// ------------------------------------------------------------------ clean bands

struct BandOptions {
    double max_fd = 2.2;      ///< a clean isovalue has a defined D(s) <= max_fd
    double min_share = 0.01;  ///< ... and I_G(s) >= min_share x the largest I_G over the curve
};

/// A run of consecutive isovalues (indices first..last of the curve, inclusive) that are all
/// clean. The representative is the middle isovalue of the run, the one farthest from the
/// isovalues where the surface turns noisy or small.
struct CleanBand {
    std::size_t first = 0, last = 0, representative = 0;
    double mean_fd = 0, max_fd = 0;  ///< over the band
    std::uint64_t max_count = 0;     ///< the largest I_G(s) in the band: the surface size
    std::size_t width() const { return last - first + 1; }
};

/// The clean bands of a curve (D from levels 0 and 1, counts of level 0), ranked best first:
/// wider bands first, then larger surfaces. Empty when no isovalue is clean. Throws
/// InputError for a non-finite max_fd or a min_share outside [0, 1].
std::vector<CleanBand> clean_bands(const FdCurve& f, const BandOptions& o = {});

// ------------------------------------------------------------------ noise level

/// Theorem 1 inverted: the r = mu / gamma whose expected edge dimension is `d` (bisection on
/// expected_edge_dimension, which increases from 2 at r = 0 to 3 as r grows). 0 for d <= 2,
/// +infinity for d >= 3, NaN for NaN.
double noise_ratio_from_edge_dimension(double d);

/// The edge model of noise.hpp for Gaussian noise of standard deviation r (gamma = 1) in
/// closed form: with tau = r sqrt(2) the standard deviation of n_b - n_a,
///   E|delta + n_b - n_a| = delta erf(delta / (tau sqrt 2)) + tau sqrt(2 / pi) exp(-delta^2 / (2 tau^2)),
///   A(g) = F(g) / g,  F(g) = (g^2 + tau^2) / 2 erf(g / (tau sqrt 2)) + tau g / sqrt(2 pi) exp(-g^2 / (2 tau^2)),
///   D = log2(8 A(1) / A(2)): 2 at r = 0, increasing to 3. expected_edge_dimension(r,
/// NoiseKind::gaussian) integrates the same numerically (they agree to about 1e-6).
double gaussian_edge_dimension(double r);

/// The Gaussian inversion: the r = sigma_n / gamma whose gaussian_edge_dimension is `d`
/// (0 for d <= 2, +infinity for d >= 3, NaN for NaN).
double gaussian_noise_ratio_from_edge_dimension(double d);

/// E|u + r (n1 - n2)| for u uniform on [0, 1] and n1, n2 standard normal: A(1) above.
double mean_edge_span_gaussian(double r);

/// The range of edge dimensions in which the inversion is trusted: below it D - 2 is within
/// a few hundredths (the scatter of measured dimensions) of a clean surface, above it the
/// curve is so flat that a hundredth in D moves r by more than 10%.
constexpr double noise_fd_min = 2.02;  ///< r ~ 0.17
constexpr double noise_fd_max = 2.95;  ///< r ~ 4.3

/// E|u + r (w1 - w2)| for u uniform on [0, 1] and w1, w2 uniform on [-1, 1]: the mean span of
/// a grid edge of the noise model with gamma = 1 (Simpson integration of edge_span_measure).
double mean_edge_span(double r);

/// The noise estimate of one curve. Under the model of Theorem 1 (clean edge spans uniform on
/// [0, gamma], uniform noise [-mu, mu] added to each vertex) an edge with observed span w is
/// intersected with probability proportional to w, so the intersected edges at s have mean
/// span E[w^2] / E[w] = gamma (1/3 + 2 r^2 / 3) / mean_edge_span(r). With r from the edge
/// dimension at s, that mean (measured) gives gamma, and mu = r gamma in grey values. This
/// generalises the gradient estimate of thesis §3.4 (the teapot's gamma = 25) to noisy data,
/// where the observed spans include the noise. Per isovalue, NaN outside the trusted range.
struct NoiseEstimate {
    IsovalueSet isovalues;
    std::vector<double> edge_fd;          ///< edge span dimension D_E(s)
    std::vector<std::uint64_t> edges;     ///< E_G(s)
    std::vector<double> mean_span;        ///< mean span of the intersected edges at s
    std::vector<double> ratio;            ///< r(s) = mu / gamma; NaN outside the trusted range
    std::vector<double> gamma;            ///< gradient gamma(s) in grey values per voxel
    std::vector<double> amplitude;        ///< mu(s) = r(s) gamma(s), in grey values
    /// The same under Gaussian noise: r(s) = sigma_n / gamma from gaussian_edge_dimension,
    /// gamma(s) from the mean span E[w^2] / E[w] = gamma (1/3 + 2 r^2) / mean_edge_span_gaussian(r),
    /// sigma_n(s) = r(s) gamma(s) in grey values; NaN outside the trusted range.
    std::vector<double> ratio_gaussian, gamma_gaussian, sigma_gaussian;
    std::size_t used = 0;                 ///< isovalues with an estimate
    double median_ratio = std::numeric_limits<double>::quiet_NaN();
    double median_amplitude = std::numeric_limits<double>::quiet_NaN();  ///< uniform noise +-mu
    double median_ratio_gaussian = std::numeric_limits<double>::quiet_NaN();
    double median_sigma_gaussian = std::numeric_limits<double>::quiet_NaN();  ///< Gaussian noise std
};

/// Estimates the noise of `v` at every isovalue of `iso` whose edge count E_G'(s) is at least
/// min_share x the largest (the edge counts on the device, the span sums on the host).
NoiseEstimate estimate_noise(Context& ctx, const Volume& v, const IsovalueSet& iso, double min_share = 0.01);
/// The same for a volume already on the device: the edge counts read it there (no upload),
/// the span sums a download.
NoiseEstimate estimate_noise(const DeviceVolume& v, const IsovalueSet& iso, double min_share = 0.01);

/// Sum of the spans b - a of the grid edges (all three axes) with a < s <= b, for every
/// isovalue of `iso`, and their count: one pass over the edges with a difference array.
struct EdgeSpanSums {
    std::vector<double> sum;
    std::vector<std::uint64_t> count;
};
EdgeSpanSums intersected_edge_spans(const Volume& v, const IsovalueSet& iso);

}  // namespace clfractal
