// The -D options and kernel arguments that carry a value type and an isovalue into the
// kernels (kernels/common.cl): one place for every kernel family.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// " -DT=<OpenCL type> -DT_IS_<OpenCL type>", plus " -DFP64" for float64 data.
inline std::string type_options(ValueType t) {
    const std::string cl = opencl_type_name(t);
    return defines({{"T", cl}}) + " -DT_IS_" + cl + (t == ValueType::float64 ? " -DFP64" : "");
}

/// type_options plus how one isovalue is compared (iso_t in kernels/common.cl): integer
/// data with ceil(s) (-DINTEGER_VALUES), float64 data in double (-DISO_DOUBLE).
inline std::string single_isovalue_options(ValueType t) {
    return type_options(t) + (is_integer(t) ? " -DINTEGER_VALUES" : t == ValueType::float64 ? " -DISO_DOUBLE" : "");
}

/// Integer data compares with ceil(s): for integers a, b and a real s, a < s <= b iff
/// a < ceil(s) <= b. Clamped to +-2^40, past every value of every integer type.
inline std::int64_t integer_isovalue(double s) {
    constexpr double limit = 1099511627776.0;
    return std::int64_t(std::clamp(std::ceil(s), -limit, limit));
}

/// Sets argument `index` of a kernel built with single_isovalue_options(t) to isovalue s
/// (an iso_t: long ceil(s), float(s) or s).
inline void set_isovalue_arg(cl::Kernel& k, cl_uint index, ValueType t, double s) {
    if (is_integer(t)) k.setArg(index, cl_long(integer_isovalue(s)));
    else if (t == ValueType::float64) k.setArg(index, cl_double(s));
    else k.setArg(index, cl_float(float(s)));
}

}  // namespace clfractal
