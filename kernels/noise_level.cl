// The block statistics of the noise level (include/clfractal/noise_level.hpp).
//
// The residual of an interior vertex is the 3D second difference
//     R = sum over the 27 offsets d in {-1,0,1}^3 of w(dx) w(dy) w(dz) v(x + d),
//     w(-1) = w(1) = 1, w(0) = -2,
// the product of [1 -2 1] along the three axes (the 3D form of Immerkaer's 2D mask). It is 0
// on every field that is constant along any one axis or quadratic in it, and for independent
// noise of standard deviation sigma it has variance 216 sigma^2 (the sum of the squared
// weights, (1 + 4 + 1)^3), whatever the noise's distribution. Since the weights sum to 0,
// R = sum w(d) (v(x + d) - v(x)): integer data subtracts in long first (exact).
//
// One work-group per block of BLOCK^3 vertices (x fastest, blocks x fastest, then y, z, of a
// z-slab). Each item sums R^2 over its vertices, counts them and keeps the smallest and largest
// value its residuals read; the group reduces the four in local memory (a tree over the
// work-group size, a power of two). Vertices on the volume's faces have no residual. Two ways
// to R: block_residuals_tiled loads the block with one vertex around it into local memory and
// applies [1 -2 1] along x, y and z in turn (three passes); block_residuals reads the 27
// values of every residual from global memory, for devices whose local memory cannot hold a
// tile. Integer data gives the same sums either way.
//
// Defines: T (kernels/common.cl), BLOCK; INTEGER_SUMS for 8- and 16-bit integer data (R is
// an integer, |R| <= 64 x 65535, R^2 and its sums exact in ulong); otherwise R and its sums in
// float, or in double for float64 data (FP64); ONE_ITEM where every group has one work-item
// (CPUs, exact or double sums): the kernels walk a block in nested loops, the same values in
// the same order.
#pragma OPENCL FP_CONTRACT OFF

#if defined(INTEGER_SUMS)
typedef long residual_t;
typedef int tile_t;  // |R| and every partial difference fit in int
typedef ulong sum_t;
#elif defined(T_IS_double)
typedef double residual_t;
typedef double tile_t;
typedef double sum_t;
#else
typedef float residual_t;
typedef float tile_t;
typedef float sum_t;
#endif

inline residual_t residual_difference(T u, T c) {
#if defined(T_IS_float) || defined(T_IS_double)
    return (residual_t)u - (residual_t)c;
#else
    return (residual_t)((long)u - (long)c);
#endif
}

inline int weight(int d) { return d == 0 ? -2 : 1; }

// s += r^2, n += 1 (exact in ulong for integer sums).
inline void accumulate(sum_t* s, uint* n, residual_t r) {
#if defined(INTEGER_SUMS)
    *s += (sum_t)(r * r);
#else
    *s += r * r;
#endif
    ++*n;
}

// The residual of interior vertex (x, y, z) of the slab (z counted from the slab's first
// slice), widening [lo, hi] by the values it reads.
inline residual_t vertex_residual(__global const T* restrict v, int nx, int ny, int x, int y, int z, T* lo, T* hi) {
    const long sy = nx, sz = (long)nx * (long)ny;
    const long c = x + sy * y + sz * z;
    const T vc = v[c];
    residual_t r = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const T u = v[c + dx + sy * dy + sz * dz];
                *lo = min(*lo, u);
                *hi = max(*hi, u);
                r += (residual_t)(weight(dx) * weight(dy) * weight(dz)) * residual_difference(u, vc);
            }
    return r;
}

