// Device memory bandwidth probe: a plain copy, 16 bytes per work-item.
// Assumes the global size equals the number of uint4 elements.
__kernel void copy_uint4(__global const uint4* src, __global uint4* dst) {
    size_t i = get_global_id(0);
    dst[i] = src[i];
}
