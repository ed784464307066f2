// Smooth isosurface construction (docs/definitions.md §18 "Smooth isosurface construction";
// thesis chapter 5), Algorithm 1 on the device: which grid edges are high fractal. The queue of
// Algorithm 2 runs on the host.
//
// -DT is the value type and s an iso_t (kernels/common.cl): integer data (-DINTEGER_VALUES)
// compares with the integer ceil(s), which selects exactly the edges a < s <= b selects for a
// real s; float data compares with s in its own type. The threshold comes in as the largest float <= h,
// so that for a float LD, LD > h_f iff LD > h.

// Edge (p, q) is intersected iff min < s <= max.
inline bool edge_intersected(T p, T q, iso_t s) {
#ifdef INTEGER_VALUES
    const long a = min((long)p, (long)q), b = max((long)p, (long)q);
#else
    const T a = min(p, q), b = max(p, q);
#endif
    return a < s && s <= b;
}

// One work-item per vertex: global size (nx, ny, nz) exactly. flags[v] gets bit 0, 1, 2
// when the edge from v to its +x, +y, +z neighbour exists and is high fractal (intersected
// and LD > h at either end; NaN never is), and bit 3 when LD(v) > h.
__kernel void high_fractal_edges(__global const T* restrict vol, __global const float* restrict ld, int nx, int ny,
                                 int nz, iso_t s, float h, __global uchar* restrict flags) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    const size_t i = z * slice + y * row + x;
    const T f = vol[i];
    const bool hot = ld[i] > h;
    uchar out = hot ? 8 : 0;
    if (x + 1 < (size_t)nx && edge_intersected(f, vol[i + 1], s) && (hot || ld[i + 1] > h)) out |= 1;
    if (y + 1 < (size_t)ny && edge_intersected(f, vol[i + row], s) && (hot || ld[i + row] > h)) out |= 2;
    if (z + 1 < (size_t)nz && edge_intersected(f, vol[i + slice], s) && (hot || ld[i + slice] > h)) out |= 4;
    flags[i] = out;
}
