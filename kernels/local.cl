// Local fractal dimension (docs/definitions.md §13 "Local fractal dimension"; thesis eq. 2.6),
// in three steps per grid:
//   cube_indicator_*   the 0/1 "cube intersected" indicator, zero-padded (below)
//   (sat.cl)           its summed-area table
//   local_dimension_*  two box queries per vertex, one in G and one in G', and the log ratio
//
// -DT is the value type, -DC=uint|ulong the count type. s is an iso_t (kernels/common.cl):
// integer data (-DINTEGER_VALUES) compares with the integer ceil(s), which selects exactly
// the cubes a < s <= b selects for a real s; float data with s in its own type.
//
// Padding: the table of a grid of nx × ny × nz vertices has nx × ny × nz entries, entry
// (x, y, z) holding cube (x - 1, y - 1, z - 1) and the planes x = 0, y = 0, z = 0 holding 0.
// Its inclusive summed-area table S then gives the count of the cubes [x0, x1) × [y0, y1) ×
// [z0, z1) as the inclusion-exclusion of S at those very corners, with no border cases.

#ifndef C
#define C uint
#endif

// Two variants of each kernel, chosen per device (Tuning::local_variant):
//  - *_vertices (GPUs): one work-item per table entry or vertex.
//  - *_rows (CPUs): local size 1 and a few work-items per core, each walking a contiguous
//    share of the x-rows; per row the window bounds along y and z are computed once and
//    the inner loops over x read contiguous rows (vectorised by the compiler).

// (& rather than &&: both comparisons are cheap, a branch on noisy data is not.)
inline C intersected(T a, T b, iso_t s) {
#ifdef INTEGER_VALUES
    return (C)(((long)a < s) & (s <= (long)b));
#else
    return (C)((a < s) & (s <= b));
#endif
}

// One work-item per table entry: global size (nx, ny, nz) exactly (nz is not read; both
// variants take the same arguments).
__kernel void cube_indicator_vertices(__global const T* restrict vol, int nx, int ny, int nz, iso_t s,
                                      __global C* restrict table) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    C in = 0;
    if (x && y && z) {
        __global const T* p = vol + (z - 1) * slice + (y - 1) * row + (x - 1);
        const T a = min(min(min(p[0], p[1]), min(p[row], p[row + 1])),
                        min(min(p[slice], p[slice + 1]), min(p[slice + row], p[slice + row + 1])));
        const T b = max(max(max(p[0], p[1]), max(p[row], p[row + 1])),
                        max(max(p[slice], p[slice + 1]), max(p[slice + row], p[slice + row + 1])));
        in = intersected(a, b, s);
    }
    table[z * slice + y * row + x] = in;
}

// Work-item i of k fills the table rows (y, z), numbered y + ny * z, in [rows * i / k,
// rows * (i + 1) / k).
__kernel void cube_indicator_rows(__global const T* restrict vol, int nx, int ny, int nz, iso_t s,
                                  __global C* restrict table) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t rows = (size_t)ny * (size_t)nz, row = (size_t)nx, slice = row * (size_t)ny;
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
    for (size_t r = r0; r < r1; ++r) {
        const size_t y = r % (size_t)ny, z = r / (size_t)ny;
        __global C* out = table + r * row;
        out[0] = 0;
        if (y == 0 || z == 0) {
            for (int x = 1; x < nx; ++x) out[x] = 0;
            continue;
        }
        // Cube x - 1 has the vertex columns x - 1 and x of these four x-rows.
        __global const T* p00 = vol + (z - 1) * slice + (y - 1) * row;
        __global const T* p10 = p00 + row;
        __global const T* p01 = p00 + slice;
        __global const T* p11 = p01 + row;
        for (int x = 1; x < nx; ++x) {
            const T a = min(min(min(p00[x - 1], p00[x]), min(p10[x - 1], p10[x])),
                            min(min(p01[x - 1], p01[x]), min(p11[x - 1], p11[x])));
            const T b = max(max(max(p00[x - 1], p00[x]), max(p10[x - 1], p10[x])),
                            max(max(p01[x - 1], p01[x]), max(p11[x - 1], p11[x])));
            out[x] = intersected(a, b, s);
        }
    }
}

