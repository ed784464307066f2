// Subsampling (docs/definitions.md §6 "Pyramid levels"): the next level keeps the vertices whose
// coordinates are even, n' = (n - 1) / 2 + 1 per axis. One work-item per output
// vertex; global size (mx rounded up to the work-group width, my, mz).
__kernel void subsample(__global const T* restrict src, int nx, int ny,
                        __global T* restrict dst, int mx, int my) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    if (x >= (size_t)mx) return;
    dst[(z * my + y) * mx + x] = src[((2 * z) * ny + 2 * y) * nx + 2 * x];
}
