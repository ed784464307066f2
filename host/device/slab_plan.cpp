#include "device/slab_plan.hpp"

#include <algorithm>
#include <climits>
#include <string>

namespace clfractal {

namespace {

std::size_t at_least_1(std::size_t x) { return std::max<std::size_t>(1, x); }

// Input slices one slab may hold under the device's limits (or Tuning::slab_bytes).
std::size_t input_slices(const Context& ctx, const SlabNeed& n) {
    if (ctx.tuning.slab_bytes) return ctx.tuning.slab_bytes / at_least_1(n.input_slice_bytes);
    const std::size_t slice = n.slice_bytes ? n.slice_bytes : n.input_slice_bytes;
    const std::size_t largest = n.largest_slice_bytes ? n.largest_slice_bytes : slice;
    const std::size_t cap = n.largest_bytes ? std::min(n.largest_bytes, ctx.max_alloc()) : ctx.max_alloc();
    return std::min(cap / at_least_1(largest), ctx.global_mem() / at_least_1(n.memory_divisor) / at_least_1(slice));
}

}  // namespace

std::size_t slab_fit(const Context& ctx, const SlabNeed& n) {
    std::size_t depth;
    if (n.forced) {
        depth = n.forced;
    } else {
        const std::size_t in = input_slices(ctx, n);
        depth = in > 2 * n.halo ? in - 2 * n.halo : (ctx.tuning.slab_bytes || n.halo == 0 ? 1 : 0);
    }
    if (n.max_slices) depth = std::min(depth, n.max_slices);
    if (depth >= n.nz) return n.nz;
    const std::size_t step = n.shared_step;
    if (step == 0 || depth == 0) return depth;
    // Slabs share their last slice with the next one, which starts a multiple of step later.
    return depth > step ? (depth - 1) / step * step + 1 : 0;
}

std::size_t plan_slab(const Context& ctx, const SlabNeed& need, const Dims& d) {
    const std::size_t depth = slab_fit(ctx, need);
    if (depth == 0)
        throw InputError("volume: a slab of " + std::to_string(need.shared_step ? need.shared_step + 1 : 2 * need.halo + 1) +
                         " slices of " + std::to_string(d.nx) + "x" + std::to_string(d.ny) +
                         " does not fit the device's memory or the slab limit");
    return depth;
}

std::size_t row_items(const Context& ctx) {
    return ctx.tuning.row_items ? ctx.tuning.row_items : 4 * ctx.compute_units();
}

bool int_axes(const Dims& d) {
    return d.nx <= std::size_t(INT_MAX) && d.ny <= std::size_t(INT_MAX) && d.nz <= std::size_t(INT_MAX);
}

void check_int_axes(const Dims& d) {
    if (!int_axes(d)) throw InputError("volume: axes longer than 2^31 - 1 vertices are not supported");
}

bool copy_doubles_host_memory(const Context& ctx, std::size_t bytes) {
    return ctx.is_cpu() && bytes > (std::size_t(64) << 20);
}

SliceRange ld_input_slices(std::size_t a, std::size_t b, std::size_t nz, int window) {
    const std::size_t half = std::size_t(window / 2);
    return {a > half ? (a - half) & ~std::size_t(1) : 0, std::min(nz, b + half)};
}

}  // namespace clfractal