// Count of the cubes [x0, x1) × [y0, y1) × [z0, z1) from the padded table S (row length
// nx, slice nx * ny). Wrapping arithmetic is exact: the true count is small.
inline C box(__global const C* S, size_t row, size_t slice, int x0, int x1, int y0, int y1, int z0, int z1) {
    __global const C* a = S + (size_t)z0 * slice;
    __global const C* b = S + (size_t)z1 * slice;
    const size_t r0 = (size_t)y0 * row, r1 = (size_t)y1 * row;
    return (b[r1 + x1] - b[r1 + x0] - b[r0 + x1] + b[r0 + x0]) -
           (a[r1 + x1] - a[r1 + x0] - a[r0 + x1] + a[r0 + x0]);
}

// In float: the ratio is rounded once and log2 adds an ulp or two, far inside the 1e-6 the
// tests allow (the counts of an 8-window are at most 512).
inline float log_ratio(C a, C b) { return a && b ? log2((float)a / (float)b) : NAN; }

// The windows (docs/definitions.md §13, revision 2) are not computed here: `win` holds the host's
// local_windows tables of the x, y and z axes one after the other (nx + ny + nz entries),
// each (lo, hi, lo_sub, hi_sub): cubes [lo, hi) of G and [lo_sub, hi_sub) of G'.

// One work-item per vertex of G: global size (nx, ny, nz) exactly. `table` and `table_sub`
// are the summed-area tables of the padded indicators of G (nx × ny × nz) and G'
// (mx × my × mz).
__kernel void local_dimension_vertices(__global const C* table, int nx, int ny, int nz,
                              __global const C* table_sub, int mx, int my, int mz,
                              __global const int4* win, __global float* restrict ld) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const int4 wx = win[x], wy = win[nx + y], wz = win[nx + ny + z];
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    const size_t row_sub = (size_t)mx, slice_sub = row_sub * (size_t)my;
    const C in_w = box(table, row, slice, wx.s0, wx.s1, wy.s0, wy.s1, wz.s0, wz.s1);
    const C in_sub = box(table_sub, row_sub, slice_sub, wx.s2, wx.s3, wy.s2, wy.s3, wz.s2, wz.s3);
    ld[(size_t)z * slice + (size_t)y * row + x] = log_ratio(in_w, in_sub);
}

// The same per x-row, rows shared out like cube_indicator_rows. Per row, the y-z part of
// the inclusion-exclusion is summed once for every column into `scratch` (nx + mx counts
// per work-item), so that each vertex needs only two lookups per grid.
__kernel void local_dimension_rows(__global const C* table, int nx, int ny, int nz,
                                   __global const C* table_sub, int mx, int my, int mz,
                                   __global const int4* win, __global float* restrict ld,
                                   __global C* restrict scratch) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t rows = (size_t)ny * (size_t)nz, row = (size_t)nx, slice = row * (size_t)ny;
    const size_t row_sub = (size_t)mx, slice_sub = row_sub * (size_t)my;
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
    __global C* col = scratch + item * (size_t)(nx + mx);
    __global C* col_sub = col + nx;
    for (size_t r = r0; r < r1; ++r) {
        const int y = r % (size_t)ny, z = r / (size_t)ny;
        const int4 wy = win[nx + y], wz = win[nx + ny + z];
        __global const C* a00 = table + wz.s0 * slice + wy.s0 * row;
        __global const C* a01 = table + wz.s0 * slice + wy.s1 * row;
        __global const C* a10 = table + wz.s1 * slice + wy.s0 * row;
        __global const C* a11 = table + wz.s1 * slice + wy.s1 * row;
        for (int x = 0; x < nx; ++x) col[x] = (a11[x] - a10[x]) - (a01[x] - a00[x]);
        __global const C* b00 = table_sub + wz.s2 * slice_sub + wy.s2 * row_sub;
        __global const C* b01 = table_sub + wz.s2 * slice_sub + wy.s3 * row_sub;
        __global const C* b10 = table_sub + wz.s3 * slice_sub + wy.s2 * row_sub;
        __global const C* b11 = table_sub + wz.s3 * slice_sub + wy.s3 * row_sub;
        for (int u = 0; u < mx; ++u) col_sub[u] = (b11[u] - b10[u]) - (b01[u] - b00[u]);
        __global float* out = ld + r * row;
        for (int x = 0; x < nx; ++x) {
            const int4 wx = win[x];
            out[x] = log_ratio(col[wx.s1] - col[wx.s0], col_sub[wx.s3] - col_sub[wx.s2]);
        }
    }
}

