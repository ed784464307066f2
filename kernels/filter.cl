// Denoising filters (docs/definitions.md §16 "Filters", §17 "Fractal-targeted filtering";
// thesis chapter 4 and §6.3): 3×3×3 median, separable Gaussian, 3D bilateral, each plain or
// masked by the local fractal dimension.
//
// Defines: -DT (and -DT_IS_<T>) the value type; -DINTEGER_VALUES for the integer types
// (results rounded to nearest even and saturated to the type); -DACC_DOUBLE for double
// accumulation (below); -DRADIUS=r for the
// Gaussian and bilateral kernels; -DMASKED for the fractal-targeted kernels, which take the
// LD field `ld` of the output slices and a float threshold `h`, and filter only where
// ld > h (NaN never qualifies), copying the input elsewhere.
//
// Slabs: `in` holds nz_in slices, the output slices are z_begin .. z_begin + nz_out - 1 of
// `in` and go to `out` from its slice 0. Clamp-to-edge is applied at the borders of `in`:
// the host gives each slab a halo of the radius (or the true volume border), so a slab's
// results equal the in-core run's.
//
// Variants (Tuning::filter_variant):
//  - *_rows (CPUs): local size 1, a few work-items per core, each walking a contiguous
//    share of the output x-rows; the interior of each row is a loop over x with fixed
//    offsets, which the compiler vectorises; the two border columns clamp.
//  - *_vertices (GPUs): one work-item per output vertex, global size (nx, ny, nz_out)
//    exactly; neighbours come through the caches (a 3×3×3 median reads 27 values a
//    work-item, all of them shared with its neighbours);
//  - median_tiled (GPUs, -DTILE_X -DTILE_Y): the median through local-memory tiles.

// One row per value type (T_IS_<OpenCL type> from the host): TV the vector of VEC values,
// SEL_CAST the select() mask for TV from an int16 relational result, CONVERT_SAT(_V) the
// rounding (to nearest even) and saturating conversion of integer results.
#define VEC 16
#define IV int16
#define VLOAD vload16
#define VSTORE vstore16
#if defined(T_IS_uchar)
#define TV uchar16
#define SEL_CAST(m) convert_char16(m)
#define CONVERT_SAT(v) convert_uchar_sat_rte(v)
#define CONVERT_SAT_V(v) convert_uchar16_sat_rte(v)
#elif defined(T_IS_char)
#define TV char16
#define SEL_CAST(m) convert_char16(m)
#define CONVERT_SAT(v) convert_char_sat_rte(v)
#define CONVERT_SAT_V(v) convert_char16_sat_rte(v)
#elif defined(T_IS_ushort)
#define TV ushort16
#define SEL_CAST(m) convert_short16(m)
#define CONVERT_SAT(v) convert_ushort_sat_rte(v)
#define CONVERT_SAT_V(v) convert_ushort16_sat_rte(v)
#elif defined(T_IS_short)
#define TV short16
#define SEL_CAST(m) convert_short16(m)
#define CONVERT_SAT(v) convert_short_sat_rte(v)
#define CONVERT_SAT_V(v) convert_short16_sat_rte(v)
#elif defined(T_IS_uint)
#define TV uint16
#define SEL_CAST(m) (m)
#define CONVERT_SAT(v) convert_uint_sat_rte(v)
#define CONVERT_SAT_V(v) convert_uint16_sat_rte(v)
#elif defined(T_IS_int)
#define TV int16
#define SEL_CAST(m) (m)
#define CONVERT_SAT(v) convert_int_sat_rte(v)
#define CONVERT_SAT_V(v) convert_int16_sat_rte(v)
#elif defined(T_IS_double)
#define TV double16
#define SEL_CAST(m) convert_long16(m)
#define CONVERT_SAT(v) (v)
#define CONVERT_SAT_V(v) (v)
#else
#define TV float16
#define SEL_CAST(m) (m)
#define CONVERT_SAT(v) (v)
#define CONVERT_SAT_V(v) (v)
#endif
#define TO_T(v) CONVERT_SAT(v)

// The accumulator of the Gaussian and bilateral filters (weights, sums, the Gaussian's
// temporaries): float, or double with -DACC_DOUBLE (int32, uint32 and float64 data, whose
// values a float does not hold). ACCV is its vector of VEC, LDV the vector of LD values.
#ifdef ACC_DOUBLE
typedef double acc_t;
#define ACCV double16
#define CONVERT_ACCV(v) convert_double16(v)
#else
typedef float acc_t;
#define ACCV float16
#define CONVERT_ACCV(v) convert_float16(v)
#endif
#define LDV float16

