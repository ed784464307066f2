// The noise level (noise_level.hpp): block statistics on the device, the robust estimate
// from them on the host.
#include "clfractal/noise_level.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>

#include "device/kernel_call.hpp"
#include "device/slab_plan.hpp"
#include "device/type_options.hpp"

namespace clfractal {

namespace {

constexpr double residual_weight_squares = 216;  // (1 + 4 + 1)^3
constexpr std::size_t max_work_group = 256;
// Sum over all lags of the squared autocorrelation of R for white noise: per axis the
// autocorrelation of [1 -2 1] is (1, -4/6, 1/6) at lags 0, 1, 2, so (1 + 2 (16 + 1) / 36)^3.
constexpr double residual_correlation = (70.0 / 36) * (70.0 / 36) * (70.0 / 36);

void check_block(std::size_t block) {
    if (block < 2 || block > 64) throw InputError("noise level: block side " + std::to_string(block) + ": must be 2..64");
}

std::size_t blocks_along(std::size_t n, std::size_t block) { return (n + block - 1) / block; }

// How the kernel sums: exactly in integers for 8- and 16-bit integer data, in double for
// float64 data, in float otherwise (kernels/noise_level.cl).
enum class SumKind { integer, wide, single };

SumKind sum_kind(ValueType t) {
    if (is_integer(t) && value_size(t) <= 2) return SumKind::integer;
    return t == ValueType::float64 ? SumKind::wide : SumKind::single;
}

std::size_t sum_bytes(SumKind k) { return k == SumKind::single ? 4 : 8; }

NoiseBlocks empty_blocks(const Dims& d, std::size_t block) {
    NoiseBlocks b;
    b.volume = d;
    b.block = block;
    b.grid = {blocks_along(d.nx, block), blocks_along(d.ny, block), blocks_along(d.nz, block)};
    const std::size_t n = b.grid.vertices();
    b.sum_squares.assign(n, 0.0);
    b.count.assign(n, 0);
    b.low.assign(n, 0.0);
    b.high.assign(n, 0.0);
    b.strides = noise_strides();
    b.strided_sums.assign(b.strides.size(), std::vector<double>(n, 0.0));
    b.strided_counts.assign(b.strides.size(), std::vector<std::uint32_t>(n, 0));
    return b;
}

// The largest stride along z: the slices a slab reads on each side.
int largest_z_stride() {
    int most = 1;
    for (const NoiseStride& s : noise_strides()) most = std::max(most, s[2]);
    return most;
}

// Whether the block kernels run one work-item a group, each walking its blocks' vertices
// alone: on CPU devices, where PoCL runs a group's items as loops cut at every barrier and
// these kernels reduce every block (the strided one 13 times), when the sums are exact or in
// double (integer and wide sums; float32 sums keep the groups' tree, whose rounding the
// suite bounds). bench/memory_bench.py's 384^3 uint16 phantom, fd --noise-level, interleaved
// beside another build: the noise level 7.4 and 6.6 s with work-groups, 5.9 and 4.8 s with one
// item for the strided kernel, 3.9 and 4.1 s for both; the same sigma.
// Such groups also compile with -DONE_ITEM: the kernels walk their blocks in nested loops with
// the bounds taken once, the same values in the same order (640^3 uint16 phantom, two estimates
// interleaved with the loops of work-items: 28.0-33.0 -> 15.9-18.5 CPU s, the same sigma).
bool one_item(const Context& ctx, SumKind kind) { return ctx.is_cpu() && kind != SumKind::single; }

// The largest power of two within the kernel's, local memory's and the block's limits, for
// items of item_bytes local memory each beside fixed_bytes for the group.
std::size_t work_group(const Context& ctx, std::size_t kernel_limit, std::size_t item_bytes, std::size_t fixed_bytes,
                       std::size_t block) {
    const std::size_t free_bytes = ctx.local_mem() > fixed_bytes ? ctx.local_mem() - fixed_bytes : 0;
    const std::size_t limit = std::min({max_work_group, kernel_limit, free_bytes / item_bytes, block * block * block});
    std::size_t wg = 1;
    while (wg * 2 <= limit) wg *= 2;
    return wg;
}

// kernels/noise_level.cl block_residuals and block_residuals_tiled (two more local arrays).
using DirectCall = KernelCall<cl::Buffer, int, int, int, int, int, int, int, int, int, cl::Buffer, cl::Buffer,
                              cl::Buffer, cl::Buffer, cl::LocalSpaceArg, cl::LocalSpaceArg, cl::LocalSpaceArg,
                              cl::LocalSpaceArg>;
using TiledCall = KernelCall<cl::Buffer, int, int, int, int, int, int, int, int, int, cl::Buffer, cl::Buffer,
                             cl::Buffer, cl::Buffer, cl::LocalSpaceArg, cl::LocalSpaceArg, cl::LocalSpaceArg,
                             cl::LocalSpaceArg, cl::LocalSpaceArg, cl::LocalSpaceArg>;

// kernels/noise_level.cl block_strided_residuals.
using StridedCall = KernelCall<cl::Buffer, int, int, int, int, int, int, int, int, int, cl::Buffer, int, int,
                               cl::Buffer, cl::Buffer, cl::LocalSpaceArg, cl::LocalSpaceArg>;

// Local memory of the tiled kernel's two arrays: (b + 2)^3 and b (b + 2)^2 values.
std::size_t tile_bytes(SumKind k, std::size_t b) {
    return ((b + 2) * (b + 2) * (b + 2) + b * (b + 2) * (b + 2)) * (k == SumKind::wide ? 8 : 4);
}

// The `count` sums of kind k in `buffer` from sum `first` on, each over 216, into
// out[0..count).
void read_sums(Context& ctx, const cl::Buffer& buffer, SumKind k, std::size_t count, double* out,
               std::size_t first = 0) {
    const auto read = [&](auto zero) {
        std::vector<decltype(zero)> host(count);
        ctx.queue().enqueueReadBuffer(buffer, CL_TRUE, first * sizeof zero, count * sizeof zero, host.data());
        for (std::size_t i = 0; i < count; ++i) out[i] = double(host[i]) / residual_weight_squares;
    };
    if (k == SumKind::integer) read(cl_ulong());
    else if (k == SumKind::wide) read(cl_double());
    else read(cl_float());
}

// The strided residuals' sums of `rows` block rows of `slab` (as slab_blocks), every stride
// in one launch.
void strided_blocks(const DeviceVolume& slab, std::size_t nz, std::size_t z_first, std::size_t z_block,
                    std::size_t rows, const std::string& options, NoiseBlocks& b) {
    Context& ctx = slab.context();
    const Dims d = slab.dims();
    const SumKind kind = sum_kind(slab.type());
    const std::size_t per_row = b.grid.nx * b.grid.ny, count = rows * per_row, first = z_block / b.block * per_row;
    const std::size_t masks = b.strides.size();
    std::vector<cl_int> strides;
    for (const NoiseStride& st : b.strides) strides.insert(strides.end(), st.begin(), st.end());
    const Buffer<cl_int> stride_buffer(ctx, strides);
    const cl::Buffer sums = create_buffer(ctx, CL_MEM_WRITE_ONLY, masks * count * sum_bytes(kind));
    Buffer<cl_uint> counts(ctx, masks * count, CL_MEM_WRITE_ONLY);
    StridedCall kernel(ctx, "noise_level", "block_strided_residuals", options);
    const std::size_t half = (b.block + 1) / 2;
    const std::size_t wg =
        one_item(ctx, kind) ? 1 : work_group(ctx, kernel.work_group_limit(), sum_bytes(kind) + 4, 0, half);
    const std::size_t per_group = ctx.is_cpu() ? std::max<std::size_t>(1, count / (16 * ctx.compute_units())) : 1;
    const std::size_t groups = (count + per_group - 1) / per_group;
    kernel(cl::NDRange(wg * groups), cl::NDRange(wg), slab.buffer(), int(d.nx), int(d.ny), int(nz), int(z_first),
           int(z_block), int(b.grid.nx), int(b.grid.ny), int(count), int(per_group), stride_buffer.get(), int(masks),
           int(count), sums, counts.get(), cl::Local(wg * sum_bytes(kind)), cl::Local(wg * 4));
    // Stride by stride into place: no host copy of every stride's sums at once (19 strides of
    // 12 bytes a block would be 120 MiB at 640^3).
    for (std::size_t m = 0; m < masks; ++m) {
        read_sums(ctx, sums, kind, count, b.strided_sums[m].data() + first, m * count);
        counts.read(ctx.queue(), b.strided_counts[m].data() + first, count, m * count);
    }
}

// The statistics of `rows` block rows of `slab`, from the row starting at volume slice
// z_block on; the slab's first slice is slice z_first of a volume of nz slices.
void slab_blocks(const DeviceVolume& slab, std::size_t nz, std::size_t z_first, std::size_t z_block, std::size_t rows,
                 NoiseBlocks& b) {
    Context& ctx = slab.context();
    const Dims d = slab.dims();
    const SumKind kind = sum_kind(slab.type());
    const std::size_t value_bytes = value_size(slab.type()), per_row = b.grid.nx * b.grid.ny;
    const std::size_t count = rows * per_row, first = z_block / b.block * per_row;
    std::string options = type_options(slab.type()) + defines({{"BLOCK", std::to_string(b.block)}});
    if (kind == SumKind::integer) options += " -DINTEGER_SUMS";
    if (one_item(ctx, kind)) options += " -DONE_ITEM";
    const std::size_t item_bytes = sum_bytes(kind) + 4 + 2 * value_bytes, tiles = tile_bytes(kind, b.block);
    // The tiled kernel where its tile and at least 32 items fit in local memory.
    const bool tiled = ctx.tuning.noise_tiles && ctx.local_mem() >= tiles + 32 * item_bytes;
    const cl::Buffer sums = create_buffer(ctx, CL_MEM_WRITE_ONLY, count * sum_bytes(kind));
    Buffer<cl_uint> counts(ctx, count, CL_MEM_WRITE_ONLY);
    const cl::Buffer lows = create_buffer(ctx, CL_MEM_WRITE_ONLY, count * value_bytes);
    const cl::Buffer highs = create_buffer(ctx, CL_MEM_WRITE_ONLY, count * value_bytes);
    // kernels/noise_level.cl block_residuals[_tiled](v, nx, ny, nz, z_first, z_block, bx, by,
    // blocks, per_group, sums, counts, lows, highs, local_sums, local_counts, local_lows,
    // local_highs[, tile, along_x]). CPUs: a few groups per compute unit, each walking its blocks.
    const std::size_t per_group = ctx.is_cpu() ? std::max<std::size_t>(1, count / (16 * ctx.compute_units())) : 1;
    const std::size_t groups = (count + per_group - 1) / per_group;
    const auto launch = [&](auto& kernel, auto... tile_args) {
        const std::size_t wg =
            one_item(ctx, kind) ? 1 : work_group(ctx, kernel.work_group_limit(), item_bytes, tiled ? tiles : 0, b.block);
        kernel(cl::NDRange(wg * groups), cl::NDRange(wg), slab.buffer(), int(d.nx), int(d.ny), int(nz), int(z_first),
               int(z_block), int(b.grid.nx), int(b.grid.ny), int(count), int(per_group), sums, counts.get(), lows, highs,
               cl::Local(wg * sum_bytes(kind)), cl::Local(wg * 4), cl::Local(wg * value_bytes),
               cl::Local(wg * value_bytes), tile_args...);
    };
    if (tiled) {
        const std::size_t edge = b.block + 2, value = kind == SumKind::wide ? 8 : 4;
        TiledCall kernel(ctx, "noise_level", "block_residuals_tiled", options);
        launch(kernel, cl::Local(edge * edge * edge * value), cl::Local(b.block * edge * edge * value));
    } else {
        DirectCall kernel(ctx, "noise_level", "block_residuals", options);
        launch(kernel);
    }
    read_sums(ctx, sums, kind, count, b.sum_squares.data() + first);
    counts.read(ctx.queue(), b.count.data() + first, count);
    visit_type(slab.type(), [&](auto zero) {
        using T = decltype(zero);
        std::vector<T> lo(count), hi(count);
        ctx.queue().enqueueReadBuffer(lows, CL_TRUE, 0, count * sizeof(T), lo.data());
        ctx.queue().enqueueReadBuffer(highs, CL_TRUE, 0, count * sizeof(T), hi.data());
        for (std::size_t i = 0; i < count; ++i) {
            const bool any = b.count[first + i] > 0;
            b.low[first + i] = any ? double(lo[i]) : 0.0;
            b.high[first + i] = any ? double(hi[i]) : 0.0;
        }
    });
    strided_blocks(slab, nz, z_first, z_block, rows, options, b);
}

bool has_residuals(const Dims& d) { return d.nx >= 3 && d.ny >= 3 && d.nz >= 3; }

}  // namespace

std::size_t noise_block_side(const Dims& d) {
    const Dims g{blocks_along(d.nx, 8), blocks_along(d.ny, 8), blocks_along(d.nz, 8)};
    return g.vertices() >= 64 ? 8 : 4;
}

const std::vector<NoiseStride>& noise_strides() {
    static const std::vector<NoiseStride> strides{{2, 1, 1}, {1, 2, 1}, {1, 1, 2}, {4, 1, 1}, {1, 4, 1},
                                                  {1, 1, 4}, {8, 1, 1}, {1, 8, 1}, {1, 1, 8}, {2, 2, 1},
                                                  {2, 1, 2}, {1, 2, 2}, {2, 2, 2}, {4, 4, 1},
                                                  {4, 1, 4}, {1, 4, 4}, {4, 4, 4}, {8, 8, 1},
                                                  {8, 8, 8}};
    return strides;
}

double noise_stride_factor(double w, int s) {
    if (!(w > 0)) return 6;
    const auto rho = [w](double d) { return std::exp(-d * d / (4 * w * w)); };
    return 6 - 8 * rho(s) + 2 * rho(2.0 * s);
}

NoiseBlocks noise_blocks(const DeviceVolume& v, std::size_t block) {
    check_block(block);
    NoiseBlocks b = empty_blocks(v.dims(), block);
    if (!has_residuals(v.dims())) return b;
    check_int_axes(v.dims());
    with_cl_errors([&] { slab_blocks(v, v.dims().nz, 0, 0, b.grid.nz, b); });
    return b;
}

NoiseBlocks noise_blocks(Context& ctx, const Volume& v, std::size_t block, std::size_t slab_slices) {
    check_block(block);
    const Dims d = v.dims();
    NoiseBlocks b = empty_blocks(d, block);
    if (!has_residuals(d)) return b;
    check_int_axes(d);
    const std::size_t slice = d.nx * d.ny, bytes = value_size(v.type());
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = slice * bytes;
    need.halo = std::size_t(largest_z_stride());
    need.forced = slab_slices;
    const auto* src = static_cast<const unsigned char*>(v.data());
    // Slabs of whole block rows, the largest z stride of halo on each side; a block's sums
    // depend only on its own values and those its taps reach, so every depth gives the same
    // statistics.
    with_smaller_slabs(plan_slab(ctx, need, d), [&](std::size_t depth) {
        const std::size_t rows_per_slab = std::max<std::size_t>(1, depth / block);
        with_cl_errors([&] {
            for (std::size_t row = 0; row < b.grid.nz; row += rows_per_slab) {
                const std::size_t rows = std::min(rows_per_slab, b.grid.nz - row), z_block = row * block;
                const std::size_t z_first = z_block - std::min(z_block, need.halo);
                const std::size_t z_end = std::min(d.nz, z_block + rows * block + need.halo);
                const DeviceVolume slab(ctx, src + z_first * slice * bytes, Dims{d.nx, d.ny, z_end - z_first},
                                        v.type());
                slab_blocks(slab, d.nz, z_first, z_block, rows, b);
            }
        });
        return 0;
    });
    return b;
}

namespace {

// The start of the shortest run of ceil(n / 2) consecutive sorted values (the first such run
// on ties).
std::size_t shorth_start(const std::vector<double>& sorted) {
    const std::size_t n = sorted.size(), h = (n + 1) / 2;
    std::size_t best = 0;
    for (std::size_t i = 1; i + h <= n; ++i)
        if (sorted[i + h - 1] - sorted[i] < sorted[best + h - 1] - sorted[best]) best = i;
    return best;
}

// The middle of that run: its median, the midpoint of its two middle values when it has an
// even count.
double shorth_centre(const std::vector<double>& sorted) {
    const std::size_t h = (sorted.size() + 1) / 2, best = shorth_start(sorted);
    return 0.5 * (sorted[best + (h - 1) / 2] + sorted[best + h / 2]);
}

// The length of that run.
double shorth_length(const std::vector<double>& sorted) {
    const std::size_t h = (sorted.size() + 1) / 2, best = shorth_start(sorted);
    return sorted[best + h - 1] - sorted[best];
}

// What a block is to the estimate: left out; usable but its residuals all 0 (a constant or
// exactly polynomial stretch); usable with noise.
enum class BlockUse : char { left_out, silent, noisy };

// Usable blocks have enough residuals and read none of the volume's extremes.
std::vector<BlockUse> usable_blocks(const NoiseBlocks& b) {
    const std::size_t n = b.count.size(), cube = b.block * b.block * b.block;
    std::uint32_t most = 0;
    double lo = 0, hi = 0;
    bool any = false;
    for (std::size_t i = 0; i < n; ++i) {
        if (!b.count[i]) continue;
        most = std::max(most, b.count[i]);
        lo = any ? std::min(lo, b.low[i]) : b.low[i];
        hi = any ? std::max(hi, b.high[i]) : b.high[i];
        any = true;
    }
    const std::uint32_t min_count = std::max<std::uint32_t>(1, std::min<std::uint32_t>(std::uint32_t(cube / 8), most));
    std::vector<BlockUse> use(n, BlockUse::left_out);
    for (std::size_t i = 0; i < n; ++i)
        if (b.count[i] >= min_count && b.low[i] > lo && b.high[i] < hi)
            use[i] = b.sum_squares[i] > 0 ? BlockUse::noisy : BlockUse::silent;
    return use;
}

// The median of `x` (reordered), NaN when empty.
double median_of(std::vector<double>& x) {
    if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t h = x.size() / 2;
    std::nth_element(x.begin(), x.begin() + std::ptrdiff_t(h), x.end());
    if (x.size() % 2) return x[h];
    return 0.5 * (x[h] + *std::max_element(x.begin(), x.begin() + std::ptrdiff_t(h)));
}

// The noise map of `result` from the usable blocks, then the map's percentiles. With a sigma
// and flat blocks (`flat`) whose median variance at these strides is above 0: sigma x
// sqrt(M_cell / M_flat), M_cell the median over the cell's usable blocks of R^2 / count at
// one stride's `sums` and `counts` (silent blocks 0), M_flat that over the flat blocks. The
// median leaves out the blocks of a cell that reach an edge while they are fewer than half
// of it (a mean took them in: cells along the phantoms' edges read 10 to 19% high). Else
// sigma x sqrt(V_cell / pooled), V_cell the mean R^2 / count over the cell's usable blocks,
// `pooled` the flat blocks' (without a sigma or `pooled`: the residual's RMS in the cell).
void noise_map(const NoiseBlocks& b, const std::vector<BlockUse>& use, const std::vector<double>& sums,
               const std::vector<std::uint32_t>& counts, const std::vector<std::size_t>& flat, double pooled,
               std::size_t map_block, NoiseLevel& result) {
    const std::size_t per = map_block / b.block;
    const Dims g = b.grid;
    const Dims m{blocks_along(g.nx, per), blocks_along(g.ny, per), blocks_along(g.nz, per)};
    std::vector<std::vector<double>> cell(m.vertices());
    std::vector<double> sum(m.vertices(), 0.0), count(m.vertices(), 0.0);
    for (std::size_t z = 0; z < g.nz; ++z)
        for (std::size_t y = 0; y < g.ny; ++y)
            for (std::size_t x = 0; x < g.nx; ++x) {
                const std::size_t i = x + g.nx * (y + g.ny * z);
                if (use[i] == BlockUse::left_out || counts[i] == 0) continue;
                const std::size_t c = x / per + m.nx * (y / per + m.ny * (z / per));
                cell[c].push_back(sums[i] / double(counts[i]));
                sum[c] += sums[i];
                count[c] += double(counts[i]);
            }
    std::vector<double> reference;
    for (const std::size_t i : flat)
        if (counts[i] > 0) reference.push_back(sums[i] / double(counts[i]));
    const double flat_median = median_of(reference);
    const bool medians = std::isfinite(result.sigma) && flat_median > 0;
    const double scale = pooled > 0 && std::isfinite(result.sigma) ? result.sigma / std::sqrt(pooled) : 1.0;
    result.map_block = map_block;
    result.map_dims = m;
    result.map.resize(m.vertices());
    std::vector<double> values;
    for (std::size_t c = 0; c < m.vertices(); ++c) {
        std::vector<double>& x = cell[c];
        double value = std::numeric_limits<double>::quiet_NaN();
        if (!x.empty())
            value = medians ? result.sigma * std::sqrt(median_of(x) / flat_median) : scale * std::sqrt(sum[c] / count[c]);
        result.map[c] = float(value);
        if (!x.empty()) values.push_back(double(result.map[c]));
    }
    std::sort(values.begin(), values.end());
    const double qs[] = {0.1, 0.5, 0.9};
    for (int k = 0; k < 3 && !values.empty(); ++k) {
        // Linear between order statistics (numpy's default percentile).
        const double at = qs[k] * double(values.size() - 1);
        const std::size_t lo = std::size_t(at);
        const double t = at - double(lo);
        result.spread[k] = lo + 1 < values.size() ? values[lo] + t * (values[lo + 1] - values[lo]) : values[lo];
    }
}

}  // namespace

namespace {

void check_options(const NoiseLevelOptions& o, std::size_t block) {
    check_block(block);
    if (!(o.clip > 0)) throw InputError("noise level: clip must be > 0");
    if (o.map_block == 0 || o.map_block % block)
        throw InputError("noise level: the map's cells (" + std::to_string(o.map_block) +
                         ") must be a multiple of the block side (" + std::to_string(block) + ")");
}

// The standard deviation of log(v) / 3 for the variance v of a block of n residuals of
// white Gaussian noise: v has relative variance 2 k / n, k the sum of the residual's squared
// autocorrelations (residual_correlation), and log(v) / 3 a third of v's relative spread.
double root_spread(std::uint32_t n) { return std::sqrt(2 * residual_correlation / double(n)) / 3; }

}  // namespace

namespace {

// y_b = log(V_b) / 3 at one stride (`sums`, `counts`) of the blocks of `flat` (indices) with
// residuals there that are not all 0, sorted.
std::vector<double> sorted_log_variances(const std::vector<double>& sums, const std::vector<std::uint32_t>& counts,
                                         const std::vector<std::size_t>& flat) {
    std::vector<double> y;
    for (std::size_t i : flat)
        if (counts[i] && sums[i] > 0) y.push_back(std::log(sums[i] / double(counts[i])) / 3);
    std::sort(y.begin(), y.end());
    return y;
}

// A stride's V: the pooled mean of R_s^2 / 216 over the blocks of `flat` (indices) with
// strided residuals that agree with the rest (the header's window); NaN without any such
// block, 0 where every one is silent.
double pooled_strided(const std::vector<double>& sums, const std::vector<std::uint32_t>& counts,
                      const std::vector<std::size_t>& flat, double clip) {
    const std::vector<double> sorted = sorted_log_variances(sums, counts, flat);
    if (sorted.empty()) {
        const bool silent = std::any_of(flat.begin(), flat.end(), [&](std::size_t i) { return counts[i] > 0; });
        return silent ? 0.0 : std::numeric_limits<double>::quiet_NaN();
    }
    const double centre = shorth_centre(sorted);
    const double robust = shorth_length(sorted) / 1.349;
    double sum = 0, count = 0;
    for (std::size_t i : flat) {
        if (!counts[i] || !(sums[i] > 0)) continue;
        if (std::abs(std::log(sums[i] / double(counts[i])) / 3 - centre) > clip * std::max(root_spread(counts[i]), robust))
            continue;
        sum += sums[i];
        count += double(counts[i]);
    }
    return sum / count;
}

// The widths of the model's grid: 0, then 0.2 .. 6 voxels in 400 steps even in log.
std::vector<double> width_grid() {
    std::vector<double> w{0.0};
    for (int i = 0; i < 400; ++i) w.push_back(0.2 * std::pow(30.0, double(i) / 399));
    return w;
}

struct CorrelationFit {
    std::array<double, 3> width{};  // NaN: no strided residual along the axis
    double white = 0;               // b, the white part's variance
    double error = 0;               // the fit's sum of squares
};

// How a fit weighs the strides: in log, (V(s e_a) - b) / (V(1) - b) against f(s) / f(1); or
// relative, V(s e_a) against b + (V(1) - b) f(s) / f(1), the difference over V(s e_a).
enum class FitScale { log, relative };

// Whether stride st reaches wider along one axis alone.
bool along_one_axis(const NoiseStride& st) { return int(st[0] > 1) + int(st[1] > 1) + int(st[2] > 1) == 1; }

// Per axis, the strides along it alone with a finite V: (stride, V), in the order of b.strides.
std::array<std::vector<std::pair<int, double>>, 3> strides_along(const NoiseBlocks& b, const std::vector<double>& v) {
    std::array<std::vector<std::pair<int, double>>, 3> along;
    for (std::size_t m = 0; m < b.strides.size(); ++m)
        for (int a = 0; a < 3 && along_one_axis(b.strides[m]); ++a)
            if (b.strides[m][a] > 1 && std::isfinite(v[m])) along[a].push_back({b.strides[m][a], v[m]});
    return along;
}

// The header's fit: per axis the w that fits the strides along a alone best, for the b in
// [0, V(1)) that fits the axes best.
CorrelationFit fit_correlation(const NoiseBlocks& b, const std::vector<double>& v, double v1, FitScale scale) {
    static const std::vector<double> widths = width_grid();
    const auto along = strides_along(b, v);
    // log(f(s) / f(1)) per axis, per stride along it, per width of the grid.
    std::array<std::vector<std::vector<double>>, 3> model;
    for (int a = 0; a < 3; ++a)
        for (const auto& stride_value : along[a]) {
            std::vector<double> row;
            for (double w : widths)
                row.push_back(std::log(noise_stride_factor(w, stride_value.first) / noise_stride_factor(w, 1)));
            model[a].push_back(row);
        }
    const double none = std::numeric_limits<double>::quiet_NaN();
    CorrelationFit best;
    best.width = {none, none, none};
    double best_error = std::numeric_limits<double>::infinity();
    // b = V(1) (1 - 10^-t) for t = 0, 0.004, .. 3.996: 0, then finer towards V(1).
    for (int k = 0; k < 1000; ++k) {
        const double white = v1 * (1 - std::pow(10.0, -0.004 * k));
        CorrelationFit fit;
        fit.white = white;
        fit.width = {none, none, none};
        double error = 0;
        bool feasible = true;
        for (int a = 0; a < 3 && feasible; ++a) {
            if (along[a].empty()) continue;
            std::vector<double> measured;
            for (const auto& stride_value : along[a]) {
                feasible = feasible && (scale == FitScale::relative || stride_value.second > white);
                measured.push_back(std::log((stride_value.second - white) / (v1 - white)));
            }
            double axis_best = std::numeric_limits<double>::infinity();
            for (std::size_t j = 0; feasible && j < widths.size(); ++j) {
                double e = 0;
                for (std::size_t q = 0; q < measured.size(); ++q) {
                    const double vs = along[a][q].second;
                    const double d = scale == FitScale::log
                                         ? measured[q] - model[a][q][j]
                                         : (vs - white - (v1 - white) * std::exp(model[a][q][j])) / vs;
                    e += d * d;
                }
                if (e < axis_best) axis_best = e, fit.width[a] = widths[j];
            }
            error += axis_best;
        }
        if (feasible && error < best_error) best_error = error, best = fit, best.error = error;
    }
    return best;
}

// Widths below this count as white: edges that taps 4 and 8 apart reach raise V(s) a little
// at every stride, which the model reads as a width of about 0.2 to 0.3 voxels.
constexpr double least_width = 0.35;

// The index of stride m in b.strides; b.strides.size() where the statistics do not hold m.
std::size_t stride_index(const NoiseBlocks& b, const NoiseStride& m) {
    return std::size_t(std::find(b.strides.begin(), b.strides.end(), m) - b.strides.begin());
}

// V at stride m (of b.strides); NaN where the statistics do not hold m.
double value_at(const NoiseBlocks& b, const std::vector<double>& v, const NoiseStride& m) {
    const std::size_t k = stride_index(b, m);
    return k < v.size() ? v[k] : std::numeric_limits<double>::quiet_NaN();
}

// The model's gain at stride m: the product over the axes of f_a(m_a) / 6, the share of the
// correlated part's variance that R_m / sqrt(216) keeps.
double stride_gain(const std::array<double, 3>& width, const NoiseStride& m) {
    double gain = 1;
    for (int a = 0; a < 3; ++a)
        gain *= noise_stride_factor(std::isnan(width[a]) ? 0.0 : width[a], m[a]) / 6;
    return gain;
}

// The least gain sigma is read at where a stride reaches it. bench/noise_correlated_bench.py's
// 132 correlated cases, median / worst |error| of sigma: read at 2 always, 2.4 / 43.7%; at the
// least gain 0.5, 2.8 / 103% (w = 1.5 then reads at 8, whose taps reach the anatomy); at 0.4,
// 2.7 / 103%; at 0.3, 2.2 / 31.1% (w = 1.5 reads at 4, gain 0.47).
constexpr double least_gain = 0.3;

// The strides sigma is read at: s along the correlated axes, 1 elsewhere, s the least of 2, 4
// and 8 whose gain reaches least_gain and whose V is finite (else the widest with a finite V,
// else 1): where the gain is small, sigma follows every error of the widths many times over (at
// w = 1.5 the gain at s = 2 is 0.008 and falls by 40% when w reads 1.6).
NoiseStride sigma_strides(const NoiseBlocks& b, const std::vector<double>& v, const std::array<double, 3>& width) {
    NoiseStride chosen{1, 1, 1};
    for (int s : {2, 4, 8}) {
        NoiseStride m{1, 1, 1};
        for (int a = 0; a < 3; ++a)
            if (width[a] > 0) m[a] = s;
        if (!std::isfinite(value_at(b, v, m))) continue;
        chosen = m;
        if (stride_gain(width, m) >= least_gain) break;
    }
    return chosen;
}

// correlation, sigma_strides and sigma of `r` from a fit, its widths under least_width taken
// as 0; true when an axis is correlated.
bool sigma_at_fit(const NoiseBlocks& b, const std::vector<double>& v, double v1, CorrelationFit fit, NoiseLevel& r) {
    for (double& w : fit.width)
        if (w < least_width) w = 0;
    r.correlation = fit.width;
    r.sigma_strides = sigma_strides(b, v, fit.width);
    const double vm = r.sigma_strides == NoiseStride{1, 1, 1} ? v1 : value_at(b, v, r.sigma_strides);
    const double gain = stride_gain(fit.width, r.sigma_strides);
    r.sigma = std::isfinite(vm) ? std::sqrt(std::max(vm - fit.white, 0.0) / gain + fit.white) : r.sigma_white;
    return fit.width[0] > 0 || fit.width[1] > 0 || fit.width[2] > 0;
}

// Whether the correlated part the fit finds can be told from structure. Structure that the
// wider taps reach (edges, shading) raises V(s) a little, faster the wider the taps (a smooth
// field's second difference grows as s^2, its square as s^4), which the model can read as a
// sliver of noise two or more voxels wide and so as a sigma many times sigma_white (the
// white-noise phantom of bench/memory_bench.py read 11x its noise). Such a fit is refused when
// both hold over the axes it calls correlated: V(s) rises faster at wider taps, the sums of
// V(8 e_a) - V(4 e_a) over 1.5 times those of V(4 e_a) - V(2 e_a) (the model's own f gives at
// most 1.43 up to w = 2.2 voxels: 0.05 at w = 1, 0.39 at 1.5), and the correlated part is a
// sliver, under a quarter of V(4 e_a) along some axis, (V(4 e_a) - b) / V(4 e_a) < 1/4 with b
// the fit's white part. Axes without strides 2, 4 and 8 are not counted.
bool told_from_structure(const NoiseBlocks& b, const std::vector<double>& v, const std::array<double, 3>& width,
                         double white) {
    const auto along = strides_along(b, v);
    double rise_wide = 0, rise_near = 0, least_share = 1;
    for (int a = 0; a < 3; ++a) {
        if (!(width[a] > 0)) continue;
        double at[9] = {};
        bool found[9] = {};
        for (const auto& [s, vs] : along[a])
            if (s <= 8) at[s] = vs, found[s] = true;
        if (!found[2] || !found[4] || !found[8] || !(at[4] > 0)) continue;
        rise_wide += at[8] - at[4];
        rise_near += at[4] - at[2];
        least_share = std::min(least_share, (at[4] - white) / at[4]);
    }
    return !(rise_wide > 1.5 * rise_near && least_share < 0.25);
}

// Texture: the ratio of V(2m) to sigma^2 read at m = 2 that noise never passes. The model's
// gain is at most 1 at every stride (f(s) <= 6), so V(2m) <= sigma^2 for noise, and structure
// that taps four apart reach raises it little: over bench/noise_correlated_bench.py's
// correlated cases read at m = 2, sqrt(V(4m)) / sigma is at most 1.15 (sigma read at 4 over
// sigma read at 2, both through the model); the lung CT's parenchyma reads 1.90.
constexpr double texture_ratio = 2.25;  // 1.5^2

// Whether the fit's correlated part is texture rather than noise: sigma read at 2 along the
// correlated axes, and V at 4 along them above texture_ratio sigma^2.
bool rises_beyond_noise(const NoiseBlocks& b, const std::vector<double>& v, const NoiseLevel& r) {
    NoiseStride wider = r.sigma_strides;
    for (int& s : wider) {
        if (s != 1 && s != 2) return false;
        if (s == 2) s = 4;
    }
    const double v4 = value_at(b, v, wider);
    return wider != r.sigma_strides && std::isfinite(v4) && v4 > texture_ratio * r.sigma * r.sigma;
}

// Structure: how far the flat blocks' y_b(s) = log(V_b(s)) / 3 at one stride spread (the
// shorth's length / 1.349) over what noise gives at their median count (root_spread). Noise
// keeps it near 1 (0.5 to 0.9 at sigma's strides over bench/noise_correlated_bench.py's
// cases; the CT phantom of ../shared/data/formats, whose noise varies between air and
// water, 2.1); structure that the model reads as wide correlated noise varies from block to
// block by orders of magnitude (smoothed walnut and stent CTs under white noise: 4.1 to 5.1,
// where sigma read 29 to 160 times the noise). Above structure_spread the correlation is
// refused.
constexpr double structure_spread = 3.0;

double spread_over_noise(const std::vector<double>& sums, const std::vector<std::uint32_t>& counts,
                         const std::vector<std::size_t>& flat) {
    const std::vector<double> y = sorted_log_variances(sums, counts, flat);
    if (y.size() < 2) return 0;
    std::vector<std::uint32_t> n;
    for (std::size_t i : flat)
        if (counts[i] && sums[i] > 0) n.push_back(counts[i]);
    std::nth_element(n.begin(), n.begin() + std::ptrdiff_t(n.size() / 2), n.end());
    return shorth_length(y) / 1.349 / root_spread(n[n.size() / 2]);
}

// `white` (the estimate before any fit) read as white noise: the widths 0 where an axis has
// strided residuals, sigma = sigma_white.
NoiseLevel read_as_white(const NoiseBlocks& b, const std::vector<double>& v, double v1,
                         const std::array<double, 3>& widths, NoiseLevel white) {
    CorrelationFit none{widths, 0.0, 0.0};
    for (double& w : none.width)
        if (!std::isnan(w)) w = 0;
    sigma_at_fit(b, v, v1, none, white);
    return white;
}

}  // namespace

NoiseLevel noise_level_from_blocks(const NoiseBlocks& b, const NoiseLevelOptions& o) {
    check_options(o, b.block);
    NoiseLevel r;
    r.block = b.block;
    r.blocks = b.count.size();
    const std::vector<BlockUse> use = usable_blocks(b);
    std::vector<double> y(use.size(), 0.0), sorted;
    double silent = 0;
    for (std::size_t i = 0; i < use.size(); ++i) {
        if (use[i] == BlockUse::noisy) sorted.push_back(y[i] = std::log(b.sum_squares[i] / double(b.count[i])) / 3);
        if (use[i] == BlockUse::silent) silent += double(b.count[i]), ++r.flat_blocks;
    }
    r.usable_blocks = sorted.size() + r.flat_blocks;
    if (sorted.empty()) {
        // No noise anywhere: sigma 0 on the silent blocks, NaN without any usable block.
        if (r.flat_blocks)
            r.sigma = r.sigma_white = 0, r.typical_variance = 0, r.flat_share = silent / double(b.volume.vertices());
        noise_map(b, use, b.sum_squares, b.count, {}, 0.0, o.map_block, r);
        return r;
    }
    r.flat_blocks = 0;
    std::sort(sorted.begin(), sorted.end());
    const double centre = shorth_centre(sorted);
    r.typical_variance = std::exp(3 * centre);
    double sum = 0, count = 0;
    std::vector<std::size_t> flat;
    for (std::size_t i = 0; i < use.size(); ++i) {
        if (use[i] != BlockUse::noisy || std::abs(y[i] - centre) > o.clip * root_spread(b.count[i])) continue;
        sum += b.sum_squares[i];
        count += double(b.count[i]);
        flat.push_back(i);
    }
    r.flat_blocks = flat.size();
    const double v1 = sum / count;
    r.sigma_white = std::sqrt(v1);
    r.flat_share = count / double(b.volume.vertices());
    // The strided V over the flat blocks, the correlation model, sigma at its strides.
    std::vector<double> v(b.strides.size());
    for (std::size_t m = 0; m < v.size(); ++m) v[m] = pooled_strided(b.strided_sums[m], b.strided_counts[m], flat, o.clip);
    // The fit in log; where it finds white noise, the relative fit, taken when its sigma is
    // over five times sigma_white and it fits ten times better than white noise (V(s) = V(1))
    // does (the rounding of integer data can hide strongly correlated noise from the log fit's
    // small differences; edges read by the wider taps give less, and on white noise any width
    // with b near V(1) fits about as well as none).
    // Either fit is taken only where its correlated part can be told from structure
    // (told_from_structure); else the noise reads as white, sigma = sigma_white.
    NoiseLevel relative = r, white_level = r;
    const CorrelationFit log_fit = fit_correlation(b, v, v1, FitScale::log);
    bool white = !sigma_at_fit(b, v, v1, log_fit, r);
    if (!white && !told_from_structure(b, v, r.correlation, log_fit.white)) {
        r = read_as_white(b, v, v1, r.correlation, white_level);
        white = true;
    }
    if (white) {
        const CorrelationFit fit = fit_correlation(b, v, v1, FitScale::relative);
        double white_error = 0;
        for (std::size_t m = 0; m < b.strides.size(); ++m) {
            const NoiseStride& st = b.strides[m];
            if (along_one_axis(st) && v[m] > 0)
                white_error += (v[m] - v1) * (v[m] - v1) / (v[m] * v[m]);
        }
        if (sigma_at_fit(b, v, v1, fit, relative) && relative.sigma > 5 * r.sigma_white &&
            fit.error * 10 < white_error && told_from_structure(b, v, relative.correlation, fit.white))
            r = relative;
    }
    // Texture or structure the model reads as correlated noise: the residuals rise beyond what
    // noise gives, or vary from block to block far more: refused, sigma = sigma_white, and said.
    const std::size_t k = stride_index(b, r.sigma_strides);
    if (rises_beyond_noise(b, v, r) ||
        (k < v.size() && spread_over_noise(b.strided_sums[k], b.strided_counts[k], flat) > structure_spread)) {
        r = read_as_white(b, v, v1, r.correlation, white_level);
        r.texture = true;
    }
    const std::size_t m = stride_index(b, r.sigma_strides);  // b.strides.size() for (1, 1, 1)
    if (m < v.size())
        noise_map(b, use, b.strided_sums[m], b.strided_counts[m], flat, v[m], o.map_block, r);
    else
        noise_map(b, use, b.sum_squares, b.count, flat, v1, o.map_block, r);
    return r;
}

bool noise_is_correlated(const NoiseLevel& l) { return l.sigma > 1.5 * l.sigma_white; }

double noise_variation(const NoiseLevel& l) {
    return l.spread[0] > 0 ? l.spread[2] / l.spread[0] : std::numeric_limits<double>::quiet_NaN();
}

namespace {

std::string three_digits(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return text;
}

}  // namespace

std::vector<std::string> noise_level_notes(const NoiseLevel& l) {
    std::vector<std::string> notes;
    const double variation = noise_variation(l);
    if (variation > 1.5)
        notes.push_back("noise varies " + three_digits(variation) + "x across the volume (the map's 90th percentile " +
                        three_digits(l.spread[2]) + " over its 10th " + three_digits(l.spread[0]) +
                        "; cells whose blocks mostly hold structure read high too)");
    if (l.texture)
        notes.push_back("the residuals at the wider taps rise or vary beyond what noise gives (texture or "
                        "structure, not noise): sigma is the white part, " + three_digits(l.sigma_white) +
                        ", and noise correlated across neighbours may be more");
    if (noise_is_correlated(l)) {
        std::string widths;
        for (int a = 0; a < 3; ++a)
            widths += (a ? ", " : "") + (std::isnan(l.correlation[a]) ? std::string("n/a") : three_digits(l.correlation[a]));
        notes.push_back("the noise is correlated (widths " + widths + " voxels along x, y, z): a white-noise estimate "
                        "reads its white part, " + three_digits(l.sigma_white) + ", " +
                        three_digits(l.sigma / l.sigma_white) + "x less than sigma " + three_digits(l.sigma) +
                        "; Theorem 1 (r(s) and its amplitudes) assumes independent noise as well, and correlated "
                        "noise roughens surfaces less than independent noise of the same sigma, so it under-states "
                        "this noise too");
    }
    return notes;
}

NoiseLevel estimate_noise_level(const DeviceVolume& v, const NoiseLevelOptions& o) {
    const std::size_t block = o.block ? o.block : noise_block_side(v.dims());
    check_options(o, block);
    const ComputeTimer timer(v.context());
    const NoiseBlocks b = noise_blocks(v, block);
    const double seconds = timer.seconds();
    NoiseLevel r = noise_level_from_blocks(b, o);
    r.seconds = seconds;
    return r;
}

NoiseLevel estimate_noise_level(Context& ctx, const Volume& v, const NoiseLevelOptions& o) {
    const std::size_t block = o.block ? o.block : noise_block_side(v.dims());
    check_options(o, block);
    const ComputeTimer timer(ctx);
    const NoiseBlocks b = noise_blocks(ctx, v, block, o.slab_slices);
    const double seconds = timer.seconds();
    NoiseLevel r = noise_level_from_blocks(b, o);
    r.seconds = seconds;
    return r;
}

}  // namespace clfractal