// ---------------------------------------------------------------- LD on blocks of 2×2×2 vertices
// (block_local_dimension in local.hpp.) With p = (k/2) mod 2, vertices 2m - p and 2m + 1 - p
// of an axis have the same windows (c0 = floor((x - k/2) / 2) is the same for both), so LD is
// constant on blocks of up to 2×2×2 vertices, block (x + p) / 2 along each axis; and W, cubes
// [2 b0, 2 b1) of G, is the union of the 2×2×2 G-cubes inside the G' cubes [b0, b1). Both counts are therefore box sums on the
// tables of G' (mx × my × mz, padded as above): I_W over the number of intersected G cubes
// inside each G' cube, I_W' over the G' indicator. One read of the volume, tables and
// queries at an eighth of the size, the same integers and the same log_ratio as
// local_dimension_*.

// One work-item per table entry: global size (mx, my, mz) exactly. Entry (X, Y, Z), all > 0,
// holds G' cube c = (X - 1, Y - 1, Z - 1), whose 3×3×3 vertices in G start at 2c:
// `counts` gets the intersected G cubes among its eight, `sub` 1 if c itself (corners 2c and
// 2c + 2) is intersected.
__kernel void block_indicators(__global const T* restrict vol, int nx, int ny, int nz, iso_t s,
                               __global C* restrict counts, __global C* restrict sub) {
    const size_t X = get_global_id(0), Y = get_global_id(1), Z = get_global_id(2);
    const size_t mx = get_global_size(0), my = get_global_size(1);
    const size_t out = (Z * my + Y) * mx + X;
    if (!X || !Y || !Z) {
        counts[out] = 0;
        sub[out] = 0;
        return;
    }
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    __global const T* p = vol + 2 * (Z - 1) * slice + 2 * (Y - 1) * row + 2 * (X - 1);
    // Min and max along x of the vertex pairs (i, i + 1) of the 9 x-rows (j, k).
    T lo[3][3][2], hi[3][3][2];
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) {
            __global const T* r = p + k * slice + j * row;
            const T a = r[0], b = r[1], c = r[2];
            lo[k][j][0] = min(a, b);
            hi[k][j][0] = max(a, b);
            lo[k][j][1] = min(b, c);
            hi[k][j][1] = max(b, c);
        }
    C n = 0;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                const T a = min(min(lo[k][j][i], lo[k][j + 1][i]), min(lo[k + 1][j][i], lo[k + 1][j + 1][i]));
                const T b = max(max(hi[k][j][i], hi[k][j + 1][i]), max(hi[k + 1][j][i], hi[k + 1][j + 1][i]));
                n += intersected(a, b, s);
            }
    T a = p[0], b = p[0];
    for (int k = 0; k < 3; k += 2)
        for (int j = 0; j < 3; j += 2)
            for (int i = 0; i < 3; i += 2) {
                const T v = p[k * slice + j * row + i];
                a = min(a, v);
                b = max(b, v);
            }
    counts[out] = n;
    sub[out] = intersected(a, b, s);
}

// The same per row of table entries (Y, Z), rows shared out like cube_indicator_rows (CPUs),
// eight G' cubes at a time in explicit vectors of 16 vertex columns (x0 = 2 (X - 1) .. x0 +
// 15, loaded at x0, x0 + 1 and x0 + 2 from the nine vertex rows of the G' cube row): the 16 G
// cubes of each of the four G cube rows, their intersections summed lane by lane and then
// over lane pairs (G' cube c holds G cubes 2c and 2c + 1), and the G' cubes from the four
// corner rows at lanes 2c (columns x0 + 2c and x0 + 2c + 2). The last G' cubes of a row, whose
// loads would pass the row's end, go one by one. Integer data compares in T: an isovalue
// outside T's range intersects nothing.
#if defined(T_IS_uchar)
#define TV16 uchar16
#define T_LOWEST 0
#define T_HIGHEST UCHAR_MAX
#elif defined(T_IS_char)
#define TV16 char16
#define T_LOWEST CHAR_MIN
#define T_HIGHEST CHAR_MAX
#elif defined(T_IS_ushort)
#define TV16 ushort16
#define T_LOWEST 0
#define T_HIGHEST USHRT_MAX
#elif defined(T_IS_short)
#define TV16 short16
#define T_LOWEST SHRT_MIN
#define T_HIGHEST SHRT_MAX
#elif defined(T_IS_uint)
#define TV16 uint16
#define T_LOWEST 0
#define T_HIGHEST UINT_MAX
#elif defined(T_IS_int)
#define TV16 int16
#define T_LOWEST INT_MIN
#define T_HIGHEST INT_MAX
#elif defined(T_IS_double)
#define TV16 double16
#else
#define TV16 float16
#endif
#define CONVERT8_(t) convert_##t##8
#define CONVERT8(t) CONVERT8_(t)
// -1 in the lanes where s intersects [lo, hi], else 0.
#define HITS16(lo, hi, sv) (convert_int16((lo) < (sv)) & convert_int16((sv) <= (hi)))

