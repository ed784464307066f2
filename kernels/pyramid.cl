// Subsampling (DESIGN §1 "Subsampling"): the next level keeps the vertices whose
// coordinates are even, n' = (n - 1) / 2 + 1 per axis. One work-item per output
// vertex; global size (mx, my, mz) exactly.
__kernel void subsample(__global const T* src, int nx, int ny,
                        __global T* dst, int mx, int my) {
    const size_t x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    dst[(z * my + y) * mx + x] = src[((2 * z) * ny + 2 * y) * nx + 2 * x];
}
