#include "clfractal/sat.hpp"

#include "device/slab_plan.hpp"
#include "device/kernel_call.hpp"

#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace clfractal {

namespace {

// Inner indices per task of the sequential row scans: two rows of this stretch stay in
// the first-level cache from one row to the next.
constexpr std::size_t row_chunk = 2048;

template <class C> const char* count_type() { return std::is_same_v<C, cl_ulong> ? "ulong" : "uint"; }

// Work-group size for a kernel: the tuning value, within the kernel's and local memory's limits.
template <class C> std::size_t group_size(Context& ctx, std::size_t kmax) {
    std::size_t wg = std::min({ctx.tuning.sat_work_group, kmax, ctx.local_mem() / sizeof(C)});
    return std::max<std::size_t>(1, wg);
}

// The scans of the d.vertices() counts (C) of `table`, in place.
template <class C> void scan_table(Context& ctx, const cl::Buffer& table, const Dims& d) {
    if (d.vertices() == 0) return;
    const std::string options = defines({{"C", count_type<C>()}});
    // The three passes as [outer][n][inner], scanned along n (see kernels/sat.cl).
    struct Pass {
        std::size_t outer, n, inner;
    };
    const Pass passes[3] = {{d.ny * d.nz, d.nx, 1}, {d.nz, d.ny, d.nx}, {1, d.nz, d.nx * d.ny}};
    with_cl_errors([&] {
        if (ctx.tuning.sat_variant == SatVariant::sequential) {
            // kernels/sat.cl scan_lines_sequential(table, n, lines), scan_rows_sequential(table,
            // n, inner, outer, chunk).
            KernelCall<cl::Buffer, int, cl_ulong> lines(ctx, "sat", "scan_lines_sequential", options);
            KernelCall<cl::Buffer, int, cl_ulong, cl_ulong, cl_ulong> rows(ctx, "sat", "scan_rows_sequential", options);
            const cl::NDRange items(row_items(ctx)), one(1);
            if (d.nx > 1) lines(items, one, table, int(d.nx), cl_ulong(passes[0].outer));
            for (const Pass& p : {passes[1], passes[2]})
                if (p.n >= 2) rows(items, one, table, int(p.n), cl_ulong(p.inner), cl_ulong(p.outer), cl_ulong(row_chunk));
        } else {
            // scan_lines_workgroup(table, n, scratch), scan_columns_workgroup(table, n, inner, scratch).
            KernelCall<cl::Buffer, int, cl::LocalSpaceArg> lines(ctx, "sat", "scan_lines_workgroup", options);
            KernelCall<cl::Buffer, int, cl_ulong, cl::LocalSpaceArg> columns(ctx, "sat", "scan_columns_workgroup", options);
            if (d.nx > 1) {
                const std::size_t wg = group_size<C>(ctx, lines.work_group_limit());
                lines(cl::NDRange(wg, d.ny, d.nz), cl::NDRange(wg, 1, 1), table, int(d.nx), cl::Local(wg * sizeof(C)));
            }
            // 32 adjacent columns make a coalesced load of 128 bytes (uint) on GPUs.
            const std::size_t wg = group_size<C>(ctx, columns.work_group_limit());
            const std::size_t tx = std::min<std::size_t>(wg, 32), tl = wg / tx;
            for (const Pass& p : {passes[1], passes[2]})
                if (p.n >= 2)
                    columns(cl::NDRange((p.inner + tx - 1) / tx * tx, tl, p.outer), cl::NDRange(tx, tl, 1), table,
                            int(p.n), cl_ulong(p.inner), cl::Local(tx * tl * sizeof(C)));
        }
    });
}

}  // namespace

template <class C> void summed_area_table(Context& ctx, Buffer<C>& table, const Dims& d) {
    static_assert(std::is_same_v<C, cl_uint> || std::is_same_v<C, cl_ulong>, "counts are cl_uint or cl_ulong");
    if (table.size() != d.vertices())
        throw std::logic_error("summed_area_table: the buffer holds " + std::to_string(table.size()) +
                               " counts, not " + dims_string(d));
    scan_table<C>(ctx, table.get(), d);
}

DeviceVolume summed_area_table(const DeviceVolume& counts) {
    if (counts.type() != ValueType::uint32)
        throw InputError(std::string("summed_area_table: counts are uint32, not ") + value_type_name(counts.type()));
    DeviceVolume table = allocate_like(counts, ValueType::uint32);
    Context& ctx = counts.context();
    with_cl_errors([&] {
        if (counts.bytes()) ctx.queue().enqueueCopyBuffer(counts.buffer(), table.buffer(), 0, 0, counts.bytes());
        scan_table<cl_uint>(ctx, table.buffer(), counts.dims());
    });
    return table;
}

template <class C> std::vector<C> summed_area_table(Context& ctx, const std::vector<C>& values, const Dims& d) {
    if (values.size() != d.vertices())
        throw std::logic_error("summed_area_table: " + std::to_string(values.size()) + " values for " +
                               dims_string(d));
    return with_cl_errors([&] {
        Buffer<C> table(ctx, values.size());
        table.write(ctx.queue(), values.data(), values.size());
        summed_area_table(ctx, table, d);
        return table.to_host(ctx.queue());
    });
}

template void summed_area_table<cl_uint>(Context&, Buffer<cl_uint>&, const Dims&);
template void summed_area_table<cl_ulong>(Context&, Buffer<cl_ulong>&, const Dims&);
template std::vector<cl_uint> summed_area_table<cl_uint>(Context&, const std::vector<cl_uint>&, const Dims&);
template std::vector<cl_ulong> summed_area_table<cl_ulong>(Context&, const std::vector<cl_ulong>&, const Dims&);

}  // namespace clfractal