#ifndef RADIUS
#define RADIUS 1
#endif

inline int clamp_index(int i, int n) { return clamp(i, 0, n - 1); }

#ifdef MASKED
#define MASK_ARGS , __global const float* restrict ld, float h
#define SELECTED(i) (ld[i] > h)
#else
#define MASK_ARGS
#define SELECTED(i) true
#endif
#ifdef BLOCK_MASKED
// median_rows only: the selection of blocks of 2×2×2 vertices (block_selection: one byte
// per block, hx × hy × hz, x fastest, phase p); vertex (x, y, z) of the whole volume is
// selected when block ((x + p) / 2, (y + p) / 2, (z + p) / 2) is. The slab is the whole volume.
// Work-item i writes tally[2 i] and tally[2 i + 1]: its selected vertices and, of those, the
// ones whose median differs from the input (no pass over the volume afterwards).
#define ROW_MASK_ARGS , __global const uchar* restrict sel, int hx, int hy, int p, __global ulong* restrict tally
// Vertex x of the row: the median where its block is selected, counted, else the input.
#define BLOCK_MASKED_STORE(x, median_expr)                 \
    if (mb[((x) + p) >> 1]) {                              \
        const T m_ = (median_expr);                        \
        o[x] = m_;                                         \
        ++selected;                                        \
        changed += m_ != c[x];                             \
    } else {                                               \
        o[x] = c[x];                                       \
    }
#else
#define ROW_MASK_ARGS MASK_ARGS
#endif

// ------------------------------------------------------------------ median

// Compare-exchange: a := min, b := max.
#define CX(a, b) { const T t_ = min(a, b); b = max(a, b); a = t_; }

