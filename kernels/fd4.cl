// 4D fractal dimension (docs/definitions.md §24 "4D fractal dimension"; thesis 6.4): per
// cube with span [a, b] the number of value bins it touches,
//     B_q(a, b) = floor((b - vmin) / q) - floor((a - vmin) / q) + 1,
// summed over the cubes of a grid (cube_bins_rows) or written as a zero-padded table for the
// summed-area tables of the local field (cube_bins_table, the layout of local.cl's indicator).
//
// -DT is the value type, -DC=uint|ulong the table type. Two ways to get the bin of a value:
//  - default (needs cl_khr_fp64): bin(x) = floor(((double)x - vmin) / q) in double, vmin and q
//    kernel arguments (BIN_T = double);
//  - -DBIN_INDEX: the values are already bin indices (T = long, computed by the host in
//    double); vmin and q are unused (BIN_T = long).
// Either way B = bin(max) - bin(min) + 1 over the cube's 8 values: x -> bin(x) is
// non-decreasing (a subtraction and a division by q > 0, each correctly rounded, are
// monotone, and so is floor), so the bin of the span's max (min) is the max (min) of the
// vertices' bins. The host guarantees every bin index and every sum fits 63 bits.

#ifdef BIN_INDEX
typedef long BIN_T;
inline long bin_of(T x, BIN_T vmin, BIN_T q) { return (long)x; }
#else
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double BIN_T;
inline long bin_of(T x, BIN_T vmin, BIN_T q) { return (long)floor(((double)x - vmin) / q); }
#endif

#ifndef C
#define C ulong
#endif

// B_q of the cube whose lowest corner is p (row length `row`, slice `slice`).
inline ulong cube_bins(__global const T* p, size_t row, size_t slice, BIN_T vmin, BIN_T q) {
    const T a = min(min(min(p[0], p[1]), min(p[row], p[row + 1])),
                    min(min(p[slice], p[slice + 1]), min(p[slice + row], p[slice + row + 1])));
    const T b = max(max(max(p[0], p[1]), max(p[row], p[row + 1])),
                    max(max(p[slice], p[slice + 1]), max(p[slice + row], p[slice + row + 1])));
    return (ulong)(bin_of(b, vmin, q) - bin_of(a, vmin, q) + 1);
}

// One work-item per row of cubes (y, z): global size (ny - 1, nz - 1) exactly (both >= 1).
// sums[y + (ny - 1) z] = the sum of B_q over the row's nx - 1 cubes (64-bit).
// The row walks its columns of 4 vertices (x; y, y + 1; z, z + 1): a cube's bins are those of
// its two columns joined, since x -> bin(x) is non-decreasing (the bin of the larger value is
// the larger bin), so each vertex is read and each column binned once.
__kernel void cube_bins_rows(__global const T* restrict vol, int nx, int ny, BIN_T vmin, BIN_T q,
                             __global ulong* restrict sums) {
    const size_t y = get_global_id(0), z = get_global_id(1);
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    __global const T* p = vol + z * slice + y * row;
    long lo = bin_of(min(min(p[0], p[row]), min(p[slice], p[slice + row])), vmin, q);
    long hi = bin_of(max(max(p[0], p[row]), max(p[slice], p[slice + row])), vmin, q);
    ulong sum = 0;
    for (int x = 1; x < nx; ++x) {
        const T a = p[x], b = p[x + row], c = p[x + slice], d = p[x + slice + row];
        const long next_lo = bin_of(min(min(a, b), min(c, d)), vmin, q);
        const long next_hi = bin_of(max(max(a, b), max(c, d)), vmin, q);
        sum += (ulong)(max(hi, next_hi) - min(lo, next_lo) + 1);
        lo = next_lo, hi = next_hi;
    }
    sums[z * (size_t)(ny - 1) + y] = sum;
}

// One work-item per table entry: global size (nx, ny, nz) exactly. Entry (x, y, z) holds
// B_q of cube (x - 1, y - 1, z - 1); the planes x = 0, y = 0, z = 0 hold 0 (local.cl).
__kernel void cube_bins_table(__global const T* restrict vol, int nx, int ny, BIN_T vmin, BIN_T q,
                              __global C* restrict table) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    C bins = 0;
    if (x && y && z) bins = (C)cube_bins(vol + (z - 1) * slice + (y - 1) * row + (x - 1), row, slice, vmin, q);
    table[z * slice + y * row + x] = bins;
}
