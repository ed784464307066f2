// 3D summed-area tables (thesis eq. 2.8), in place: inclusive prefix sums along x, then
// y, then z; the composition of the three 1D scans is the 3D table. -DC=uint|ulong is
// the count type (sums wrap modulo 2^32 or 2^64).
//
// Each pass views the table as [outer][n][inner] and scans along the middle index n:
//   x: outer = ny * nz, n = nx, inner = 1
//   y: outer = nz,      n = ny, inner = nx
//   z: outer = 1,       n = nz, inner = nx * ny
//
// Two variants, chosen per device (Tuning::sat_variant):
//  - sequential (CPUs), local size 1 and a few work-items per core, each taking a
//    contiguous share of the work: scan_lines_sequential runs the x pass with a running
//    sum in a register; scan_rows_sequential runs the y and z passes by adding row j-1 to
//    row j over a stretch of the contiguous inner index (vectorised by the compiler).
//  - workgroup (GPUs): scan_lines_workgroup runs the x pass with one work-group per
//    line, scanning WG elements at a time in local memory with a running carry;
//    scan_columns_workgroup runs the y and z passes with work-groups of TX adjacent
//    columns (local dimension 0, so loads are coalesced along x) by TL work-items along
//    the axis (local dimension 1). Any work-group shape works, powers of two or not.

#ifndef C
#define C uint
#endif

// x pass, sequential: work-item i of k scans lines [lines * i / k, lines * (i + 1) / k).
__kernel void scan_lines_sequential(__global C* table, int n, ulong lines) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t l0 = lines * item / items, l1 = lines * (item + 1) / items;
    for (size_t l = l0; l < l1; ++l) {
        __global C* p = table + l * (size_t)n;
        C s = 0;
        for (int i = 0; i < n; ++i) {
            s += p[i];
            p[i] = s;
        }
    }
}

// y and z passes, sequential: the work is outer * ceil(inner / chunk) tasks (one outer
// index, one stretch of at most `chunk` inner indices), shared out like the lines above.
// A stretch of two consecutive rows stays in cache from one j to the next.
__kernel void scan_rows_sequential(__global C* table, int n, ulong inner, ulong outer, ulong chunk) {
    const size_t item = get_global_id(0), items = get_global_size(0);
    const size_t chunks = (inner + chunk - 1) / chunk, tasks = outer * chunks;
    const size_t t0 = tasks * item / items, t1 = tasks * (item + 1) / items;
    for (size_t t = t0; t < t1; ++t) {
        const size_t o = t / chunks, c0 = (t % chunks) * chunk, c1 = min(inner, c0 + chunk);
        __global C* plane = table + o * (size_t)n * inner;
        for (int j = 1; j < n; ++j) {
            __global const C* prev = plane + (size_t)(j - 1) * inner;
            __global C* row = plane + (size_t)j * inner;
            for (size_t x = c0; x < c1; ++x) row[x] += prev[x];
        }
    }
}

// x pass, workgroup: global (WG, ny, nz), local (WG, 1, 1); `scratch` holds WG counts.
// Hillis-Steele scan of each block of WG elements, plus the carry of the blocks before.
__kernel void scan_lines_workgroup(__global C* table, int n, __local C* scratch) {
    const int lid = get_local_id(0), wg = get_local_size(0);
    const size_t line = get_group_id(1) + get_num_groups(1) * get_group_id(2);
    __global C* p = table + line * (size_t)n;
    C carry = 0;
    for (int base = 0; base < n; base += wg) {
        const int i = base + lid;
        C v = i < n ? p[i] : 0;
        scratch[lid] = v;
        barrier(CLK_LOCAL_MEM_FENCE);
        for (int off = 1; off < wg; off <<= 1) {
            const C add = lid >= off ? scratch[lid - off] : 0;
            barrier(CLK_LOCAL_MEM_FENCE);
            v += add;
            scratch[lid] = v;
            barrier(CLK_LOCAL_MEM_FENCE);
        }
        if (i < n) p[i] = v + carry;
        carry += scratch[wg - 1];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
}

// y and z passes, workgroup: global (inner rounded up to TX, TL, outer), local (TX, TL, 1);
// `scratch` holds TX * TL counts. Each column (one inner index of one outer index) is
// scanned TL elements at a time with a running carry, like the lines above.
__kernel void scan_columns_workgroup(__global C* table, int n, ulong inner, __local C* scratch) {
    const int lx = get_local_id(0), ly = get_local_id(1);
    const int tx = get_local_size(0), tl = get_local_size(1);
    const size_t col = get_global_id(0);
    const bool live = col < inner;  // the last group may reach past the last column
    __global C* p = table + get_global_id(2) * (size_t)n * inner + col;
    C carry = 0;
    for (int base = 0; base < n; base += tl) {
        const int j = base + ly;
        const bool in = live && j < n;
        C v = in ? p[(size_t)j * inner] : 0;
        scratch[ly * tx + lx] = v;
        barrier(CLK_LOCAL_MEM_FENCE);
        for (int off = 1; off < tl; off <<= 1) {
            const C add = ly >= off ? scratch[(ly - off) * tx + lx] : 0;
            barrier(CLK_LOCAL_MEM_FENCE);
            v += add;
            scratch[ly * tx + lx] = v;
            barrier(CLK_LOCAL_MEM_FENCE);
        }
        if (in) p[(size_t)j * inner] = v + carry;
        carry += scratch[(tl - 1) * tx + lx];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
}
