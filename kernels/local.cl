// Local fractal dimension (DESIGN §1; thesis eq. 2.6), in three steps per grid:
//   cube_indicator_*   the 0/1 "cube intersected" indicator, zero-padded (below)
//   (sat.cl)           its summed-area table
//   local_dimension_*  two box queries per vertex, one in G and one in G', and the log ratio
//
// -DT=uchar|ushort|short|float is the value type, -DC=uint|ulong the count type. Integer
// data (-DINTEGER_VALUES) compares with the integer ceil(s), which selects exactly the cubes
// a < s <= b selects for a real s; float data compares with s as a float.
//
// Padding: the table of a grid of nx × ny × nz vertices has nx × ny × nz entries, entry
// (x, y, z) holding cube (x - 1, y - 1, z - 1) and the planes x = 0, y = 0, z = 0 holding 0.
// Its inclusive summed-area table S then gives the count of the cubes [x0, x1) × [y0, y1) ×
// [z0, z1) as the inclusion-exclusion of S at those very corners, with no border cases.

#ifndef C
#define C uint
#endif

#ifdef INTEGER_VALUES
typedef int iso_t;
#else
typedef float iso_t;
#endif

// Two variants of each kernel, chosen per device (Tuning::local_variant):
//  - *_vertices (GPUs): one work-item per table entry or vertex.
//  - *_rows (CPUs): local size 1 and a few work-items per core, each walking a contiguous
//    share of the x-rows; per row the window bounds along y and z are computed once and
//    the inner loops over x read contiguous rows (vectorised by the compiler).

inline C intersected(T a, T b, iso_t s) {
#ifdef INTEGER_VALUES
    return (int)a < s && s <= (int)b;
#else
    return a < s && s <= b;
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

// The windows (DESIGN §1, revision 2) are not computed here: `win` holds the host's
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
