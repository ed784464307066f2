// The entries of the module clfractal_blas in the library (device/blas_module.hpp): loaded by
// the first use, looked for as every module is (device/module_loader.hpp). Without it, a fit
// of more than two levels or a correlation is a DeviceError naming why; nothing else needs it.
#include <atomic>

#include "clfractal/device.hpp"
#include "clfractal/error.hpp"
#include "device/blas_module.hpp"
#include "device/module_loader.hpp"

namespace clfractal {
namespace detail {
namespace {

struct Loaded {
    const BlasModule* module = nullptr;
    std::string why;  // what every attempt said, when none gave a module
};

// Set once blas() has loaded the module: release_blas_caches() has nothing to release before.
std::atomic<const BlasModule*> loaded_module{nullptr};

Loaded load() {
    Loaded out;
    out.module = load_module<BlasModule>(blas_module_file, "clfractal_blas_module", blas_module_abi,
                                         reinterpret_cast<const void*>(&load), out.why);
    loaded_module.store(out.module);
    return out;
}

}  // namespace

const BlasModule& blas() {
    static const Loaded loaded = load();
    if (!loaded.module) throw DeviceError("dense linear algebra (CLBlast) is missing: " + loaded.why, 0);
    return *loaded.module;
}

}  // namespace detail

void release_blas_caches() {
    if (const detail::BlasModule* m = detail::loaded_module.load()) m->clear_cache();
}

}  // namespace clfractal
