// The noise level of a scan: the standard deviation of its noise in grey values, estimated
// where the signal is locally flat, so that anatomy and edges do not count as noise.
//
// Residual. At every interior vertex the 3D second difference
//     R(x) = sum over d in {-1,0,1}^3 of w(dx) w(dy) w(dz) v(x + d),  w(+-1) = 1, w(0) = -2
// (the product of [1 -2 1] along the three axes, the 3D form of Immerkaer's mask). For
// independent noise of standard deviation sigma, E[R^2] = 216 sigma^2 for every distribution
// of the noise (216 is the sum of the squared weights), so R^2 / 216 estimates sigma^2 without
// assuming Gaussian noise: uniform noise, the rounding of integer data and Gaussian noise are
// measured alike. R is 0 on every field that is at most quadratic along any one axis, so
// smooth anatomy, ramps and axis-aligned edges leave it almost untouched.
//
// Blocks. The volume is cut into blocks of block^3 vertices (kernels/noise_level.cl sums R^2
// per block on the device, with the range of the values the block's residuals read). A block
// is usable when it has at least min(block^3 / 8, the largest block's count) residuals and its
// residuals read neither the volume's smallest nor its largest value: values at the extremes
// are clipped (at an integer type's limits, a scanner's floor, a zeroed background), where the
// noise is cut off or absent. Usable blocks whose residuals are all 0 (constant or exactly
// polynomial stretches) take no part in the estimate; when no usable block has any residual,
// sigma is 0 (estimated on those blocks), and NaN when no block is usable.
//
// Estimate. Per usable block with residual y_b = log(v_b) / 3, v_b = (sum of R^2 / 216) / count. For white
// Gaussian noise y_b is near-normal (the cube root of a sum of squares, Wilson-Hilferty) with
// standard deviation s(n) = sqrt(2 k / n) / 3 for n residuals, k = (70/36)^3 = 7.35 the sum of
// R's squared autocorrelations. The centre c is the shorth of the y_b: the median of the
// shortest run of ceil(N / 2) consecutive sorted values (the first on ties), which lies where
// most blocks agree and which structure, inflating some blocks, does not pull. Flat blocks
// have |y_b - c| <= clip s(count_b): they agree with c as well as pure noise would. sigma^2 is
// the pooled mean over the flat blocks (their sum of R^2 / 216 over their count): unbiased for
// every noise distribution, since the window is symmetric about c and wide. flat_share is the
// flat blocks' residuals over all vertices. Where the noise itself varies across the volume,
// sigma is the level most blocks share, and flat_share says how many.
//
// That pooled value is sigma_white: the noise's white (vertex-to-vertex) part. Noise
// correlated across neighbouring vertices (a reconstruction kernel, earlier smoothing) reads
// lower, as it does for every residual-based estimator; sigma itself allows for correlation:
//
// Strided residuals. R_s is R with the taps s_a apart along axis a (the mask's 27 values at
// x + (dx sx, dy sy, dz sz)), taken at the vertices whose coordinates are all even. For noise
// of standard deviation sigma whose autocorrelation is a product of per-axis functions
// rho_a(d), E[R_s^2] = sigma^2 prod_a f_a(s_a), f_a(s) = 6 - 8 rho_a(s) + 2 rho_a(2 s) (6 for
// white noise). The strides are noise_strides(): 2, 4, 8 along one axis at a time (the other
// two at 1, which keeps anatomy out as R does), 2 and 4 along two or three axes, and (8,8,1),
// (8,8,8). V(s) is the
// pooled mean of R_s^2 / 216 over the flat blocks that agree with the rest (the shorth of
// log(V_b(s)) / 3 and a window of clip times the larger of its white spread and its robust
// spread, the shorth's length / 1.349), so that a block flat to R but reaching an edge at
// stride s drops out.
//
// Correlation model. The noise is a white part of variance b plus a correlated part of
// variance a whose autocorrelation along axis a is Gaussian, rho_a(d) = exp(-d^2 / (4 w_a^2)):
// white noise smoothed by a Gaussian of standard deviation w_a voxels (w_a = 0: white). So
// V(s) = a prod_a f_a(s_a) / 216 + b. Per axis, (V(s e_a) - b) / (V(1) - b) = f_a(s) / f_a(1)
// for s = 2, 4, 8 fixes w_a (least squares in log over a grid of w: 0 and 400 widths from 0.2 to
// 6 voxels, even in log); b is the value of V(1) (1 - 10^-t), t = 0, 0.004, .., 3.996, that fits
// the three axes best. Where that finds white noise, the same fit of V(s e_a) against
// b + (V(1) - b) f_a(s) / f_a(1), the differences over V(s e_a), is taken instead when its sigma
// is over five times sigma_white and its sum of squares under a tenth of white noise's (V(s) =
// V(1)): where rounding dominates V(1) (8-bit data, widths near 1.5), the
// log fit's small differences hide strongly correlated noise. correlation = (w_x, w_y, w_z), a width under 0.35 voxels taken as 0
// (white): edges that the wider taps reach raise every V(s) a little, which reads as widths of
// 0.2 to 0.3 on white noise.
//
// sigma. sigma^2 = (V(m) - b) / (prod_a f_a(m_a) / 216) + b, with m_a = s where w_a > 0 and
// 1 elsewhere, s the least of 2, 4, 8 whose gain prod_a f_a(m_a) / 6 reaches 0.3 (and whose V
// exists): where the gain is small an error of the widths moves sigma many times over, and
// wider taps reach more anatomy. For white noise m = (1, 1, 1) and sigma = sigma_white.
//
// Texture. The gain is at most 1, so noise gives V(2m) <= sigma^2. Where sigma is read at
// s = 2 and V at 4 along the same axes passes 2.25 sigma^2, the rise is texture or structure:
// the correlation is refused (w = 0, sigma = sigma_white, texture = true). So it is where the
// flat blocks' log(V_b(m)) / 3 at sigma's strides spread (the shorth's length / 1.349) over 3
// times what noise gives at their median count: noise keeps that near 1, while blurred edges
// of high contrast, which the model can read as wide correlated noise, vary from block to
// block by orders of magnitude.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

