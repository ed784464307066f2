// The OpenCL C sources of kernels/*.cl, embedded at build time (cmake/embed_kernels.cmake).
#pragma once

namespace clfractal::detail {

struct KernelSource {
    const char* family;  ///< file name without .cl
    const char* source;
};
/// Terminated by {nullptr, nullptr}.
extern const KernelSource kernel_sources[];

}  // namespace clfractal::detail
