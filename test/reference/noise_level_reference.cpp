#include "reference/noise_level_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace clfractal;

namespace ref {

namespace {

// w(d) of the second difference [1 -2 1].
int weight(int d) { return d == 0 ? -2 : 1; }

// R_s of vertex (x, y, z): the 27 values at x + (dx sx, dy sy, dz sz), weighted; widens
// [lo, hi] by the values it reads. R itself is stride (1, 1, 1).
long double strided_residual(const Volume& v, std::size_t x, std::size_t y, std::size_t z, const NoiseStride& s,
                             double& lo, double& hi) {
    const Dims d = v.dims();
    long double r = 0;
    visit(v, [&](const auto* p) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::size_t i = std::size_t(long(x) + dx * s[0]) +
                                          d.nx * (std::size_t(long(y) + dy * s[1]) + d.ny * std::size_t(long(z) + dz * s[2]));
                    const double u = double(p[i]);
                    lo = std::min(lo, u);
                    hi = std::max(hi, u);
                    r += (long double)(weight(dx) * weight(dy) * weight(dz)) * (long double)u;
                }
    });
    return r;
}

}  // namespace

NoiseBlocks noise_blocks(const Volume& v, std::size_t block) {
    const Dims d = v.dims();
    NoiseBlocks b;
    b.volume = d;
    b.block = block;
    b.grid = {(d.nx + block - 1) / block, (d.ny + block - 1) / block, (d.nz + block - 1) / block};
    const std::size_t n = b.grid.vertices();
    b.sum_squares.assign(n, 0.0);
    b.count.assign(n, 0);
    b.low.assign(n, 0.0);
    b.high.assign(n, 0.0);
    std::vector<long double> sums(n, 0.0L);
    std::vector<double> lo(n, std::numeric_limits<double>::infinity()), hi(n, -std::numeric_limits<double>::infinity());
    for (std::size_t z = 1; z + 1 < d.nz; ++z)
        for (std::size_t y = 1; y + 1 < d.ny; ++y)
            for (std::size_t x = 1; x + 1 < d.nx; ++x) {
                const std::size_t i = x / block + b.grid.nx * (y / block + b.grid.ny * (z / block));
                const long double r = strided_residual(v, x, y, z, {1, 1, 1}, lo[i], hi[i]);
                sums[i] += r * r;
                ++b.count[i];
            }
    for (std::size_t i = 0; i < n; ++i) {
        b.sum_squares[i] = double(sums[i]) / 216.0;
        if (b.count[i]) b.low[i] = lo[i], b.high[i] = hi[i];
    }
    // The strided residuals at the vertices with even coordinates whose taps lie in the volume.
    b.strides = noise_strides();
    for (const NoiseStride& s : b.strides) {
        std::vector<long double> strided(n, 0.0L);
        std::vector<std::uint32_t> counts(n, 0);
        for (std::size_t z = 0; z < d.nz; z += 2)
            for (std::size_t y = 0; y < d.ny; y += 2)
                for (std::size_t x = 0; x < d.nx; x += 2) {
                    if (x < std::size_t(s[0]) || y < std::size_t(s[1]) || z < std::size_t(s[2]) ||
                        x + s[0] >= d.nx || y + s[1] >= d.ny || z + s[2] >= d.nz)
                        continue;
                    const std::size_t i = x / block + b.grid.nx * (y / block + b.grid.ny * (z / block));
                    double unused_lo = 0, unused_hi = 0;
                    const long double r = strided_residual(v, x, y, z, s, unused_lo, unused_hi);
                    strided[i] += r * r;
                    ++counts[i];
                }
        std::vector<double> sums216(n);
        for (std::size_t i = 0; i < n; ++i) sums216[i] = double(strided[i]) / 216.0;
        b.strided_sums.push_back(sums216);
        b.strided_counts.push_back(counts);
    }
    return b;
}