struct NoiseLevelOptions {
    /// Block side in vertices, 2..64; 0: noise_block_side(dims).
    std::size_t block = 0;
    std::size_t map_block = 32;  ///< side of the noise map's cells, a multiple of block
    double clip = 3;             ///< flat blocks lie within clip x s(count) of the centre
    /// Largest z-slab of the host-volume overload in slices (0: from the device's memory);
    /// rounded down to a multiple of block. Every slab depth gives the same result.
    std::size_t slab_slices = 0;
};

/// The automatic block side: 8 when the volume holds at least 64 blocks of 8 (counted as
/// ceil(n / 8) per axis), else 4. Blocks of 8 separate noise from structure well (a block's
/// y varies by s = 5.7% from noise alone) while still fitting between clipped regions.
std::size_t noise_block_side(const Dims& d);

/// Taps spacing of a strided residual along x, y, z.
using NoiseStride = std::array<int, 3>;

/// The strides the block statistics hold: (2,1,1), (1,2,1), (1,1,2), the same with 4 and 8,
/// then (2,2,1), (2,1,2), (1,2,2), (2,2,2), the same with 4, and (8,8,1), (8,8,8).
const std::vector<NoiseStride>& noise_strides();

/// The 1D factor of the Gaussian correlation model for width w (voxels) at stride s:
/// 6 - 8 rho(s) + 2 rho(2 s), rho(d) = exp(-d^2 / (4 w^2)); 6 for w = 0.
double noise_stride_factor(double w, int s);

/// The per-block statistics, blocks x fastest, then y, then z; block (i, j, k) covers
/// vertices [i b, (i + 1) b) x [j b, (j + 1) b) x [k b, (k + 1) b) of the volume.
struct NoiseBlocks {
    Dims volume{};                      ///< the volume's dims
    std::size_t block = 0;              ///< block side
    Dims grid{};                        ///< blocks per axis, ceil(n / block)
    std::vector<double> sum_squares;    ///< sum of R^2 / 216 over the block's residuals
    std::vector<std::uint32_t> count;   ///< residuals (interior vertices) of the block
    std::vector<double> low, high;      ///< range of the values its residuals read (0 if none)
    /// The strided residuals, per stride of `strides` (noise_strides()), per block: the sum of
    /// R_s^2 / 216 over the block's vertices with even coordinates whose taps lie in the
    /// volume, and their count.
    std::vector<NoiseStride> strides;
    std::vector<std::vector<double>> strided_sums;
    std::vector<std::vector<std::uint32_t>> strided_counts;
};

