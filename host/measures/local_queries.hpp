// The window queries of the local dimensions on raw device buffers, shared by the LD field
// (local.cpp), LD4 (fd4.cpp) and the fractal-targeted filters (processing/filter.cpp).
// Private to the library.
#pragma once
#include <string>

#include "clfractal/local.hpp"

namespace clfractal {

/// The query step of the local dimensions (LD here, LD4 in fd4.hpp): for every vertex of a
/// grid of `d`, log2(box_W / box_W') of the windows of local_windows(·, window), where
/// `table` and `table_sub` are the summed-area tables of zero-padded per-cube counts of G
/// (d) and G' (level_dims(d, 1)) as kernels/local.cl lays them out; NaN where either box
/// sum is 0. `options` are the -D defines of kernels/local.cl (-DC must name C); `out`
/// receives d.vertices() floats. Follows ctx.tuning.local_variant.
template <class C>
void window_log_ratios(Context& ctx, const Buffer<C>& table, const Dims& d, const Buffer<C>& table_sub, int window,
                       const std::string& options, const cl::Buffer& out);

/// The LD field on blocks of 2×2×2 vertices. With p = (k/2) mod 2, vertices 2m - p and
/// 2m + 1 - p of an axis have the same windows, so LD is constant on each block ((x + p) / 2,
/// (y + p) / 2, (z + p) / 2); and W is the union of the 2×2×2 blocks of G cubes inside W', so
/// both counts are box sums on tables of G' (the intersected G cubes inside each G' cube, and
/// the G' indicator): one read of the values, tables and queries at an eighth of the size.
/// Returns the ld_block_dims(dims, window) floats, x fastest: vertex (x, y, z) has the value
/// of its block, bit for bit the value local_fractal_dimension gives it. `values` holds
/// dims.vertices() values of `type` on the device.
Buffer<float> block_local_dimension(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& dims,
                                    double iso, int window = 8);
/// The selection of the fractal-targeted filters on the same blocks, fused with the window
/// queries: one byte per block, 1 where its LD is > h (NaN never qualifies), else 0. The
/// queries walk rows (the CPU kernel) whatever the device.
Buffer<cl_uchar> block_selection(Context& ctx, const cl::Buffer& values, ValueType type, const Dims& dims,
                                 double iso, int window, float h);
/// The blocks of block_local_dimension: (n + p + 1) / 2 per axis of n vertices.
Dims ld_block_dims(const Dims& dims, int window);
/// The block phase p = (window / 2) mod 2: vertex x lies in block (x + p) / 2.
inline int ld_block_phase(int window) { return (window / 2) % 2; }


}  // namespace clfractal
