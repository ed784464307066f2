#include "clfractal/sat.hpp"

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
template <class C> std::size_t group_size(Context& ctx, const cl::Kernel& k) {
    std::size_t kmax = k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(ctx.device());
    std::size_t wg = std::min({ctx.tuning.sat_work_group, kmax, ctx.local_mem() / sizeof(C)});
    return std::max<std::size_t>(1, wg);
}

}  // namespace

template <class C> void summed_area_table(Context& ctx, Buffer<C>& table, const Dims& d) {
    static_assert(std::is_same_v<C, cl_uint> || std::is_same_v<C, cl_ulong>, "counts are cl_uint or cl_ulong");
    if (table.size() != d.vertices())
        throw std::logic_error("summed_area_table: the buffer holds " + std::to_string(table.size()) +
                               " counts, not " + dims_string(d));
    if (d.vertices() == 0) return;
    const std::string& variant = ctx.tuning.sat_variant;
    const std::string options = defines({{"C", count_type<C>()}});
    // The three passes as [outer][n][inner], scanned along n (see kernels/sat.cl).
    struct Pass {
        std::size_t outer, n, inner;
    };
    const Pass passes[3] = {{d.ny * d.nz, d.nx, 1}, {d.nz, d.ny, d.nx}, {1, d.nz, d.nx * d.ny}};
    with_cl_errors([&] {
        if (variant == "sequential") {
            cl::Kernel lines = ctx.kernel("sat", "scan_lines_sequential", options);
            cl::Kernel rows = ctx.kernel("sat", "scan_rows_sequential", options);
            const std::size_t items = ctx.tuning.row_items ? ctx.tuning.row_items : 4 * ctx.compute_units();
            lines.setArg(0, table.get());
            lines.setArg(1, int(d.nx));
            lines.setArg(2, cl_ulong(passes[0].outer));
            if (d.nx > 1) ctx.launch(lines, cl::NDRange(items), cl::NDRange(1));
            for (const Pass& p : {passes[1], passes[2]}) {
                if (p.n < 2) continue;
                rows.setArg(0, table.get());
                rows.setArg(1, int(p.n));
                rows.setArg(2, cl_ulong(p.inner));
                rows.setArg(3, cl_ulong(p.outer));
                rows.setArg(4, cl_ulong(row_chunk));
                ctx.launch(rows, cl::NDRange(items), cl::NDRange(1));
            }
        } else if (variant == "workgroup") {
            cl::Kernel lines = ctx.kernel("sat", "scan_lines_workgroup", options);
            cl::Kernel columns = ctx.kernel("sat", "scan_columns_workgroup", options);
            if (d.nx > 1) {
                const std::size_t wg = group_size<C>(ctx, lines);
                lines.setArg(0, table.get());
                lines.setArg(1, int(d.nx));
                lines.setArg(2, cl::Local(wg * sizeof(C)));
                ctx.launch(lines, cl::NDRange(wg, d.ny, d.nz), cl::NDRange(wg, 1, 1));
            }
            // 32 adjacent columns make a coalesced load of 128 bytes (uint) on GPUs.
            const std::size_t wg = group_size<C>(ctx, columns);
            const std::size_t tx = std::min<std::size_t>(wg, 32), tl = wg / tx;
            for (const Pass& p : {passes[1], passes[2]}) {
                if (p.n < 2) continue;
                columns.setArg(0, table.get());
                columns.setArg(1, int(p.n));
                columns.setArg(2, cl_ulong(p.inner));
                columns.setArg(3, cl::Local(tx * tl * sizeof(C)));
                ctx.launch(columns, cl::NDRange((p.inner + tx - 1) / tx * tx, tl, p.outer), cl::NDRange(tx, tl, 1));
            }
        } else {
            throw std::logic_error("unknown summed-area table variant '" + variant + "'");
        }
    });
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