struct NoiseLevel {
    /// The noise's standard deviation, correlation allowed for (the header's definition):
    /// what a uniform region shows. NaN: no usable block.
    double sigma = std::numeric_limits<double>::quiet_NaN();
    double sigma_white = std::numeric_limits<double>::quiet_NaN();  ///< the pooled R: the white part
    /// The correlation model's width w per axis (x, y, z) in voxels: 0 for white noise; NaN
    /// where an axis has no strided residual or no noise was found.
    std::array<double, 3> correlation{std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::quiet_NaN()};
    NoiseStride sigma_strides{1, 1, 1};  ///< the strides sigma was read at
    /// Whether the residuals at the wider taps rise or vary from block to block beyond what
    /// noise gives (texture or structure, not noise): the correlation is then refused and
    /// sigma is sigma_white.
    bool texture = false;
    double flat_share = 0;              ///< residuals of the flat blocks / all vertices
    std::size_t blocks = 0, usable_blocks = 0, flat_blocks = 0;
    std::size_t block = 0;
    double typical_variance = std::numeric_limits<double>::quiet_NaN();  ///< exp(3 c), grey values^2
    /// The noise map: per cell of map_block^3 vertices (x fastest), sigma in the cell: sigma x
    /// sqrt(M_cell / M_flat), M_cell the median of the block variances (R_m^2 / 216 over the
    /// count) of the cell's usable blocks (silent ones 0) at sigma's strides m, M_flat that of
    /// the flat blocks: the local noise, the blocks an edge crosses left out while they are
    /// fewer than half of the cell's; NaN where the cell has no usable block with residuals at
    /// those strides. Where M_flat is 0, the pooled means take the medians' place (without any
    /// noise: the residual's RMS in the cell).
    std::size_t map_block = 0;
    Dims map_dims{};
    std::vector<float> map;
    /// The 10th, 50th and 90th percentiles of the map over its cells with a value (NaN
    /// without any): how much the noise varies across the volume.
    std::array<double, 3> spread{std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::quiet_NaN()};
    double seconds = 0;                 ///< device time of the block statistics (no compilation)
};

/// The block statistics of a volume on the device, in one piece. Throws InputError for a
/// block side outside 2..64. A volume with an axis shorter than 3 has no residual (all
/// counts 0).
NoiseBlocks noise_blocks(const DeviceVolume& v, std::size_t block = 16);
/// The same for a host volume, z-slab by z-slab (each slab of whole block rows uploads one
/// slice more on each side); smaller slabs when the device runs out of memory.
NoiseBlocks noise_blocks(Context& ctx, const Volume& v, std::size_t block = 16, std::size_t slab_slices = 0);

/// The estimate from block statistics (the header's definition). Throws InputError for a
/// map_block that is not a positive multiple of the blocks' side or a clip that is not > 0.
NoiseLevel noise_level_from_blocks(const NoiseBlocks& b, const NoiseLevelOptions& o = {});

/// The noise's variation across the volume: the map's 90th percentile over its 10th (NaN
/// without a map value or where the 10th is 0).
double noise_variation(const NoiseLevel& l);

/// Whether the noise reads as correlated: sigma > 1.5 sigma_white (a white-noise estimate
/// falls short by a third or more). The notes say so, and the denoising ladder then takes
/// the median everywhere instead of the fractal-targeted median.
bool noise_is_correlated(const NoiseLevel& l);

/// Plain statements for the front ends, empty when neither holds: "noise varies 3.1x across
/// the volume ..." when noise_variation > 1.5, and when noise_is_correlated, that the noise
/// is correlated, that a white-noise estimate reads sigma / sigma_white times less, and that
/// Theorem 1 (independent noise: r(s), its amplitudes) under-states it too.
std::vector<std::string> noise_level_notes(const NoiseLevel& l);

/// noise_blocks, then noise_level_from_blocks.
NoiseLevel estimate_noise_level(const DeviceVolume& v, const NoiseLevelOptions& o = {});
NoiseLevel estimate_noise_level(Context& ctx, const Volume& v, const NoiseLevelOptions& o = {});

}  // namespace clfractal