// Forgetful selection (Paeth; McGuire's 3×3 median), written out as a fixed network of
// 153 compare-exchanges on constant indices (the compiler keeps v in registers and drops the
// halves that are never used): keep 15 candidates, move their minimum and maximum aside with
// compare-exchanges (pairs, then a min chain and a max chain), replace them by the next
// value, and so on; after 13 rounds the median of the 27 values is the middle of the last 3.
// Generated once from that description and checked against sorting
// (test/processing/filter_test.cpp checks every kernel against std::nth_element).
#define MEDIAN27_NETWORK(CX, v) \
    CX(v[0], v[14]); CX(v[1], v[13]); CX(v[2], v[12]); CX(v[3], v[11]); CX(v[4], v[10]); CX(v[5], v[9]); CX(v[6], v[8]); \
    CX(v[0], v[1]); CX(v[0], v[2]); CX(v[0], v[3]); CX(v[0], v[4]); CX(v[0], v[5]); CX(v[0], v[6]); CX(v[0], v[7]); CX(v[7], v[14]); \
    CX(v[8], v[14]); CX(v[9], v[14]); CX(v[10], v[14]); CX(v[11], v[14]); CX(v[12], v[14]); CX(v[13], v[14]); CX(v[1], v[15]); \
    CX(v[2], v[13]); CX(v[3], v[12]); CX(v[4], v[11]); CX(v[5], v[10]); CX(v[6], v[9]); CX(v[7], v[8]); CX(v[1], v[2]); CX(v[1], v[3]); \
    CX(v[1], v[4]); CX(v[1], v[5]); CX(v[1], v[6]); CX(v[1], v[7]); CX(v[8], v[15]); CX(v[9], v[15]); CX(v[10], v[15]); \
    CX(v[11], v[15]); CX(v[12], v[15]); CX(v[13], v[15]); CX(v[2], v[16]); CX(v[3], v[13]); CX(v[4], v[12]); CX(v[5], v[11]); \
    CX(v[6], v[10]); CX(v[7], v[9]); CX(v[2], v[3]); CX(v[2], v[4]); CX(v[2], v[5]); CX(v[2], v[6]); CX(v[2], v[7]); CX(v[2], v[8]); \
    CX(v[8], v[16]); CX(v[9], v[16]); CX(v[10], v[16]); CX(v[11], v[16]); CX(v[12], v[16]); CX(v[13], v[16]); CX(v[3], v[17]); \
    CX(v[4], v[13]); CX(v[5], v[12]); CX(v[6], v[11]); CX(v[7], v[10]); CX(v[8], v[9]); CX(v[3], v[4]); CX(v[3], v[5]); CX(v[3], v[6]); \
    CX(v[3], v[7]); CX(v[3], v[8]); CX(v[9], v[17]); CX(v[10], v[17]); CX(v[11], v[17]); CX(v[12], v[17]); CX(v[13], v[17]); \
    CX(v[4], v[18]); CX(v[5], v[13]); CX(v[6], v[12]); CX(v[7], v[11]); CX(v[8], v[10]); CX(v[4], v[5]); CX(v[4], v[6]); \
    CX(v[4], v[7]); CX(v[4], v[8]); CX(v[4], v[9]); CX(v[9], v[18]); CX(v[10], v[18]); CX(v[11], v[18]); CX(v[12], v[18]); \
    CX(v[13], v[18]); CX(v[5], v[19]); CX(v[6], v[13]); CX(v[7], v[12]); CX(v[8], v[11]); CX(v[9], v[10]); CX(v[5], v[6]); \
    CX(v[5], v[7]); CX(v[5], v[8]); CX(v[5], v[9]); CX(v[10], v[19]); CX(v[11], v[19]); CX(v[12], v[19]); CX(v[13], v[19]); \
    CX(v[6], v[20]); CX(v[7], v[13]); CX(v[8], v[12]); CX(v[9], v[11]); CX(v[6], v[7]); CX(v[6], v[8]); CX(v[6], v[9]); \
    CX(v[6], v[10]); CX(v[10], v[20]); CX(v[11], v[20]); CX(v[12], v[20]); CX(v[13], v[20]); CX(v[7], v[21]); CX(v[8], v[13]); \
    CX(v[9], v[12]); CX(v[10], v[11]); CX(v[7], v[8]); CX(v[7], v[9]); CX(v[7], v[10]); CX(v[11], v[21]); CX(v[12], v[21]); \
    CX(v[13], v[21]); CX(v[8], v[22]); CX(v[9], v[13]); CX(v[10], v[12]); CX(v[8], v[9]); CX(v[8], v[10]); CX(v[8], v[11]); \
    CX(v[11], v[22]); CX(v[12], v[22]); CX(v[13], v[22]); CX(v[9], v[23]); CX(v[10], v[13]); CX(v[11], v[12]); CX(v[9], v[10]); \
    CX(v[9], v[11]); CX(v[12], v[23]); CX(v[13], v[23]); CX(v[10], v[24]); CX(v[11], v[13]); CX(v[10], v[11]); CX(v[10], v[12]); \
    CX(v[12], v[24]); CX(v[13], v[24]); CX(v[11], v[25]); CX(v[12], v[13]); CX(v[11], v[12]); CX(v[13], v[25]); CX(v[12], v[26]); \
    CX(v[12], v[13]); CX(v[13], v[26]);

inline T median27(T* v) {
    MEDIAN27_NETWORK(CX, v);
    return v[13];
}

// The same on VEC neighbouring x at once (TV = T vector of width VEC).
#define CXV(a, b) { const TV t_ = min(a, b); b = max(a, b); a = t_; }
inline TV median27_vec(TV* v) {
    MEDIAN27_NETWORK(CXV, v);
    return v[13];
}

// The 27 neighbours of (x, y, z) for x with x - 1 and x + 1 given (clamped by the caller).
#define GATHER27(rows, xm, x, xp, v)                                                    \
    for (int r_ = 0; r_ < 9; ++r_) {                                                     \
        v[3 * r_] = rows[r_][xm];                                                         \
        v[3 * r_ + 1] = rows[r_][x];                                                      \
        v[3 * r_ + 2] = rows[r_][xp];                                                     \
    }

// Pointers to the 9 input rows (y + dy, z + dz), clamped, of output row (y, z).
#define NINE_ROWS(in, rows, y, zin, nx, ny, nz_in)                                        \
    __global const T* rows[9];                                                            \
    for (int dz = -1; dz <= 1; ++dz)                                                      \
        for (int dy = -1; dy <= 1; ++dy)                                                  \
            rows[3 * (dz + 1) + dy + 1] =                                                 \
                in + ((size_t)clamp_index(zin + dz, nz_in) * (size_t)ny + (size_t)clamp_index(y + dy, ny)) * (size_t)nx;