// The group's sums and counts reduced in local memory (a tree over the work-group size, a
// power of two); every item returns the group's totals.
inline void reduce_sum_count(sum_t* s, uint* n, __local sum_t* local_sums, __local uint* local_counts) {
    const int lid = (int)get_local_id(0), wg = (int)get_local_size(0);
    local_sums[lid] = *s;
    local_counts[lid] = *n;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int step = wg / 2; step > 0; step /= 2) {
        if (lid < step) {
            local_sums[lid] += local_sums[lid + step];
            local_counts[lid] += local_counts[lid + step];
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    *s = local_sums[0];
    *n = local_counts[0];
    barrier(CLK_LOCAL_MEM_FENCE);  // the next reduction reuses local memory
}

// The group's sums, counts and ranges reduced in local memory; item 0 writes block b's.
inline void reduce_block(sum_t s, uint n, T lo, T hi, int b, __global sum_t* restrict sums,
                         __global uint* restrict counts, __global T* restrict lows, __global T* restrict highs,
                         __local sum_t* local_sums, __local uint* local_counts, __local T* local_lows,
                         __local T* local_highs) {
    const int lid = (int)get_local_id(0), wg = (int)get_local_size(0);
    reduce_sum_count(&s, &n, local_sums, local_counts);
    local_lows[lid] = lo;
    local_highs[lid] = hi;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int step = wg / 2; step > 0; step /= 2) {
        if (lid < step) {
            local_lows[lid] = min(local_lows[lid], local_lows[lid + step]);
            local_highs[lid] = max(local_highs[lid], local_highs[lid + step]);
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (lid == 0) {
        sums[b] = s;
        counts[b] = n;
        lows[b] = local_lows[0];
        highs[b] = local_highs[0];
    }
}

// Block b of a z-slab by the direct kernel: R from global memory, reduced and written.
// The slab holds slices z_first .. of a volume of nz slices; its blocks start at volume slice
// z_block (a multiple of BLOCK), and a vertex has a residual when it is interior to the whole
// volume. Out: per block the sum of R^2, the residual count, and the range of the values read
// (the first interior vertex's value where there is none).
inline void direct_block(__global const T* restrict v, int nx, int ny, int nz, int z_first, int z_block, int bx,
                         int by, int b, __global sum_t* restrict sums, __global uint* restrict counts,
                         __global T* restrict lows, __global T* restrict highs, __local sum_t* local_sums,
                         __local uint* local_counts, __local T* local_lows, __local T* local_highs) {
    const int lid = (int)get_local_id(0), wg = (int)get_local_size(0);
    const int x0 = (b % bx) * BLOCK, y0 = (b / bx % by) * BLOCK, z0 = z_block + b / (bx * by) * BLOCK;
    // Every residual of the block reads its first interior vertex, so its value starts the range.
    const int fx = max(x0, 1), fy = max(y0, 1), fz = max(z0, 1);
    const bool any = fx <= nx - 2 && fy <= ny - 2 && fz <= nz - 2;
    const size_t first = any ? (size_t)fx + (size_t)nx * ((size_t)fy + (size_t)ny * (size_t)(fz - z_first)) : 0;
    T lo = v[first], hi = lo;
    sum_t s = 0;
    uint n = 0;
    for (int i = lid; any && i < BLOCK * BLOCK * BLOCK; i += wg) {
        const int x = x0 + i % BLOCK, y = y0 + i / BLOCK % BLOCK, z = z0 + i / (BLOCK * BLOCK);
        if (x < 1 || y < 1 || z < 1 || x > nx - 2 || y > ny - 2 || z > nz - 2) continue;
        accumulate(&s, &n, vertex_residual(v, nx, ny, x, y, z - z_first, &lo, &hi));
    }
    reduce_block(s, n, lo, hi, b, sums, counts, lows, highs, local_sums, local_counts, local_lows, local_highs);
}

// Global size: work-group size x ceil(blocks / per_group), local: the work-group size. Each
// group takes blocks g per_group .. (g + 1) per_group - 1 of the slab's `blocks` (bx by per
// block row) in turn: several per group where launching groups costs more than their work
// (CPUs).
__kernel void block_residuals(__global const T* restrict v, int nx, int ny, int nz, int z_first, int z_block, int bx,
                              int by, int blocks, int per_group, __global sum_t* restrict sums,
                              __global uint* restrict counts, __global T* restrict lows, __global T* restrict highs,
                              __local sum_t* local_sums, __local uint* local_counts, __local T* local_lows,
                              __local T* local_highs) {
    const int g = (int)get_group_id(0);
    for (int b = g * per_group; b < min(blocks, (g + 1) * per_group); ++b) {
        direct_block(v, nx, ny, nz, z_first, z_block, bx, by, b, sums, counts, lows, highs, local_sums, local_counts,
                     local_lows, local_highs);
        barrier(CLK_LOCAL_MEM_FENCE);  // the next block reuses local memory
    }
}

// v - ref in tile_t: integers subtract in long (exact), float data in its own type. The
// weights sum to 0, so R does not change, and a float tile keeps the precision of values far
// from 0 (int32, uint32) relative to the block's own spread.
inline tile_t tile_value(T u, T ref) {
#if defined(T_IS_float) || defined(T_IS_double)
    return (tile_t)(u - ref);
#else
    return (tile_t)((long)u - (long)ref);
#endif
}

#define EDGE (BLOCK + 2)

// As direct_block (the same results), through local memory: `tile` holds EDGE^3 values (the
// block and one vertex around it, x fastest; 0 outside the volume, which no residual reads),
// `along_x` BLOCK x EDGE x EDGE. The second difference along y goes back into `tile` (BLOCK x
// BLOCK x EDGE), the one along z gives R.
inline void tiled_block(__global const T* restrict v, int nx, int ny, int nz, int z_first, int z_block, int bx, int by,
                        int b, __global sum_t* restrict sums, __global uint* restrict counts, __global T* restrict lows,
                        __global T* restrict highs, __local sum_t* local_sums, __local uint* local_counts,
                        __local T* local_lows, __local T* local_highs, __local tile_t* tile, __local tile_t* along_x) {
    const int lid = (int)get_local_id(0), wg = (int)get_local_size(0);
    const int x0 = (b % bx) * BLOCK, y0 = (b / bx % by) * BLOCK, z0 = z_block + b / (bx * by) * BLOCK;
    const int fx = max(x0, 1), fy = max(y0, 1), fz = max(z0, 1);
    const bool any = fx <= nx - 2 && fy <= ny - 2 && fz <= nz - 2;
    const size_t first = any ? (size_t)fx + (size_t)nx * ((size_t)fy + (size_t)ny * (size_t)(fz - z_first)) : 0;
    const T ref = v[first];
    T lo = ref, hi = ref;
#if defined(ONE_ITEM)
    // One work-item a group (CPUs): the same tile, passes and sum, in the same order, as
    // nested loops.
    for (int k = 0; k < EDGE; ++k)
        for (int j = 0; j < EDGE; ++j) {
            const int y = y0 - 1 + j, z = z0 - 1 + k;
            const bool row = any && y >= 0 && z >= 0 && y < ny && z < nz;
            __global const T* p = v + (size_t)nx * ((size_t)(row ? y : 0) + (size_t)ny * (size_t)(row ? z - z_first : 0));
            for (int i = 0; i < EDGE; ++i) {
                const int x = x0 - 1 + i;
                tile_t t = 0;
                if (row && x >= 0 && x < nx) {
                    const T u = p[x];
                    lo = min(lo, u);
                    hi = max(hi, u);
                    t = tile_value(u, ref);
                }
                tile[(k * EDGE + j) * EDGE + i] = t;
            }
        }
    for (int r = 0; r < EDGE * EDGE; ++r)
        for (int i = 0; i < BLOCK; ++i) {
            const int t = r * EDGE + i;
            along_x[r * BLOCK + i] = tile[t] + tile[t + 2] - 2 * tile[t + 1];
        }
    for (int k = 0; k < EDGE; ++k)
        for (int j = 0; j < BLOCK; ++j)
            for (int i = 0; i < BLOCK; ++i) {
                const int a = i + BLOCK * (j + EDGE * k);
                tile[(k * BLOCK + j) * BLOCK + i] = along_x[a] + along_x[a + 2 * BLOCK] - 2 * along_x[a + BLOCK];
            }
    sum_t s = 0;
    uint n = 0;
    if (any) {
        const int xs = max(x0, 1) - x0, xe = min(x0 + BLOCK - 1, nx - 2) - x0;
        const int ys = max(y0, 1) - y0, ye = min(y0 + BLOCK - 1, ny - 2) - y0;
        const int zs = max(z0, 1) - z0, ze = min(z0 + BLOCK - 1, nz - 2) - z0;
        for (int k = zs; k <= ze; ++k)
            for (int j = ys; j <= ye; ++j)
                for (int i = xs; i <= xe; ++i) {
                    const int c = (k * BLOCK + j) * BLOCK + i;
                    accumulate(&s, &n, (residual_t)(tile[c] + tile[c + 2 * BLOCK * BLOCK] - 2 * tile[c + BLOCK * BLOCK]));
                }
    }
    sums[b] = s;
    counts[b] = n;
    lows[b] = lo;
    highs[b] = hi;
#else
    // The tile: vertices x0 - 1 .. x0 + BLOCK (y, z alike) that lie in the volume, exactly the
    // values the block's residuals read.
    for (int i = lid; i < EDGE * EDGE * EDGE; i += wg) {
        const int x = x0 - 1 + i % EDGE, y = y0 - 1 + i / EDGE % EDGE, z = z0 - 1 + i / (EDGE * EDGE);
        tile_t t = 0;
        if (any && x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz) {
            const T u = v[(size_t)x + (size_t)nx * ((size_t)y + (size_t)ny * (size_t)(z - z_first))];
            lo = min(lo, u);
            hi = max(hi, u);
            t = tile_value(u, ref);
        }
        tile[i] = t;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int i = lid; i < BLOCK * EDGE * EDGE; i += wg) {
        const int t = i / BLOCK * EDGE + i % BLOCK;
        along_x[i] = tile[t] + tile[t + 2] - 2 * tile[t + 1];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int i = lid; i < BLOCK * BLOCK * EDGE; i += wg) {
        const int a = i % BLOCK + BLOCK * (i / BLOCK % BLOCK + EDGE * (i / (BLOCK * BLOCK)));
        tile[i] = along_x[a] + along_x[a + 2 * BLOCK] - 2 * along_x[a + BLOCK];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    sum_t s = 0;
    uint n = 0;
    for (int i = lid; any && i < BLOCK * BLOCK * BLOCK; i += wg) {
        const int x = x0 + i % BLOCK, y = y0 + i / BLOCK % BLOCK, z = z0 + i / (BLOCK * BLOCK);
        if (x < 1 || y < 1 || z < 1 || x > nx - 2 || y > ny - 2 || z > nz - 2) continue;
        accumulate(&s, &n, (residual_t)(tile[i] + tile[i + 2 * BLOCK * BLOCK] - 2 * tile[i + BLOCK * BLOCK]));
    }
    reduce_block(s, n, lo, hi, b, sums, counts, lows, highs, local_sums, local_counts, local_lows, local_highs);
#endif
}

// As block_residuals, with the two tile arrays.
__kernel void block_residuals_tiled(__global const T* restrict v, int nx, int ny, int nz, int z_first, int z_block,
                                    int bx, int by, int blocks, int per_group, __global sum_t* restrict sums,
                                    __global uint* restrict counts, __global T* restrict lows,
                                    __global T* restrict highs, __local sum_t* local_sums, __local uint* local_counts,
                                    __local T* local_lows, __local T* local_highs, __local tile_t* tile,
                                    __local tile_t* along_x) {
    const int g = (int)get_group_id(0);
    for (int b = g * per_group; b < min(blocks, (g + 1) * per_group); ++b) {
        tiled_block(v, nx, ny, nz, z_first, z_block, bx, by, b, sums, counts, lows, highs, local_sums, local_counts,
                    local_lows, local_highs, tile, along_x);
        barrier(CLK_LOCAL_MEM_FENCE);  // the next block reuses local memory
    }
}

// The strided residuals: R_s with the taps of [1 -2 1] s_a apart along axis a,
//     R_s = sum over d in {-1,0,1}^3 of w(dx) w(dy) w(dz) v(x + dx sx, y + dy sy, z + dz sz),
// at the vertices of block b whose three coordinates are even and whose taps all lie in the
// volume (s_a <= coordinate <= n_a - 1 - s_a). For white noise E[R_s^2] = 216 sigma^2 too;
// for correlated noise the strides see what the neighbouring taps share (noise_level.hpp).
inline residual_t strided_residual(__global const T* restrict v, int nx, int ny, int x, int y, int z, int sx, int sy,
                                   int sz) {
    const long sy_step = (long)nx * sy, sz_step = (long)nx * (long)ny * sz;
    const long c = x + (long)nx * y + (long)nx * (long)ny * z;
#if defined(INTEGER_SUMS)
    // Exact integers: [1 -2 1] along x, then y, then z gives the same R in a third of the
    // operations.
    residual_t r = 0;
    for (int dz = -1; dz <= 1; ++dz) {
        residual_t rz = 0;
        for (int dy = -1; dy <= 1; ++dy) {
            const long p = c + dy * sy_step + dz * sz_step;
            rz += weight(dy) * ((residual_t)v[p - sx] + (residual_t)v[p + sx] - 2 * (residual_t)v[p]);
        }
        r += weight(dz) * rz;
    }
    return r;
#else
    const T vc = v[c];
    residual_t r = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                r += (residual_t)(weight(dx) * weight(dy) * weight(dz)) *
                     residual_difference(v[c + dx * sx + dy * sy_step + dz * sz_step], vc);
    return r;
#endif
}

// Global size: work-group size x ceil(blocks / per_group), local: the work-group size, as
// block_residuals. `strides` holds masks x 3 strides (x, y, z); the slab holds slices
// z_first .. of a volume of nz slices with at least the largest z stride of halo on each side.
// Out: sums[m blocks_out + block_first + b] and counts likewise, per mask m.
__kernel void block_strided_residuals(__global const T* restrict v, int nx, int ny, int nz, int z_first, int z_block,
                                      int bx, int by, int blocks, int per_group, __global const int* restrict strides,
                                      int masks, int mask_pitch, __global sum_t* restrict sums,
                                      __global uint* restrict counts, __local sum_t* local_sums,
                                      __local uint* local_counts) {
    const int g = (int)get_group_id(0), lid = (int)get_local_id(0), wg = (int)get_local_size(0);
    const int evens = (BLOCK + 1) / 2;
    for (int b = g * per_group; b < min(blocks, (g + 1) * per_group); ++b) {
        const int x0 = (b % bx) * BLOCK, y0 = (b / bx % by) * BLOCK, z0 = z_block + b / (bx * by) * BLOCK;
        for (int m = 0; m < masks; ++m) {
            const int sx = strides[3 * m], sy = strides[3 * m + 1], sz = strides[3 * m + 2];
            sum_t s = 0;
            uint n = 0;
#if defined(ONE_ITEM)
            // One work-item a group (CPUs, whose compilers run a group's items as loops): the
            // same vertices in the same order, their bounds taken once.
            const int xs = max(x0 + (x0 & 1), sx + (sx & 1)), xe = min(x0 + BLOCK - 1, nx - 1 - sx);
            const int ys = max(y0 + (y0 & 1), sy + (sy & 1)), ye = min(y0 + BLOCK - 1, ny - 1 - sy);
            const int zs = max(z0 + (z0 & 1), sz + (sz & 1)), ze = min(z0 + BLOCK - 1, nz - 1 - sz);
            for (int z = zs; z <= ze; z += 2)
                for (int y = ys; y <= ye; y += 2)
                    for (int x = xs; x <= xe; x += 2)
                        accumulate(&s, &n, strided_residual(v, nx, ny, x, y, z - z_first, sx, sy, sz));
            sums[m * mask_pitch + b] = s;
            counts[m * mask_pitch + b] = n;
#else
            for (int i = lid; i < evens * evens * evens; i += wg) {
                // The even coordinates of the block: x0 rounded up to even, then every second.
                const int x = (x0 + (x0 & 1)) + 2 * (i % evens), y = (y0 + (y0 & 1)) + 2 * (i / evens % evens),
                          z = (z0 + (z0 & 1)) + 2 * (i / (evens * evens));
                if (x >= x0 + BLOCK || y >= y0 + BLOCK || z >= z0 + BLOCK) continue;
                if (x < sx || y < sy || z < sz || x > nx - 1 - sx || y > ny - 1 - sy || z > nz - 1 - sz) continue;
                accumulate(&s, &n, strided_residual(v, nx, ny, x, y, z - z_first, sx, sy, sz));
            }
            reduce_sum_count(&s, &n, local_sums, local_counts);
            if (lid == 0) {
                sums[m * mask_pitch + b] = s;
                counts[m * mask_pitch + b] = n;
            }
#endif
        }
    }
}
