// Helpers shared by the test suites.
#pragma once
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"

namespace testutil {

inline clfractal::Context& ctx() { return clfractal::Context::shared(); }

/// A volume of uniform random integers in [lo, hi] (float data: integers / 2, so that
/// ties and exact isovalue hits are common), from a fixed seed.
inline clfractal::Volume random_volume(clfractal::Dims d, clfractal::ValueType t, long lo, long hi,
                                       std::uint32_t seed) {
    clfractal::Volume v(d, t);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<long> dist(lo, hi);
    clfractal::visit(v, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t i = 0; i < v.vertices(); ++i) {
            long x = dist(rng);
            p[i] = std::is_floating_point<T>::value ? T(double(x) / 2) : T(x);
        }
    });
    return v;
}

/// Restores the shared context's tuning when it goes out of scope.
struct TuningGuard {
    clfractal::Tuning saved = ctx().tuning;
    ~TuningGuard() { ctx().tuning = saved; }
};

/// The directory of real benchmark volumes, or "" when absent.
inline std::string shared_data() {
#ifdef CLFRACTAL_SHARED_DATA
    if (std::filesystem::exists(std::string(CLFRACTAL_SHARED_DATA) + "/MANIFEST.tsv")) return CLFRACTAL_SHARED_DATA;
#endif
    return "";
}

}  // namespace testutil
