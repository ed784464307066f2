// The finiteness check of float data (NaN and infinite values) every reader and upload
// applies, with the first bad vertex in its message.
#include "clfractal/volume.hpp"

#include <cmath>
#include <string>

namespace clfractal {

NonFinite count_non_finite(const void* data, ValueType t, std::size_t n) {
    NonFinite r{0, 0, n};
    if (is_integer(t)) return r;
    // The vectorised pass for the common all-finite case; the first bad index is only
    // searched for when there is one.
    const ValueStats s = value_stats(data, t, n);
    r.nan = s.nan;
    r.inf = s.inf;
    if (s.nan + s.inf) r.first = first_non_finite(data, t, n);
    return r;
}

void check_finite(const void* data, ValueType t, std::size_t n, const Dims& d, std::size_t offset,
                  const std::string& what) {
    const NonFinite nf = count_non_finite(data, t, n);
    if (nf.nan + nf.inf == 0) return;
    std::string counts;
    if (nf.nan) counts = std::to_string(nf.nan) + " NaN";
    if (nf.inf) counts += (counts.empty() ? "" : " and ") + std::to_string(nf.inf) + " infinite";
    counts += nf.nan + nf.inf > 1 ? " values" : " value";
    const std::size_t plane = d.nx * d.ny, z0 = offset / plane, z1 = (offset + n - 1) / plane;
    if (offset != 0 || n != d.vertices())
        counts += z0 == z1 ? " in slice " + std::to_string(z0) : " in slices " + std::to_string(z0) + ".." + std::to_string(z1);
    const double f = visit_type(t, [&](auto zero) { return double(static_cast<const decltype(zero)*>(data)[nf.first]); });
    const std::size_t i = offset + nf.first;
    throw InputError(what + ": float data contains " + counts + " (the first, " +
                     (std::isnan(f) ? "NaN" : f > 0 ? "Inf" : "-Inf") + ", at vertex (" + std::to_string(i % d.nx) + "," +
                     std::to_string(i / d.nx % d.ny) + "," + std::to_string(i / plane) +
                     ")); counting, filtering and meshing need finite values");
}

void check_finite(const Volume& v, const std::string& what) {
    check_finite(v.data(), v.type(), v.vertices(), v.dims(), 0, what);
}

}  // namespace clfractal
