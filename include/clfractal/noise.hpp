// The noise model (docs/definitions.md §21 "Noise formula"; thesis §3.2, Theorem 1, Lemmas
// 1-3, and the open problems of §6.2), reproducible noise injection on the device
// (docs/definitions.md §22), and the noise experiment of thesis §3.2.1 (Figs. 3.5-3.7).
//
// Edge model. An edge whose clean values are x and x + delta gets independent noise n_a, n_b.
// With x uniform over a range of width 2 Lambda around the isovalue sigma (wide enough to
// hold every x for which sigma can fall in the noisy span), the probability that sigma lies
// in the noisy span is
//     P(delta) = E| delta + n_b - n_a | / (2 Lambda),                                  (*)
// because for fixed noise the x for which sigma lies between x + n_a and x + delta + n_b
// form an interval of length |delta + n_b - n_a|. For uniform noise on [-mu, mu] this is
// Lemma 2; averaging over delta uniform on [0, gamma] gives Lemma 3. The subsampled grid G'
// has 1/8 of the edges near sigma and spans uniform on [0, 2 gamma], so the expected edge
// dimension is
//     D = log2( 8 A(gamma) / A(2 gamma) ),  A(g) = (1/g) int_0^g E|delta + n_b - n_a| d delta,
// which for uniform noise is Theorem 1 (r = mu / gamma) and for Gaussian noise (standard
// deviation sigma_n, r = sigma_n / gamma) is evaluated by numerical integration.
//
// Box model (beyond the thesis, §6.2 "what is the formula for the box dimension"): a cube
// of side h whose clean values are linear, c + h g.v for its 8 corners v in {0,1}^3, with
// gradient g of length gamma in a uniformly random direction (which makes the edge spans
// uniform on [0, gamma], the edge model's assumption), plus independent noise at each
// corner. The same argument as (*) gives P(cube intersected) = E[max_v - min_v] / (2 Lambda),
// so D_box = log2( 8 R(1) / R(2) ), R(h) = E[ range_v (h g.v + n_v) ], estimated by Monte
// Carlo over directions and noise (common random numbers for h = 1 and h = 2).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

// ------------------------------------------------------------------ Theorem 1 and lemmas

/// Lemma 1: the probability that sigma lies in the span of the noisy values s_a + n_a,
/// s_b + n_b (s_a <= s_b, n uniform on [-mu, mu], mu > 0). The thesis states three cases
/// (both values within mu of sigma: 1/2 - (s_a - sigma)(s_b - sigma) / (2 mu^2); only s_b
/// within: 1/2 + (s_b - sigma) / (2 mu); only s_a within: 1/2 - (s_a - sigma) / (2 mu), where
/// the thesis prints "+", a sign slip its own proof and Lemma 2 do not make); this function is
/// the general P(a < sigma) P(b >= sigma) + P(a >= sigma) P(b < sigma), which equals them
/// there (and is 0 or 1 in the remaining cases).
double lemma1_probability(double s_a, double s_b, double sigma, double mu);

/// Lemma 2: the probability that sigma lies in the noisy span of an edge with span
/// [x, x + delta], x uniform on [sigma - Lambda, sigma + Lambda], Lambda >= mu + delta:
/// (8 mu^3 - delta^3) / (24 mu^2 Lambda) + delta^2 / (4 mu Lambda) if delta <= 2 mu,
/// delta / (2 Lambda) otherwise. Throws std::invalid_argument if Lambda < mu + delta.
double lemma2_probability(double delta, double mu, double lambda);

/// Lemma 3: Lemma 2 averaged over delta uniform on [0, gamma] (Lambda >= mu + gamma):
/// (32 mu^3 + 8 mu gamma^2 - gamma^3) / (96 mu^2 Lambda) if gamma <= 2 mu,
/// (3 gamma^2 + 2 mu^2) / (12 gamma Lambda) otherwise.
double lemma3_probability(double gamma, double mu, double lambda);

/// Theorem 1 (eqs. 3.2-3.4): the expected fractal edge span dimension under uniform noise
/// [-r gamma, r gamma]:
///   r >= 1:        log2((32 r^3 + 8 r - 1) / (4 r^3 + 4 r - 1))
///   1/2 <= r <= 1: log2((32 r^3 + 8 r - 1) / (r^4 + 6 r^2))
///   r < 1/2:       log2(8 (2 r^2 + 3) / (r^2 + 6))
/// 2 at r = 0, continuous, increasing to 3. Throws std::invalid_argument for r < 0 or NaN.
double expected_edge_dimension(double r);

// ------------------------------------------------------------------ beyond the thesis

enum class NoiseKind { uniform, gaussian };
const char* noise_kind_name(NoiseKind k);
/// "uniform" or "gaussian"; throws InputError otherwise.
NoiseKind parse_noise_kind(const std::string& name);

/// E|delta + n_b - n_a| for two independent noise values of `kind` with `amplitude` (mu of
/// uniform [-mu, mu], or the standard deviation of Gaussian noise), by composite Simpson
/// integration over the density of n_b - n_a (triangular on [-2 mu, 2 mu], or normal with
/// standard deviation amplitude * sqrt(2), cut at 10 standard deviations). 2 Lambda times
/// Lemma 2's probability for uniform noise.
double edge_span_measure(double delta, NoiseKind kind, double amplitude);

/// The expected edge dimension of the edge model (*) for noise amplitude r (gamma = 1), by
/// composite Simpson integration of edge_span_measure over delta. For uniform noise it
/// agrees with expected_edge_dimension(r) to about 1e-6.
double expected_edge_dimension(double r, NoiseKind kind);

