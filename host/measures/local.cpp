#include "clfractal/local.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>

#include "clfractal/pyramid.hpp"
#include "clfractal/sat.hpp"
#include "device/slab_plan.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "measures/local_queries.hpp"

namespace clfractal {

namespace {

void check_window(int window) {
    const std::string problem = window_problem(window);
    if (!problem.empty()) throw InputError("--window " + std::to_string(window) + ": " + problem);
}

}  // namespace

std::string window_problem(int window) {
    return window < 2 || window % 2 != 0 ? "the window must be even and at least 2" : "";
}

void check_local_arguments(double iso, int window) {
    check_window(window);
    if (!std::isfinite(iso)) throw InputError("--iso: the isovalue must be a finite number");
}

std::vector<LocalWindow> local_windows(std::size_t n, int window) {
    check_window(window);
    if (n > std::size_t(std::numeric_limits<std::int32_t>::max()))
        throw InputError("an axis of " + std::to_string(n) + " vertices is longer than the local dimension's 2^31 - 1");
    const long long half = window / 2, m = (static_cast<long long>(n) - 1) / 2 + 1;
    std::vector<LocalWindow> w(n);
    for (long long x = 0; x < static_cast<long long>(n); ++x) {
        // c0 = floor((x - k/2) / 2), with floor division for negative values too.
        const long long d = x - half, c0 = d >= 0 ? d / 2 : -((1 - d) / 2);
        const long long b0 = std::max(0LL, c0), b1 = std::max(b0, std::min(m - 1, c0 + half));
        w[std::size_t(x)] = LocalWindow{std::int32_t(2 * b0), std::int32_t(2 * b1), std::int32_t(b0), std::int32_t(b1)};
    }
    return w;
}

namespace {

}  // namespace

template <class C>
void window_log_ratios(Context& ctx, const Buffer<C>& table, const Dims& d, const Buffer<C>& table_sub, int window,
                       const std::string& options, const cl::Buffer& out) {
    const Dims ds = level_dims(d, 1);
    const bool rows = ctx.tuning.local_variant == LocalVariant::rows;
    const std::size_t items = row_items(ctx);
    Buffer<C> scratch(ctx, rows ? items * (d.nx + ds.nx) : 0);
    // The window tables of the three axes, x then y then z (local_windows).
    std::vector<LocalWindow> windows;
    for (std::size_t n : {d.nx, d.ny, d.nz}) {
        const std::vector<LocalWindow> w = local_windows(n, window);
        windows.insert(windows.end(), w.begin(), w.end());
    }
    const Buffer<LocalWindow> window_table(ctx, windows);
    // kernels/local.cl local_dimension_*(table, nx, ny, nz, table_sub, mx, my, mz, win, ld
    // [, scratch]).
    using Vertices = KernelCall<cl::Buffer, int, int, int, cl::Buffer, int, int, int, cl::Buffer, cl::Buffer>;
    using Rows = KernelCall<cl::Buffer, int, int, int, cl::Buffer, int, int, int, cl::Buffer, cl::Buffer, cl::Buffer>;
    const int nx = int(d.nx), ny = int(d.ny), nz = int(d.nz), mx = int(ds.nx), my = int(ds.ny), mz = int(ds.nz);
    if (rows)
        Rows(ctx, "local", "local_dimension_rows", options)(cl::NDRange(items), cl::NDRange(1), table.get(), nx, ny, nz,
                                                            table_sub.get(), mx, my, mz, window_table.get(), out,
                                                            scratch.get());
    else
        Vertices(ctx, "local", "local_dimension_vertices", options)(cl::NDRange(d.nx, d.ny, d.nz), cl::NullRange,
                                                                    table.get(), nx, ny, nz, table_sub.get(), mx, my,
                                                                    mz, window_table.get(), out);
}

template void window_log_ratios<cl_uint>(Context&, const Buffer<cl_uint>&, const Dims&, const Buffer<cl_uint>&, int,
                                         const std::string&, const cl::Buffer&);
template void window_log_ratios<cl_ulong>(Context&, const Buffer<cl_ulong>&, const Dims&, const Buffer<cl_ulong>&, int,
                                          const std::string&, const cl::Buffer&);

namespace {

// Writes the LD field of `values` (d.vertices() values of `type`) into `ld` (d.vertices()
// floats), with C-bit tables.
template <class C>
void field_on_device(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso, int window,
                     const cl::Buffer& ld) {
    const Dims ds = level_dims(d, 1);
    const std::size_t table_bytes = d.vertices() * sizeof(C);
    if (table_bytes > ctx.max_alloc() || d.vertices() * sizeof(float) > ctx.max_alloc())
        throw InputError("volume " + dims_string(d) + ": the local-dimension tables need " +
                         std::to_string(table_bytes >> 20) + " MiB, more than the device's largest allocation (" +
                         std::to_string(ctx.max_alloc() >> 20) + " MiB)");
    const bool rows = ctx.tuning.local_variant == LocalVariant::rows;
    const std::size_t items = row_items(ctx);

    const std::string options =
        single_isovalue_options(type) + defines({{"C", std::is_same_v<C, cl_ulong> ? "ulong" : "uint"}});
    // kernels/local.cl cube_indicator_*(vol, nx, ny, nz, s, table).
    KernelCall<cl::Buffer, int, int, int, ScalarArg, cl::Buffer> indicator(
        ctx, "local", rows ? "cube_indicator_rows" : "cube_indicator_vertices", options);

    Buffer<unsigned char> sub(ctx, ds.vertices() * value_size(type));
    Buffer<C> table(ctx, d.vertices()), table_sub(ctx, ds.vertices());
    subsample(ctx, values, type, d, sub.get());

    auto indicator_table = [&](const cl::Buffer& vol, const Dims& dims, Buffer<C>& out) {
        const cl::NDRange global = rows ? cl::NDRange(items) : cl::NDRange(dims.nx, dims.ny, dims.nz);
        indicator(global, rows ? cl::NDRange(1) : cl::NullRange, vol, int(dims.nx), int(dims.ny), int(dims.nz),
                  isovalue_arg(type, iso), out.get());
        summed_area_table(ctx, out, dims);
    };
    indicator_table(values, d, table);
    indicator_table(sub.get(), ds, table_sub);

    window_log_ratios(ctx, table, d, table_sub, window, options, ld);
}

void field_on_device(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso, int window,
                     const cl::Buffer& ld) {
    check_local_arguments(iso, window);
    check_dims(d, "volume");
    with_cl_errors([&] {
        if (d.cubes() > ctx.tuning.sat_max_32bit) field_on_device<cl_ulong>(ctx, values, type, d, iso, window, ld);
        else field_on_device<cl_uint>(ctx, values, type, d, iso, window, ld);
    });
}

}  // namespace

Dims ld_block_dims(const Dims& d, int window) {
    const std::size_t p = std::size_t(ld_block_phase(window));
    return Dims{(d.nx + p + 1) / 2, (d.ny + p + 1) / 2, (d.nz + p + 1) / 2};
}

namespace {

// The summed-area tables of block_local_dimension (the intersected G cubes inside each G'
// cube, and the G' indicator, both mx × my × mz padded) and the window tables of G.
template <class C> struct BlockTables {
    Buffer<C> counts, sub;
    Buffer<LocalWindow> windows;
};

template <class C>
BlockTables<C> block_tables(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso,
                            int window, const std::string& options) {
    const Dims ds = level_dims(d, 1);
    Buffer<C> counts(ctx, ds.vertices()), sub(ctx, ds.vertices());
    // Tuning::local_variant as for the full field: whole rows per work-item on CPUs.
    // kernels/local.cl block_indicators[_rows](vol, nx, ny, nz, s, [snx, sny, snz,] counts, sub).
    if (ctx.tuning.local_variant == LocalVariant::rows) {
        KernelCall<cl::Buffer, int, int, int, ScalarArg, int, int, int, cl::Buffer, cl::Buffer> indicators(
            ctx, "local", "block_indicators_rows", options);
        indicators(cl::NDRange(row_items(ctx)), cl::NDRange(1), values, int(d.nx), int(d.ny), int(d.nz),
                   isovalue_arg(type, iso), int(ds.nx), int(ds.ny), int(ds.nz), counts.get(), sub.get());
    } else {
        KernelCall<cl::Buffer, int, int, int, ScalarArg, cl::Buffer, cl::Buffer> indicators(ctx, "local",
                                                                                          "block_indicators", options);
        indicators(cl::NDRange(ds.nx, ds.ny, ds.nz), cl::NullRange, values, int(d.nx), int(d.ny), int(d.nz),
                   isovalue_arg(type, iso), counts.get(), sub.get());
    }
    summed_area_table(ctx, counts, ds);
    summed_area_table(ctx, sub, ds);
    std::vector<LocalWindow> windows;
    for (std::size_t n : {d.nx, d.ny, d.nz}) {
        const std::vector<LocalWindow> w = local_windows(n, window);
        windows.insert(windows.end(), w.begin(), w.end());
    }
    Buffer<LocalWindow> window_table(ctx, windows.size(), CL_MEM_READ_ONLY);
    window_table.write(ctx.queue(), windows.data(), windows.size());
    return BlockTables<C>{std::move(counts), std::move(sub), std::move(window_table)};
}

std::string block_options(ValueType type, bool wide) {
    return single_isovalue_options(type) + defines({{"C", wide ? "ulong" : "uint"}});
}

template <class C>
void block_field(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso, int window,
                 const cl::Buffer& ld) {
    const Dims ds = level_dims(d, 1), hb = ld_block_dims(d, window);
    const std::string options = block_options(type, std::is_same_v<C, cl_ulong>);
    const BlockTables<C> tables = block_tables<C>(ctx, values, type, d, iso, window, options);
    const Buffer<C>& counts = tables.counts;
    const Buffer<C>& sub = tables.sub;
    const Buffer<LocalWindow>& window_table = tables.windows;
    if (ctx.tuning.local_variant == LocalVariant::rows) {
        // block_dimension_rows(counts, sub, snx, sny, windows, nx, ny, phase, bnx, bny, bnz, ld, scratch).
        const std::size_t items = row_items(ctx);
        Buffer<C> scratch(ctx, items * 2 * ds.nx);
        KernelCall<cl::Buffer, cl::Buffer, int, int, cl::Buffer, int, int, int, int, int, int, cl::Buffer, cl::Buffer>
            query(ctx, "local", "block_dimension_rows", options);
        query(cl::NDRange(items), cl::NDRange(1), counts.get(), sub.get(), int(ds.nx), int(ds.ny), window_table.get(),
              int(d.nx), int(d.ny), ld_block_phase(window), int(hb.nx), int(hb.ny), int(hb.nz), ld, scratch.get());
    } else {
        // block_dimension(counts, sub, snx, sny, windows, nx, ny, phase, bnx, bny, ld).
        KernelCall<cl::Buffer, cl::Buffer, int, int, cl::Buffer, int, int, int, int, int, cl::Buffer> query(
            ctx, "local", "block_dimension", options);
        // A fixed work-group size: PoCL compiles a kernel once per work-group size.
        const std::size_t wg = std::min<std::size_t>(16, ctx.max_work_group());
        query(cl::NDRange((hb.nx + wg - 1) / wg * wg, hb.ny, hb.nz), cl::NDRange(wg, 1, 1), counts.get(), sub.get(),
              int(ds.nx), int(ds.ny), window_table.get(), int(d.nx), int(d.ny), ld_block_phase(window), int(hb.nx),
              int(hb.ny), ld);
    }
}

void check_block_arguments(const Dims& d, double iso, int window) {
    check_local_arguments(iso, window);
    check_dims(d, "volume");
    local_windows(std::max({d.nx, d.ny, d.nz}), window);  // axis length check
}

// block_selection with C-bit tables.
template <class C>
void block_select(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso, int window,
                  float h, const cl::Buffer& sel) {
    const Dims ds = level_dims(d, 1), hb = ld_block_dims(d, window);
    const std::string options = block_options(type, std::is_same_v<C, cl_ulong>);
    const BlockTables<C> t = block_tables<C>(ctx, values, type, d, iso, window, options);
    const std::size_t items = row_items(ctx);
    Buffer<C> scratch(ctx, items * 2 * ds.nx);
    // The ratios a / b that settle LD > h without log2 (kernels/local.cl above()).
    const double power = std::exp2(double(h));
    const float lo = float(power * (1 - 1.0 / 1024)), hi = float(power * (1 + 1.0 / 1024));
    // block_selection_rows(counts, sub, snx, sny, windows, nx, ny, phase, bnx, bny, bnz, h, lo, hi, sel, scratch).
    KernelCall<cl::Buffer, cl::Buffer, int, int, cl::Buffer, int, int, int, int, int, int, float, float, float,
               cl::Buffer, cl::Buffer>
        query(ctx, "local", "block_selection_rows", options);
    query(cl::NDRange(items), cl::NDRange(1), t.counts.get(), t.sub.get(), int(ds.nx), int(ds.ny), t.windows.get(),
          int(d.nx), int(d.ny), ld_block_phase(window), int(hb.nx), int(hb.ny), int(hb.nz), h, lo, hi, sel,
          scratch.get());
}

}  // namespace

Buffer<float> block_local_dimension(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso,
                                    int window) {
    check_block_arguments(d, iso, window);
    Buffer<float> ld(ctx, ld_block_dims(d, window).vertices());
    with_cl_errors([&] {
        // The counts of a G' box are at most 8 times its G' cubes: 32 bits hold them while
        // G has at most sat_max_32bit cubes, as for local_fractal_dimension.
        if (d.cubes() > ctx.tuning.sat_max_32bit) block_field<cl_ulong>(ctx, values, type, d, iso, window, ld.get());
        else block_field<cl_uint>(ctx, values, type, d, iso, window, ld.get());
    });
    return ld;
}

Buffer<cl_uchar> block_selection(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso,
                                 int window, float h) {
    check_block_arguments(d, iso, window);
    Buffer<cl_uchar> sel(ctx, ld_block_dims(d, window).vertices());
    with_cl_errors([&] {
        if (d.cubes() > ctx.tuning.sat_max_32bit) block_select<cl_ulong>(ctx, values, type, d, iso, window, h, sel.get());
        else block_select<cl_uint>(ctx, values, type, d, iso, window, h, sel.get());
    });
    return sel;
}


namespace {

// The block field spread over the vertices into `ld`: the same values as field_on_device at a
// fraction of the cost.
void block_field_on_device(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& d, double iso,
                           int window, const cl::Buffer& ld) {
    const Buffer<float> blocks = block_local_dimension(ctx, values, type, d, iso, window);
    with_cl_errors([&] {
        const Dims hb = ld_block_dims(d, window);
        // expand_blocks(blocks, bnx, bny, phase, ld).
        KernelCall<cl::Buffer, int, int, int, cl::Buffer> expand(
            ctx, "local", "expand_blocks", single_isovalue_options(type) + defines({{"C", "uint"}}));
        expand(cl::NDRange(d.nx, d.ny, d.nz), cl::NullRange, blocks.get(), int(hb.nx), int(hb.ny),
               ld_block_phase(window), ld);
    });
}

}  // namespace

DeviceVolume local_fractal_dimension(const DeviceVolume& v, double iso, int window) {
    DeviceVolume ld = allocate_like(v, ValueType::float32);
    block_field_on_device(v.context(), v.buffer(), v.type(), v.dims(), iso, window, ld.buffer());
    return ld;
}

namespace {

// The slab need of the LD field of a grid of `d`: per slice the values, the field, the table
// (64-bit when the grid may need it) and the subsampled values and table (an eighth); the
// tables and the field within the largest allocation, the run within a third of the
// device's memory, the values within Tuning::slab_bytes (which tests lower to force slabs).
SlabNeed local_need(const Context& ctx, const Dims& d, ValueType type, std::size_t halo) {
    const std::size_t plane = d.nx * d.ny, table = d.cubes() > ctx.tuning.sat_max_32bit ? 8 : 4;
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = plane * value_size(type);
    need.slice_bytes = plane * (value_size(type) * 9 / 8 + 4 + 8 * 9 / 8 + 1);
    need.largest_slice_bytes = plane * table;
    need.memory_divisor = 3;
    need.halo = halo;
    return need;
}

Volume local_in_core(Context& ctx, const Volume& v, double iso, int window);

// Out of core: output slices [a, b) from the input slab [lo, hi) with lo = a - k/2 rounded
// down to even (so the slab's level-1 slices are the volume's) and hi = b + k/2: every
// window of those slices lies inside the slab, or meets the volume's ends where the slab
// ends too, so each slab gives exactly the whole-volume values.
// The input slab of `depth` output slices: k/2 more on each side, one more where the start
// is rounded down to even.
Volume local_in_slabs(Context& ctx, const Volume& v, double iso, int window, std::size_t depth) {
    const Dims d = v.dims();
    const std::size_t plane = d.nx * d.ny, slice_bytes = plane * value_size(v.type());
    Volume out(d, ValueType::float32, v.name);
    out.spacing = v.spacing;
    for (std::size_t a = 0; a < d.nz; a += depth) {
        const std::size_t b = std::min(d.nz, a + depth);
        const auto [lo, hi] = ld_input_slices(a, b, d.nz, window);
        Volume slab(Dims{d.nx, d.ny, hi - lo}, v.type());
        std::memcpy(slab.data(), static_cast<const unsigned char*>(v.data()) + lo * slice_bytes, slab.size_bytes());
        const Volume f = local_in_core(ctx, slab, iso, window);
        std::memcpy(out.as<float>() + a * plane, f.as<float>() + (a - lo) * plane, (b - a) * plane * sizeof(float));
    }
    return out;
}

}  // namespace

Volume local_fractal_dimension(Context& ctx, const Volume& v, double iso, int window) {
    check_local_arguments(iso, window);
    const Dims d = v.dims();
    std::size_t depth = d.nz;  // output slices per pass: all of them in core
    if (d.nz > 1 && slab_fit(ctx, local_need(ctx, d, v.type(), 0)) < d.nz)
        depth = plan_slab(ctx, local_need(ctx, d, v.type(), std::size_t(window / 2) + 1), d);
    // On a CPU device the buffers are host memory: where the tables beside the values and
    // the field would pass a volume + 128 MiB, slabs whose buffers take about 192 MiB (the
    // process then holds the values, the field and one slab).
    if (ctx.is_cpu() && !ctx.tuning.slab_bytes && d.nz > 1) {
        const SlabNeed need = local_need(ctx, d, v.type(), 0);
        const std::size_t plane = d.nx * d.ny, tables = need.slice_bytes - plane * (value_size(v.type()) + 4);
        if (tables * d.nz > v.size_bytes() + (std::size_t(128) << 20)) {
            const std::size_t slab_slice = need.slice_bytes + plane * (value_size(v.type()) + 4);
            depth = std::min(depth, std::max<std::size_t>(std::size_t(window) + 2,
                                                          (std::size_t(192) << 20) / std::max<std::size_t>(1, slab_slice)));
        }
    }
    return with_smaller_slabs(depth, [&](std::size_t slab) {
        return slab >= d.nz ? local_in_core(ctx, v, iso, window) : local_in_slabs(ctx, v, iso, window, slab);
    });
}

namespace {

Volume local_in_core(Context& ctx, const Volume& v, double iso, int window) {
    Volume out(v.dims(), ValueType::float32, v.name);
    out.spacing = v.spacing;
    const DeviceVolume values(ctx, v);
    const DeviceVolume ld = DeviceVolume::output(ctx, out);
    if (ctx.tuning.local_blocks) block_field_on_device(ctx, values.buffer(), v.type(), v.dims(), iso, window, ld.buffer());
    else field_on_device(ctx, values.buffer(), v.type(), v.dims(), iso, window, ld.buffer());
    ld.download_to(out);
    return out;
}

}  // namespace


Rgb ld_colour(double ld) {
    if (std::isnan(ld)) return Rgb{128, 128, 128};
    const double t = std::clamp((ld - ld_blue) / (ld_red - ld_blue), 0.0, 1.0);
    const auto r = std::uint8_t(std::lround(255 * t));
    return Rgb{r, 0, std::uint8_t(255 - r)};
}

LocalSummary summarize_local(const Volume& ld) {
    const float* p = ld.as<float>();
    const long long n = (long long)ld.vertices();
    std::size_t defined = 0, above_blue = 0, above_red = 0;
    double sum = 0;
#pragma omp parallel for reduction(+ : defined, above_blue, above_red, sum) schedule(static)
    for (long long i = 0; i < n; ++i) {
        if (std::isnan(p[i])) continue;
        ++defined;
        above_blue += p[i] > ld_blue;
        above_red += p[i] > ld_red;
        sum += p[i];
    }
    LocalSummary s;
    s.vertices = ld.vertices();
    s.defined = defined;
    s.above_blue = defined ? double(above_blue) / double(defined) : 0;
    s.above_red = defined ? double(above_red) / double(defined) : 0;
    s.mean = defined ? sum / double(defined) : std::numeric_limits<double>::quiet_NaN();
    return s;
}

}  // namespace clfractal