// The medians of columns x0 .. x0 + VEC - 1 (all interior: 1 <= x0, x0 + VEC <= nx - 1).
inline TV median_vec(__global const T* const* rows, int x0) {
    TV v[27];
    for (int r = 0; r < 9; ++r) {
        v[3 * r] = VLOAD(0, rows[r] + x0 - 1);
        v[3 * r + 1] = VLOAD(0, rows[r] + x0);
        v[3 * r + 2] = VLOAD(0, rows[r] + x0 + 1);
    }
    return median27_vec(v);
}

inline T median_scalar(__global const T* const* rows, int x, int nx) {
    T v[27];
    GATHER27(rows, max(x - 1, 0), x, min(x + 1, nx - 1), v);
    return median27(v);
}

// Output row r = y + ny z of the slab: VEC columns at a time in the interior, the rest one by
// one. Masked: blocks of VEC columns without a selected vertex are copied, others computed and
// merged.
__kernel void median_rows(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                          __global T* restrict out ROW_MASK_ARGS) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t nrows = (size_t)ny * (size_t)nz_out;
    const size_t r0 = nrows * item / items, r1 = nrows * (item + 1) / items;
#ifdef BLOCK_MASKED
    ulong selected = 0, changed = 0;
#endif
    for (size_t r = r0; r < r1; ++r) {
        const int y = (int)(r % (size_t)ny), z = (int)(r / (size_t)ny);
        NINE_ROWS(in, rows, y, z_begin + z, nx, ny, nz_in);
        __global T* o = out + r * (size_t)nx;
        __global const T* c = rows[4];  // the row itself
#ifdef MASKED
        __global const float* m = ld + r * (size_t)nx;
#elif defined(BLOCK_MASKED)
        __global const uchar* mb = sel + ((size_t)((z + p) >> 1) * (size_t)hy + (size_t)((y + p) >> 1)) * (size_t)hx;
        // A row whose blocks are all unselected is copied.
        int row_selected = 0;
        for (int b = 0; b < hx && !row_selected; ++b) row_selected = mb[b];
        if (!row_selected) {
            int x = 0;
            for (; x + VEC <= nx; x += VEC) VSTORE(VLOAD(0, c + x), 0, o + x);
            for (; x < nx; ++x) o[x] = c[x];
            continue;
        }
#endif
        int x = 0;
        for (; x < nx; ++x) {
            if (x >= 1 && x + VEC <= nx - 1) break;  // the vector loop takes over
#ifdef MASKED
            o[x] = m[x] > h ? median_scalar(rows, x, nx) : c[x];
#elif defined(BLOCK_MASKED)
            BLOCK_MASKED_STORE(x, median_scalar(rows, x, nx))
#else
            o[x] = median_scalar(rows, x, nx);
#endif
        }
        for (; x + VEC <= nx - 1; x += VEC) {
#ifdef MASKED
            const IV sel = isgreater(vload16(0, m + x), (LDV)h);
            if (!any(sel)) {
                VSTORE(VLOAD(0, c + x), 0, o + x);
                continue;
            }
            VSTORE(select(VLOAD(0, c + x), median_vec(rows, x), SEL_CAST(sel)), 0, o + x);
#elif defined(BLOCK_MASKED)
            // Columns x .. x + VEC - 1 lie in blocks (x + p) / 2 .. (x + VEC - 1 + p) / 2.
            int chunk_selected = 0;
            for (int b = (x + p) >> 1; b <= (x + VEC - 1 + p) >> 1; ++b) chunk_selected |= mb[b];
            if (!chunk_selected) {
                VSTORE(VLOAD(0, c + x), 0, o + x);
                continue;
            }
            T med[VEC];
            VSTORE(median_vec(rows, x), 0, med);
            for (int i = 0; i < VEC; ++i) {
                BLOCK_MASKED_STORE(x + i, med[i])
            }
#else
            VSTORE(median_vec(rows, x), 0, o + x);
#endif
        }
        for (; x < nx; ++x) {
#ifdef MASKED
            o[x] = m[x] > h ? median_scalar(rows, x, nx) : c[x];
#elif defined(BLOCK_MASKED)
            BLOCK_MASKED_STORE(x, median_scalar(rows, x, nx))
#else
            o[x] = median_scalar(rows, x, nx);
#endif
        }
    }
#ifdef BLOCK_MASKED
    tally[2 * item] = selected;
    tally[2 * item + 1] = changed;
#endif
}