/// The expected box dimension of the 8-vertex cube model for noise amplitude r (gamma = 1),
/// by Monte Carlo with `samples` (direction, noise) draws from a fixed seed. Its standard
/// error is about 0.16 / sqrt(samples) (0.00016 at the default, r = 1, over 8 seeds).
double expected_box_dimension(double r, NoiseKind kind, std::size_t samples = std::size_t(1) << 20,
                              std::uint64_t seed = 1);

// ------------------------------------------------------------------ reproducible noise

/// The uniform draw of vertex `index`: the top 24 bits of the splitmix draw that
/// uniform_noise (synthetic.hpp) uses, as (int(bits >> 40) - 2^23) * 2^-23, exact in
/// float32 and in [-1, 1).
float uniform_noise_f32(std::uint64_t seed, std::uint64_t index);

/// The standard normal draw of vertex `index`: Box-Muller from the draws 2 index and
/// 2 index + 1 of the same generator (counters offset by 2^62, apart from the uniform ones):
///   u1 = ((bits1 >> 40) + 1) * 2^-24 in (0, 1],  u2 = (bits2 >> 40) * 2^-24 in [0, 1),
///   z  = sqrt(-2 ln u1) * cos(2 pi u2),
/// evaluated with float32 additions and multiplications only (polynomial logarithm and
/// cosine, Newton square root; kernels/noise.cl documents the steps) in the same order on
/// the host and in the kernel, so every IEEE device gives the same bits as this function.
/// Within 3e-6 of the double-precision Box-Muller value of the same u1, u2.
float gaussian_noise_f32(std::uint64_t seed, std::uint64_t index);

struct NoiseOptions {
    NoiseKind kind = NoiseKind::uniform;
    double amplitude = 0;          ///< mu of uniform [-mu, mu]; standard deviation of Gaussian
    std::uint64_t seed = 1;
    /// false: the result is float32, v = float(value) + float(amplitude) * draw (two float32
    /// operations, no fused multiply-add; for int32, uint32 and float64 input the add is
    /// double(value) + double(float(amplitude) * draw), rounded to float32). true: that value
    /// rounded to nearest (half away from zero) and clamped to the input's type (float64
    /// input: kept in double).
    bool keep_type = false;
    /// Largest slab in z-slices (0: from the device's largest allocation). Results are the
    /// same for every slab size: each vertex's draw depends only on its global index.
    std::size_t slab_slices = 0;
};

/// Adds noise to every vertex of `v` on the device, slab by slab. Throws InputError for a
/// negative or non-finite amplitude.
Volume add_noise(Context& ctx, const Volume& v, const NoiseOptions& opt);
/// The same for a volume on the device, in one piece; the result stays there.
DeviceVolume add_noise(const DeviceVolume& v, const NoiseOptions& opt);

/// The same on the host: the definition the device is compared against, bit for bit.
Volume add_noise_host(const Volume& v, const NoiseOptions& opt);

// ------------------------------------------------------------------ the experiment

/// The thesis' synthetic data for the experiment (§3.2.1), N^3 float32, gradient 1:
/// "points": distance to the nearest of P random points; "circle": distance to a circle of
/// radius N/4 (isosurfaces are tori). Built on make_synthetic's "points" and "torus".
Volume noise_experiment_volume(const std::string& shape, std::size_t n, int points, std::uint64_t seed);

/// Default isovalues of the experiment for a synthetic shape of size N (docs/guide/theorem.md).
std::vector<float> default_noise_isovalues(const std::string& shape, std::size_t n);

/// gamma estimated from the edge spans near isovalue `iso`. The model assumes that the
/// edges whose minimum value lies near the isovalue have spans uniform on [0, gamma] (mean
/// gamma / 2). Starting from sqrt(2) times the median span of the intersected edges (their
/// spans have density 2 delta / gamma^2 under the model, median gamma / sqrt(2)), it
/// iterates gamma := 2 x the mean span of the edges (all three axes) whose minimum lies
/// within gamma of `iso`, until it changes by less than 0.1% (at most 50 passes). Throws
/// InputError when no edge is intersected or the values there are flat.
double estimate_gamma(const Volume& v, double iso);

struct NoisePoint {
    double amplitude = 0;        ///< mu (uniform) or the standard deviation (Gaussian)
    double r = 0;                ///< amplitude / gamma
    double measured_edge_fd = 0; ///< mean edge dimension over the isovalues where defined
    double measured_box_fd = 0;  ///< mean box dimension over the isovalues where defined
    double formula = 0;          ///< expected edge dimension (Theorem 1, or the Gaussian integral)
    double model_box = 0;        ///< expected box dimension of the 8-vertex model
    std::vector<double> edge_fd, box_fd;  ///< per isovalue (NaN where undefined)
};

/// For each amplitude: noise added to `clean` (float32 result), edge and box span
/// dimensions counted at `isovalues` on the device, averaged, beside the models at
/// r = amplitude / gamma. `progress` (may be empty) gets one line per amplitude.
std::vector<NoisePoint> noise_experiment(Context& ctx, const Volume& clean, const std::vector<float>& isovalues,
                                         const std::vector<double>& amplitudes, NoiseKind kind, double gamma,
                                         std::uint64_t seed, std::size_t box_samples = std::size_t(1) << 20,
                                         const std::function<void(const std::string&)>& progress = {});

}  // namespace clfractal
