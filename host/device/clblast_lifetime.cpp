// The lifetime of CLBlast's process-wide caches of compiled programs (see device.hpp).
#include <clblast.h>

#include "clfractal/device.hpp"

namespace clfractal {

void release_blas_caches() { clblast::ClearCache(); }

}  // namespace clfractal