__kernel void block_indicators_rows(__global const T* restrict vol, int nx, int ny, int nz, iso_t s, int mx, int my,
                                    int mz, __global C* restrict counts, __global C* restrict sub) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t rows = (size_t)my * (size_t)mz, row = (size_t)nx, slice = row * (size_t)ny;
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
#ifdef INTEGER_VALUES
    const int outside = s <= (long)T_LOWEST || s > (long)T_HIGHEST;
    const T st = outside ? (T)0 : (T)s;
#else
    const int outside = 0;
    const T st = s;
#endif
    const TV16 sv = (TV16)st;
    for (size_t r = r0; r < r1; ++r) {
        const size_t Y = r % (size_t)my, Z = r / (size_t)my;
        __global C* cn = counts + r * (size_t)mx;
        __global C* sb = sub + r * (size_t)mx;
        cn[0] = 0;
        sb[0] = 0;
        if (!Y || !Z || outside) {
            for (int X = 1; X < mx; ++X) cn[X] = sb[X] = 0;
            continue;
        }
        __global const T* v[3][3];
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j) v[k][j] = vol + (2 * (Z - 1) + k) * slice + (2 * (Y - 1) + j) * row;
        int X = 1;
        for (; X + 7 < mx && 2 * (X - 1) + 17 < nx; X += 8) {
            const int x0 = 2 * (X - 1);
            int16 hits = 0;
            for (int k = 0; k < 2; ++k)
                for (int j = 0; j < 2; ++j) {
                    TV16 lo = min(min(vload16(0, v[k][j] + x0), vload16(0, v[k][j + 1] + x0)),
                                  min(vload16(0, v[k + 1][j] + x0), vload16(0, v[k + 1][j + 1] + x0)));
                    TV16 hi = max(max(vload16(0, v[k][j] + x0), vload16(0, v[k][j + 1] + x0)),
                                  max(vload16(0, v[k + 1][j] + x0), vload16(0, v[k + 1][j + 1] + x0)));
                    const int x1 = x0 + 1;
                    lo = min(lo, min(min(vload16(0, v[k][j] + x1), vload16(0, v[k][j + 1] + x1)),
                                     min(vload16(0, v[k + 1][j] + x1), vload16(0, v[k + 1][j + 1] + x1))));
                    hi = max(hi, max(max(vload16(0, v[k][j] + x1), vload16(0, v[k][j + 1] + x1)),
                                     max(vload16(0, v[k + 1][j] + x1), vload16(0, v[k + 1][j + 1] + x1))));
                    hits += HITS16(lo, hi, sv);
                }
            vstore8(CONVERT8(C)(-(hits.even + hits.odd)), 0, cn + X);
            const int x2 = x0 + 2;
            const TV16 lo = min(min(min(vload16(0, v[0][0] + x0), vload16(0, v[0][2] + x0)),
                                    min(vload16(0, v[2][0] + x0), vload16(0, v[2][2] + x0))),
                                min(min(vload16(0, v[0][0] + x2), vload16(0, v[0][2] + x2)),
                                    min(vload16(0, v[2][0] + x2), vload16(0, v[2][2] + x2))));
            const TV16 hi = max(max(max(vload16(0, v[0][0] + x0), vload16(0, v[0][2] + x0)),
                                    max(vload16(0, v[2][0] + x0), vload16(0, v[2][2] + x0))),
                                max(max(vload16(0, v[0][0] + x2), vload16(0, v[0][2] + x2)),
                                    max(vload16(0, v[2][0] + x2), vload16(0, v[2][2] + x2))));
            vstore8(CONVERT8(C)(-HITS16(lo, hi, sv).even), 0, sb + X);
        }
        for (; X < mx; ++X) {
            const int x0 = 2 * (X - 1);
            C n = 0;
            for (int k = 0; k < 2; ++k)
                for (int j = 0; j < 2; ++j)
                    for (int i = 0; i < 2; ++i) {
                        const int x = x0 + i;
                        const T a = min(min(min(v[k][j][x], v[k][j][x + 1]), min(v[k][j + 1][x], v[k][j + 1][x + 1])),
                                        min(min(v[k + 1][j][x], v[k + 1][j][x + 1]),
                                            min(v[k + 1][j + 1][x], v[k + 1][j + 1][x + 1])));
                        const T b = max(max(max(v[k][j][x], v[k][j][x + 1]), max(v[k][j + 1][x], v[k][j + 1][x + 1])),
                                        max(max(v[k + 1][j][x], v[k + 1][j][x + 1]),
                                            max(v[k + 1][j + 1][x], v[k + 1][j + 1][x + 1])));
                        n += intersected(a, b, s);
                    }
            cn[X] = n;
            const T a = min(min(min(v[0][0][x0], v[0][0][x0 + 2]), min(v[0][2][x0], v[0][2][x0 + 2])),
                            min(min(v[2][0][x0], v[2][0][x0 + 2]), min(v[2][2][x0], v[2][2][x0 + 2])));
            const T b = max(max(max(v[0][0][x0], v[0][0][x0 + 2]), max(v[0][2][x0], v[0][2][x0 + 2])),
                            max(max(v[2][0][x0], v[2][0][x0 + 2]), max(v[2][2][x0], v[2][2][x0 + 2])));
            sb[X] = intersected(a, b, s);
        }
    }
}