__kernel void median_vertices(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                              __global T* restrict out MASK_ARGS) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t o = ((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx + (size_t)x;
    NINE_ROWS(in, rows, y, z_begin + z, nx, ny, nz_in);
    if (!SELECTED(o)) {
        out[o] = rows[4][x];
        return;
    }
    T v[27];
    GATHER27(rows, max(x - 1, 0), x, min(x + 1, nx - 1), v);
    out[o] = median27(v);
}

#ifdef TILE_X
// Work-group (TILE_X, TILE_Y, 1), global size (nx, ny) rounded up to it, nz_out: each group
// loads its tile of three slices with a 1-vertex border (clamped) into local memory once, and
// every work-item reads its 27 values from there (GPUs: 27 reads of local memory instead of 27
// of global memory per vertex).
__kernel __attribute__((reqd_work_group_size(TILE_X, TILE_Y, 1)))
void median_tiled(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                  __global T* restrict out MASK_ARGS) {
    __local T tile[3][TILE_Y + 2][TILE_X + 2];
    const int lx = get_local_id(0), ly = get_local_id(1);
    const int x0 = (int)get_group_id(0) * TILE_X - 1, y0 = (int)get_group_id(1) * TILE_Y - 1;
    const int z = get_global_id(2), zin = z_begin + z;
    for (int i = ly * TILE_X + lx; i < 3 * (TILE_Y + 2) * (TILE_X + 2); i += TILE_X * TILE_Y) {
        const int tx = i % (TILE_X + 2), ty = (i / (TILE_X + 2)) % (TILE_Y + 2), tz = i / ((TILE_X + 2) * (TILE_Y + 2));
        tile[tz][ty][tx] = in[((size_t)clamp_index(zin + tz - 1, nz_in) * (size_t)ny +
                               (size_t)clamp_index(y0 + ty, ny)) * (size_t)nx + (size_t)clamp_index(x0 + tx, nx)];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    const int x = get_global_id(0), y = get_global_id(1);
    if (x >= nx || y >= ny) return;
    const size_t o = ((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx + (size_t)x;
    if (!SELECTED(o)) {
        out[o] = tile[1][ly + 1][lx + 1];
        return;
    }
    T v[27];
    for (int dz = 0; dz < 3; ++dz)
        for (int dy = 0; dy < 3; ++dy)
            for (int dx = 0; dx < 3; ++dx) v[9 * dz + 3 * dy + dx] = tile[dz][ly + dy][lx + dx];
    out[o] = median27(v);
}
#endif

// ------------------------------------------------------------------ Gaussian

// Three passes with normalised weights w[0..2 RADIUS] (w[RADIUS + i] for offset i), acc_t
// accumulation: z (input type -> acc_t), y (acc_t -> acc_t), x (acc_t -> output type,
// rounded and saturated for integer types; masked: selected vertices only). Each pass
// accumulates in offset order -RADIUS .. RADIUS.

// The rows variants work on VEC columns at a time, the last nx % VEC one by one.

// Output rows (y, z) of the pass over z: reads `in` (nz_in slices of T).
__kernel void gauss_z_rows(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                           __constant acc_t* w, __global acc_t* restrict out) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t nrows = (size_t)ny * (size_t)nz_out;
    const size_t r0 = nrows * item / items, r1 = nrows * (item + 1) / items;
    for (size_t r = r0; r < r1; ++r) {
        const int y = (int)(r % (size_t)ny), z = (int)(r / (size_t)ny);
        __global const T* p[2 * RADIUS + 1];
        for (int k = -RADIUS; k <= RADIUS; ++k)
            p[k + RADIUS] = in + ((size_t)clamp_index(z_begin + z + k, nz_in) * (size_t)ny + (size_t)y) * (size_t)nx;
        __global acc_t* o = out + r * (size_t)nx;
        int x = 0;
        for (; x + VEC <= nx; x += VEC) {
            ACCV acc = 0;
            for (int k = 0; k <= 2 * RADIUS; ++k) acc += w[k] * CONVERT_ACCV(VLOAD(0, p[k] + x));
            vstore16(acc, 0, o + x);
        }
        for (; x < nx; ++x) {
            acc_t acc = 0;
            for (int k = 0; k <= 2 * RADIUS; ++k) acc += w[k] * (acc_t)p[k][x];
            o[x] = acc;
        }
    }
}

__kernel void gauss_y_rows(__global const acc_t* restrict in, int nx, int ny, int nz, __constant acc_t* w,
                           __global acc_t* restrict out) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t nrows = (size_t)ny * (size_t)nz;
    const size_t r0 = nrows * item / items, r1 = nrows * (item + 1) / items;
    for (size_t r = r0; r < r1; ++r) {
        const int y = (int)(r % (size_t)ny), z = (int)(r / (size_t)ny);
        __global const acc_t* p[2 * RADIUS + 1];
        for (int k = -RADIUS; k <= RADIUS; ++k)
            p[k + RADIUS] = in + ((size_t)z * (size_t)ny + (size_t)clamp_index(y + k, ny)) * (size_t)nx;
        __global acc_t* o = out + r * (size_t)nx;
        int x = 0;
        for (; x + VEC <= nx; x += VEC) {
            ACCV acc = 0;
            for (int k = 0; k <= 2 * RADIUS; ++k) acc += w[k] * vload16(0, p[k] + x);
            vstore16(acc, 0, o + x);
        }
        for (; x < nx; ++x) {
            acc_t acc = 0;
            for (int k = 0; k <= 2 * RADIUS; ++k) acc += w[k] * p[k][x];
            o[x] = acc;
        }
    }
}

// `orig` is the input (nz_in slices of T) for the unselected vertices of the masked kernel.
__kernel void gauss_x_rows(__global const acc_t* restrict in, int nx, int ny, int nz, __constant acc_t* w,
                           __global T* restrict out, __global const T* restrict orig, int z_begin MASK_ARGS) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t nrows = (size_t)ny * (size_t)nz;
    const size_t r0 = nrows * item / items, r1 = nrows * (item + 1) / items;
    for (size_t r = r0; r < r1; ++r) {
        __global const acc_t* p = in + r * (size_t)nx;
        __global T* o = out + r * (size_t)nx;
#ifdef MASKED
        __global const T* c = orig + ((size_t)z_begin * (size_t)ny) * (size_t)nx + r * (size_t)nx;
        __global const float* m = ld + r * (size_t)nx;
#define STORE_X(x, acc) o[x] = m[x] > h ? TO_T(acc) : c[x]
#else
#define STORE_X(x, acc) o[x] = TO_T(acc)
#endif
        // Columns x with x - RADIUS >= 0 and x + RADIUS + VEC <= nx go VEC at a time; the
        // others clamp, one by one.
        int x = 0;
        for (; x < nx; ++x) {
            if (x >= RADIUS && x + RADIUS + VEC <= nx) break;
            acc_t acc = 0;
            for (int k = -RADIUS; k <= RADIUS; ++k) acc += w[k + RADIUS] * p[clamp_index(x + k, nx)];
            STORE_X(x, acc);
        }
        for (; x + RADIUS + VEC <= nx; x += VEC) {
            ACCV acc = 0;
            for (int k = -RADIUS; k <= RADIUS; ++k) acc += w[k + RADIUS] * vload16(0, p + x + k);
#ifdef MASKED
            const IV sel = isgreater(vload16(0, m + x), (LDV)h);
            VSTORE(select(VLOAD(0, c + x), CONVERT_SAT_V(acc), SEL_CAST(sel)), 0, o + x);
#else
            VSTORE(CONVERT_SAT_V(acc), 0, o + x);
#endif
        }
        for (; x < nx; ++x) {
            acc_t acc = 0;
            for (int k = -RADIUS; k <= RADIUS; ++k) acc += w[k + RADIUS] * p[clamp_index(x + k, nx)];
            STORE_X(x, acc);
        }
#undef STORE_X
    }
}

// One work-item per vertex: global size (nx, ny, nz_out) exactly.
__kernel void gauss_z_vertices(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                               __constant acc_t* w, __global acc_t* restrict out) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    acc_t acc = 0;
    for (int k = -RADIUS; k <= RADIUS; ++k)
        acc += w[k + RADIUS] *
               (acc_t)in[((size_t)clamp_index(z_begin + z + k, nz_in) * (size_t)ny + (size_t)y) * (size_t)nx + x];
    out[((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx + x] = acc;
}

__kernel void gauss_y_vertices(__global const acc_t* restrict in, int nx, int ny, int nz, __constant acc_t* w,
                               __global acc_t* restrict out) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    acc_t acc = 0;
    for (int k = -RADIUS; k <= RADIUS; ++k)
        acc += w[k + RADIUS] * in[((size_t)z * (size_t)ny + (size_t)clamp_index(y + k, ny)) * (size_t)nx + x];
    out[((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx + x] = acc;
}

__kernel void gauss_x_vertices(__global const acc_t* restrict in, int nx, int ny, int nz, __constant acc_t* w,
                               __global T* restrict out, __global const T* restrict orig, int z_begin MASK_ARGS) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t row = ((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx;
    acc_t acc = 0;
    for (int k = -RADIUS; k <= RADIUS; ++k) acc += w[k + RADIUS] * in[row + clamp_index(x + k, nx)];
#ifdef MASKED
    out[row + x] = ld[row + x] > h ? TO_T(acc) : orig[(size_t)z_begin * (size_t)ny * (size_t)nx + row + x];
#else
    out[row + x] = TO_T(acc);
#endif
}

// ------------------------------------------------------------------ bilateral

// out(v) = sum_w ws(|w - v|) wr(f(w) - f(v)) f(w) / sum_w ws wr over the cube of radius
// RADIUS around v, clamp-to-edge (a clamped neighbour counts with the weight of its
// position), with ws(d) = exp(-d^2 / (2 sigma_s^2)) tabulated in `ws` (index
// (dz + R)(2R + 1)^2 + (dy + R)(2R + 1) + dx + R) and, for the plain filter,
// wr(t) = exp(-t^2 * inv_2sr2), inv_2sr2 = 1 / (2 sigma_r^2).
//
// LD-guided variant (-DLD_GUIDED; thesis §6.3): the range scale follows the local fractal
// dimension of v: sigma_r(v) = sigma_r * clamp(LD(v) - 2, 0, 1). Where LD(v) <= 2 or is
// undefined the value is kept; in the noisiest regions (LD -> 3) the filter approaches the
// plain bilateral filter with sigma_r. `ld` then holds LD of the output slices.
inline acc_t bilateral_at(__global const T* in, int nx, int ny, int nz_in, int x, int y, int zin,
                          __constant acc_t* ws, acc_t inv_2sr2) {
    const acc_t c = (acc_t)in[((size_t)zin * (size_t)ny + (size_t)y) * (size_t)nx + x];
    acc_t num = 0, den = 0;
    int k = 0;
    for (int dz = -RADIUS; dz <= RADIUS; ++dz) {
        const size_t zo = (size_t)clamp_index(zin + dz, nz_in) * (size_t)ny;
        for (int dy = -RADIUS; dy <= RADIUS; ++dy) {
            __global const T* row = in + (zo + (size_t)clamp_index(y + dy, ny)) * (size_t)nx;
            for (int dx = -RADIUS; dx <= RADIUS; ++dx, ++k) {
                const acc_t f = (acc_t)row[clamp_index(x + dx, nx)];
                const acc_t d = f - c;
                const acc_t wgt = ws[k] * exp(-d * d * inv_2sr2);
                num += wgt * f;
                den += wgt;
            }
        }
    }
    return num / den;  // den >= ws[centre] = 1
}

#ifdef LD_GUIDED
#define BILATERAL_ARGS , __global const float* restrict ld
#else
#define BILATERAL_ARGS MASK_ARGS
#endif

// The range term of vertex i (output-slab index); returns false where v keeps its value.
inline bool range_term(size_t i, acc_t inv_2sr2, acc_t* out_inv BILATERAL_ARGS) {
#ifdef LD_GUIDED
    if (isnan(ld[i]) || !(ld[i] > 2.0f)) return false;
    const float t = min(ld[i] - 2.0f, 1.0f);
    *out_inv = inv_2sr2 / ((acc_t)t * (acc_t)t);  // t = LD - 2 is exact in float
    return true;
#else
    *out_inv = inv_2sr2;
    return SELECTED(i);
#endif
}

// range_term with this build's mask arguments.
#if defined(LD_GUIDED)
#define RANGE_TERM(i, inv_2sr2, inv) range_term(i, inv_2sr2, inv, ld)
#elif defined(MASKED)
#define RANGE_TERM(i, inv_2sr2, inv) range_term(i, inv_2sr2, inv, ld, h)
#else
#define RANGE_TERM(i, inv_2sr2, inv) range_term(i, inv_2sr2, inv)
#endif

// bilateral_at for VEC neighbouring columns x0 .. x0 + VEC - 1, all with x0 - RADIUS >= 0
// and x0 + VEC + RADIUS <= nx; `inv` the range term per column.
inline ACCV bilateral_vec(__global const T* in, int nx, int ny, int nz_in, int x0, int y, int zin,
                        __constant acc_t* ws, ACCV inv) {
    const ACCV c = CONVERT_ACCV(VLOAD(0, in + ((size_t)zin * (size_t)ny + (size_t)y) * (size_t)nx + x0));
    ACCV num = 0, den = 0;
    int k = 0;
    for (int dz = -RADIUS; dz <= RADIUS; ++dz) {
        const size_t zo = (size_t)clamp_index(zin + dz, nz_in) * (size_t)ny;
        for (int dy = -RADIUS; dy <= RADIUS; ++dy) {
            __global const T* row = in + (zo + (size_t)clamp_index(y + dy, ny)) * (size_t)nx + x0;
            for (int dx = -RADIUS; dx <= RADIUS; ++dx, ++k) {
                const ACCV f = CONVERT_ACCV(VLOAD(0, row + dx));
                const ACCV d = f - c;
                const ACCV wgt = ws[k] * exp(-d * d * inv);
                num += wgt * f;
                den += wgt;
            }
        }
    }
    return num / den;
}

// Output rows of the slab: VEC columns at a time where the cube stays inside the row (blocks
// without a selected vertex copied), the border columns one by one.
__kernel void bilateral_rows(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                             __constant acc_t* ws, acc_t inv_2sr2, __global T* restrict out BILATERAL_ARGS) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t nrows = (size_t)ny * (size_t)nz_out;
    const size_t r0 = nrows * item / items, r1 = nrows * (item + 1) / items;
    for (size_t r = r0; r < r1; ++r) {
        const int y = (int)(r % (size_t)ny), z = (int)(r / (size_t)ny);
        __global const T* c = in + ((size_t)(z_begin + z) * (size_t)ny + (size_t)y) * (size_t)nx;
        __global T* o = out + r * (size_t)nx;
        int x = 0;
        for (;; ++x) {
            if (x >= RADIUS && x + VEC + RADIUS <= nx) {
                // The interior, VEC columns at a time.
                for (; x + VEC + RADIUS <= nx; x += VEC) {
#if defined(LD_GUIDED)
                    const LDV l = vload16(0, ld + r * (size_t)nx + x);
                    const IV sel = isgreater(l, (LDV)2.0f);
                    if (!any(sel)) {
                        VSTORE(VLOAD(0, c + x), 0, o + x);
                        continue;
                    }
                    const LDV t = select((LDV)1.0f, fmin(l - 2.0f, 1.0f), sel);
                    const ACCV inv = inv_2sr2 / (CONVERT_ACCV(t) * CONVERT_ACCV(t));  // t is exact
#elif defined(MASKED)
                    const IV sel = isgreater(vload16(0, ld + r * (size_t)nx + x), (LDV)h);
                    if (!any(sel)) {
                        VSTORE(VLOAD(0, c + x), 0, o + x);
                        continue;
                    }
                    const ACCV inv = inv_2sr2;
#else
                    const ACCV inv = inv_2sr2;
#endif
                    const TV f = CONVERT_SAT_V(bilateral_vec(in, nx, ny, nz_in, x, y, z_begin + z, ws, inv));
#if defined(LD_GUIDED) || defined(MASKED)
                    VSTORE(select(VLOAD(0, c + x), f, SEL_CAST(sel)), 0, o + x);
#else
                    VSTORE(f, 0, o + x);
#endif
                }
            }
            if (x >= nx) break;
            const size_t i = r * (size_t)nx + (size_t)x;
            acc_t inv;
            const bool on = RANGE_TERM(i, inv_2sr2, &inv);
            o[x] = on ? TO_T(bilateral_at(in, nx, ny, nz_in, x, y, z_begin + z, ws, inv)) : c[x];
        }
    }
}

__kernel void bilateral_vertices(__global const T* restrict in, int nx, int ny, int nz_in, int z_begin, int nz_out,
                                 __constant acc_t* ws, acc_t inv_2sr2, __global T* restrict out BILATERAL_ARGS) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t i = ((size_t)z * (size_t)ny + (size_t)y) * (size_t)nx + (size_t)x;
    acc_t inv;
    const bool on = RANGE_TERM(i, inv_2sr2, &inv);
    out[i] = on ? TO_T(bilateral_at(in, nx, ny, nz_in, x, y, z_begin + z, ws, inv))
                : in[((size_t)(z_begin + z) * (size_t)ny + (size_t)y) * (size_t)nx + x];
}
