// The module clfractal_blas (device/blas_module.hpp): CLBlast's GEMV and DOT behind a table.
#include <clblast.h>

#include "device/blas_module.hpp"

namespace {

template <class R>
int gemv(std::size_t m, std::size_t n, cl_mem a, cl_mem x, cl_mem y, cl_command_queue queue) {
    return int(clblast::Gemv<R>(clblast::Layout::kRowMajor, clblast::Transpose::kNo, m, n, R(1), a, 0, n, x, 0, 1,
                                R(0), y, 0, 1, &queue));
}

template <class R>
int dot(std::size_t n, cl_mem out, std::size_t at, cl_mem x, cl_mem y, cl_command_queue queue) {
    return int(clblast::Dot<R>(n, out, at, x, 0, 1, y, 0, 1, &queue));
}

void clear_cache() { clblast::ClearCache(); }

const clfractal::detail::BlasModule table{clfractal::detail::blas_module_abi, gemv<float>, gemv<double>, dot<float>,
                                          dot<double>, clear_cache};

}  // namespace

extern "C" __attribute__((visibility("default"))) const clfractal::detail::BlasModule* clfractal_blas_module() {
    return &table;
}