// One work-item per block of the hx × hy × hz blocks (hx = (nx + p + 1) / 2, ...); the global
// size may be rounded up along x (items beyond hx return), so that every launch has the same
// work-group size. `counts` and `sub` are the summed-area tables of block_indicators' outputs;
// `win` the window tables of G as for local_dimension_*; `ld` gets the LD of the block's
// vertices, read at its first vertex max(0, 2 X - p).
__kernel void block_dimension(__global const C* counts, __global const C* sub, int mx, int my,
                              __global const int4* win, int nx, int ny, int p, int hx, int hy,
                              __global float* restrict ld) {
    const int X = get_global_id(0), Y = get_global_id(1), Z = get_global_id(2);
    if (X >= hx) return;
    const int4 wx = win[max(0, 2 * X - p)], wy = win[nx + max(0, 2 * Y - p)], wz = win[nx + ny + max(0, 2 * Z - p)];
    const size_t row = (size_t)mx, slice = row * (size_t)my;
    const C in_w = box(counts, row, slice, wx.s2, wx.s3, wy.s2, wy.s3, wz.s2, wz.s3);
    const C in_sub = box(sub, row, slice, wx.s2, wx.s3, wy.s2, wy.s3, wz.s2, wz.s3);
    ld[((size_t)Z * (size_t)hy + Y) * (size_t)hx + X] = log_ratio(in_w, in_sub);
}

// The same per row of blocks (Y, Z), rows shared out like cube_indicator_rows (CPUs): per
// row the y-z part of both box sums is taken once for every G' column into `col` and
// `col_sub` (mx counts each; nondecreasing along x), then two lookups per table and block.
// Returns 0, with no further work, when the row's windows hold no intersected G' cube
// anywhere along x (no LD in the row).
inline int block_row_columns(__global const C* counts, __global const C* sub, int mx, int my,
                             __global const int4* win, int nx, int ny, int p, int Y, int Z, __global C* col,
                             __global C* col_sub) {
    const size_t row = (size_t)mx, slice = row * (size_t)my;
    const int4 wy = win[nx + max(0, 2 * Y - p)], wz = win[nx + ny + max(0, 2 * Z - p)];
    const size_t o00 = wz.s2 * slice + wy.s2 * row, o01 = wz.s2 * slice + wy.s3 * row;
    const size_t o10 = wz.s3 * slice + wy.s2 * row, o11 = wz.s3 * slice + wy.s3 * row;
    const int last = mx - 1;
    if ((sub[o11 + last] - sub[o10 + last]) - (sub[o01 + last] - sub[o00 + last]) == 0) return 0;
    for (int u = 0; u < mx; ++u) {
        col[u] = (counts[o11 + u] - counts[o10 + u]) - (counts[o01 + u] - counts[o00 + u]);
        col_sub[u] = (sub[o11 + u] - sub[o10 + u]) - (sub[o01 + u] - sub[o00 + u]);
    }
    return 1;
}

