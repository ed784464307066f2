// Local fractal dimension (DESIGN §1; thesis eq. 2.6), in three steps per grid:
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

inline C intersected(T a, T b, iso_t s) {
#ifdef INTEGER_VALUES
    return (long)a < s && s <= (long)b;
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

// floor(v / 2) for negative v too (C division truncates towards zero).
inline int floor_half(int v) { return v >= 0 ? v / 2 : -((1 - v) / 2); }

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

// One work-item per vertex of G: global size (nx, ny, nz) exactly. `table` and `table_sub`
// are the summed-area tables of the padded indicators of G (nx × ny × nz) and G'
// (mx × my × mz); half_k = k / 2.
__kernel void local_dimension_vertices(__global const C* table, int nx, int ny, int nz,
                              __global const C* table_sub, int mx, int my, int mz,
                              int half_k, __global float* restrict ld) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    // Window W in G: cubes [max(0, x - k/2), min(n - 1, x + k/2)) per axis.
    const int x0 = max(0, x - half_k), x1 = min(nx - 1, x + half_k);
    const int y0 = max(0, y - half_k), y1 = min(ny - 1, y + half_k);
    const int z0 = max(0, z - half_k), z1 = min(nz - 1, z + half_k);
    // Window W' in G': cubes [max(0, c0), min(n' - 1, c0 + k/2)), c0 = floor((x - k/2) / 2);
    // never empty-reversed, since c0 <= n' - 1 (clamped all the same).
    const int cx = floor_half(x - half_k), cy = floor_half(y - half_k), cz = floor_half(z - half_k);
    const int u0 = max(0, cx), u1 = max(u0, min(mx - 1, cx + half_k));
    const int v0 = max(0, cy), v1 = max(v0, min(my - 1, cy + half_k));
    const int w0 = max(0, cz), w1 = max(w0, min(mz - 1, cz + half_k));
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    const size_t row_sub = (size_t)mx, slice_sub = row_sub * (size_t)my;
    const C in_w = box(table, row, slice, x0, x1, y0, y1, z0, z1);
    const C in_sub = box(table_sub, row_sub, slice_sub, u0, u1, v0, v1, w0, w1);
    ld[(size_t)z * slice + (size_t)y * row + x] = log_ratio(in_w, in_sub);
}

// The same per x-row, rows shared out like cube_indicator_rows. Per row, the y-z part of
// the inclusion-exclusion is summed once for every column into `scratch` (nx + mx counts
// per work-item), so that each vertex needs only two lookups per grid.
__kernel void local_dimension_rows(__global const C* table, int nx, int ny, int nz,
                                   __global const C* table_sub, int mx, int my, int mz,
                                   int half_k, __global float* restrict ld, __global C* restrict scratch) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t rows = (size_t)ny * (size_t)nz, row = (size_t)nx, slice = row * (size_t)ny;
    const size_t row_sub = (size_t)mx, slice_sub = row_sub * (size_t)my;
    const size_t r0 = rows * item / items, r1 = rows * (item + 1) / items;
    __global C* col = scratch + item * (size_t)(nx + mx);
    __global C* col_sub = col + nx;
    for (size_t r = r0; r < r1; ++r) {
        const int y = r % (size_t)ny, z = r / (size_t)ny;
        const int y0 = max(0, y - half_k), y1 = min(ny - 1, y + half_k);
        const int z0 = max(0, z - half_k), z1 = min(nz - 1, z + half_k);
        const int cy = floor_half(y - half_k), cz = floor_half(z - half_k);
        const int v0 = max(0, cy), v1 = max(v0, min(my - 1, cy + half_k));
        const int w0 = max(0, cz), w1 = max(w0, min(mz - 1, cz + half_k));
        __global const C* a00 = table + z0 * slice + y0 * row;
        __global const C* a01 = table + z0 * slice + y1 * row;
        __global const C* a10 = table + z1 * slice + y0 * row;
        __global const C* a11 = table + z1 * slice + y1 * row;
        for (int x = 0; x < nx; ++x) col[x] = (a11[x] - a10[x]) - (a01[x] - a00[x]);
        __global const C* b00 = table_sub + w0 * slice_sub + v0 * row_sub;
        __global const C* b01 = table_sub + w0 * slice_sub + v1 * row_sub;
        __global const C* b10 = table_sub + w1 * slice_sub + v0 * row_sub;
        __global const C* b11 = table_sub + w1 * slice_sub + v1 * row_sub;
        for (int u = 0; u < mx; ++u) col_sub[u] = (b11[u] - b10[u]) - (b01[u] - b00[u]);
        __global float* out = ld + r * row;
        for (int x = 0; x < nx; ++x) {
            const int x0 = max(0, x - half_k), x1 = min(nx - 1, x + half_k);
            const int cx = floor_half(x - half_k);
            const int u0 = max(0, cx), u1 = max(u0, min(mx - 1, cx + half_k));
            out[x] = log_ratio(col[x1] - col[x0], col_sub[u1] - col_sub[u0]);
        }
    }
}
