// Dense linear algebra (CLBlast) as a module loaded on first use (device/blas_loader.cpp):
// CLBlast's start-up (its static tables and relocations, ~1.2 ms of a process start on a
// 2-core Xeon) is paid only by processes that fit more than two levels or correlate
// curves. The module (device/blas.cpp, the library file clfractal_blas) links CLBlast and
// OpenCL only and exports one C entry, clfractal_blas_module(), returning this table.
#pragma once
#include <cstddef>

#include "clfractal/opencl.hpp"

namespace clfractal::detail {

/// Changed whenever the table or a signature in it changes: a module of another number is
/// not used.
constexpr int blas_module_abi = 1;

/// Each call returns CLBlast's status (0: success) and enqueues its work on `queue`.
struct BlasModule {
    int abi;
    /// y = A x, A row-major m x n (float, double).
    int (*gemv_float)(std::size_t m, std::size_t n, cl_mem a, cl_mem x, cl_mem y, cl_command_queue queue);
    int (*gemv_double)(std::size_t m, std::size_t n, cl_mem a, cl_mem x, cl_mem y, cl_command_queue queue);
    /// out[at] = x . y over n elements (float, double).
    int (*dot_float)(std::size_t n, cl_mem out, std::size_t at, cl_mem x, cl_mem y, cl_command_queue queue);
    int (*dot_double)(std::size_t n, cl_mem out, std::size_t at, cl_mem x, cl_mem y, cl_command_queue queue);
    /// Releases CLBlast's process-wide caches of compiled programs (release_blas_caches).
    void (*clear_cache)();
};

/// The module's file name, as the loader looks for it beside the library.
constexpr const char* blas_module_file = "libclfractal_blas.so";

/// The module, loaded by the first call (thread-safe); throws DeviceError saying why when it
/// cannot be.
const BlasModule& blas();

}  // namespace clfractal::detail

/// The module's one entry.
extern "C" const clfractal::detail::BlasModule* clfractal_blas_module();