// LD of block X of a row from its columns (block_row_columns).
#define BLOCK_LD(X) \
    log_ratio(col[win[max(0, 2 * (X) - p)].s3] - col[win[max(0, 2 * (X) - p)].s2], \
              col_sub[win[max(0, 2 * (X) - p)].s3] - col_sub[win[max(0, 2 * (X) - p)].s2])

// The rows of block_*_rows (rows shared out like cube_indicator_rows; `scratch`: 2 mx counts
// per work-item): `empty` for each block X of a row without LD, `block` for each block of
// the others, with the row's columns at hand.
#define BLOCK_ROWS(empty, block)                                                                 \
    const size_t item = get_global_id(0), items = get_global_size(0);                            \
    const size_t rows = (size_t)hy * (size_t)hz;                                                 \
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;                       \
    __global C* col = scratch + item * 2 * (size_t)mx;                                           \
    __global C* col_sub = col + mx;                                                              \
    for (size_t r = r0; r < r1; ++r) {                                                           \
        const size_t o = r * (size_t)hx;                                                         \
        if (!block_row_columns(counts, sub, mx, my, win, nx, ny, p, r % (size_t)hy, r / (size_t)hy, col, col_sub)) { \
            for (int X = 0; X < hx; ++X) empty;                                                  \
            continue;                                                                            \
        }                                                                                        \
        for (int X = 0; X < hx; ++X) block;                                                      \
    }

__kernel void block_dimension_rows(__global const C* counts, __global const C* sub, int mx, int my,
                                   __global const int4* win, int nx, int ny, int p, int hx, int hy, int hz,
                                   __global float* restrict ld, __global C* restrict scratch) {
    BLOCK_ROWS(ld[o + X] = NAN, ld[o + X] = BLOCK_LD(X))
}

// log_ratio(a, b) > h, with log2 taken only where the ratio r = a / b (in float, as
// log_ratio) lies within a factor 1 +- 2^-10 of 2^h: below (r <= lo) log2(r) <= h - 0.0014 and
// above (r >= hi) log2(r) >= h + 0.0014, far past log2's error of a few ulp. lo and hi come
// from the host (2^h (1 -+ 2^-10), infinite or 0 past float's range).
inline uchar above(C a, C b, float h, float lo, float hi) {
    if (!a || !b) return 0;
    const float r = (float)a / (float)b;
    return r <= lo ? 0 : r >= hi ? 1 : log2(r) > h;
}

// The same fused with the selection of the fractal-targeted filters: `sel` gets 1 for the
// blocks with LD > h (the LD of block_dimension_rows, compared as the filters compare it;
// NaN never qualifies), else 0: a byte per block instead of a float.
__kernel void block_selection_rows(__global const C* counts, __global const C* sub, int mx, int my,
                                   __global const int4* win, int nx, int ny, int p, int hx, int hy, int hz,
                                   float h, float lo, float hi, __global uchar* restrict sel,
                                   __global C* restrict scratch) {
    BLOCK_ROWS(sel[o + X] = 0, sel[o + X] = above(col[win[max(0, 2 * X - p)].s3] - col[win[max(0, 2 * X - p)].s2],
                                                  col_sub[win[max(0, 2 * X - p)].s3] - col_sub[win[max(0, 2 * X - p)].s2],
                                                  h, lo, hi))
}

// One work-item per vertex: global size (nx, ny, nz) exactly. The block field of
// block_dimension (hx × hy blocks per block slice, phase p) spread over the blocks' vertices.
__kernel void expand_blocks(__global const float* restrict blocks, int hx, int hy, int p, __global float* restrict ld) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    ld[(z * get_global_size(1) + y) * get_global_size(0) + x] =
        blocks[(((z + p) >> 1) * (size_t)hy + ((y + p) >> 1)) * (size_t)hx + ((x + p) >> 1)];
}
