// The subsampling kernel's typed call, shared by the pyramid and the span counter.
// Private to the library.
#pragma once
#include "device/kernel_call.hpp"

namespace clfractal {

/// kernels/pyramid.cl subsample(src, nx, ny, dst, mx, my).
using SubsampleKernel = KernelCall<cl::Buffer, int, int, cl::Buffer, int, int>;

}  // namespace clfractal