namespace {

// The median of x (sorted here): the middle value, or the mean of the two middle ones.
double median(std::vector<double> x) {
    std::sort(x.begin(), x.end());
    const std::size_t n = x.size();
    return n % 2 ? x[n / 2] : (x[n / 2 - 1] + x[n / 2]) / 2;
}

// The white-noise map: cells of map_block / block blocks per axis; in each, sigma x
// sqrt(median of its usable blocks' variances / median of the flat blocks' variances), or,
// without flat blocks, the residual's RMS over its usable blocks.
void fill_map(const NoiseBlocks& b, const std::vector<char>& use, const std::vector<double>& flat, double sigma,
              std::size_t map_block, NoiseLevel& r) {
    const std::size_t per = map_block / b.block;
    r.map_block = map_block;
    r.map_dims = {(b.grid.nx + per - 1) / per, (b.grid.ny + per - 1) / per, (b.grid.nz + per - 1) / per};
    r.map.assign(r.map_dims.vertices(), std::numeric_limits<float>::quiet_NaN());
    for (std::size_t c = 0; c < r.map.size(); ++c) {
        const std::size_t cx = c % r.map_dims.nx, cy = c / r.map_dims.nx % r.map_dims.ny, cz = c / (r.map_dims.nx * r.map_dims.ny);
        double sum = 0, count = 0;
        std::vector<double> variances;
        for (std::size_t i = 0; i < r.blocks; ++i) {
            const std::size_t x = i % b.grid.nx, y = i / b.grid.nx % b.grid.ny, z = i / (b.grid.nx * b.grid.ny);
            if (use[i] > 0 && x / per == cx && y / per == cy && z / per == cz)
                sum += b.sum_squares[i], count += b.count[i], variances.push_back(b.sum_squares[i] / b.count[i]);
        }
        if (count == 0) continue;
        r.map[c] = float(flat.empty() ? std::sqrt(sum / count) : sigma * std::sqrt(median(variances) / median(flat)));
    }
}

}  // namespace

NoiseLevel noise_level(const NoiseBlocks& b, std::size_t map_block, double clip) {
    NoiseLevel r;
    r.block = b.block;
    r.blocks = b.count.size();
    // The volume's extremes, the largest count.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    std::uint32_t most = 0;
    for (std::size_t i = 0; i < r.blocks; ++i)
        if (b.count[i]) lo = std::min(lo, b.low[i]), hi = std::max(hi, b.high[i]), most = std::max(most, b.count[i]);
    const std::uint32_t min_count = std::max<std::uint32_t>(1, std::min<std::uint32_t>(std::uint32_t(b.block * b.block * b.block / 8), most));
    std::vector<char> use(r.blocks);  // 0 left out, 1 usable with every residual 0, 2 usable with noise
    std::vector<double> variances;
    double silent = 0;
    for (std::size_t i = 0; i < r.blocks; ++i) {
        if (b.count[i] >= min_count && b.low[i] > lo && b.high[i] < hi) use[i] = b.sum_squares[i] > 0 ? 2 : 1;
        if (use[i] == 2) variances.push_back(b.sum_squares[i] / b.count[i]);
        if (use[i] == 1) silent += b.count[i];
    }
    r.usable_blocks = std::size_t(std::count_if(use.begin(), use.end(), [](char u) { return u > 0; }));
    if (variances.empty()) {
        r.flat_blocks = r.usable_blocks;
        if (r.usable_blocks)
            r.sigma = r.sigma_white = 0, r.typical_variance = 0, r.flat_share = silent / double(b.volume.vertices());
        fill_map(b, use, {}, 0.0, map_block, r);
        return r;
    }
    // The shorth of y = log(v) / 3: the shortest run of ceil(N / 2) sorted values, its median.
    std::vector<double> y;
    for (double v : variances) y.push_back(std::log(v) / 3);
    std::sort(y.begin(), y.end());
    const std::size_t h = (y.size() + 1) / 2;
    std::size_t best = 0;
    for (std::size_t i = 0; i + h <= y.size(); ++i)
        if (y[i + h - 1] - y[i] < y[best + h - 1] - y[best]) best = i;
    const double centre = (y[best + (h - 1) / 2] + y[best + h / 2]) / 2;
    r.typical_variance = std::exp(3 * centre);
    double sum = 0, count = 0;
    std::vector<double> flat;  // the flat blocks' variances
    for (std::size_t i = 0; i < r.blocks; ++i) {
        if (use[i] != 2) continue;
        const double spread = std::sqrt(2 * std::pow(70.0 / 36, 3) / b.count[i]) / 3;
        if (std::abs(std::log(b.sum_squares[i] / b.count[i]) / 3 - centre) <= clip * spread)
            sum += b.sum_squares[i], count += b.count[i], ++r.flat_blocks, flat.push_back(b.sum_squares[i] / b.count[i]);
    }
    r.sigma_white = std::sqrt(sum / count);
    r.flat_share = count / double(b.volume.vertices());
    fill_map(b, use, flat, r.sigma_white, map_block, r);
    return r;
}

}  // namespace ref
