// The -D options and kernel arguments that carry a value type and an isovalue into the
// kernels (kernels/common.cl): one place for every kernel family.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"
#include "device/kernel_call.hpp"

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

/// A scalar kernel argument whose OpenCL type is chosen at run time (a -D type such as
/// iso_t or BIN_T): long, double or float, set with its own size by KernelCall.
struct ScalarArg {
    union {
        cl_long integer;
        cl_double wide;
        cl_float single;
    } value;
    std::size_t bytes = 0;

    static ScalarArg of(cl_long x) {
        ScalarArg a{};
        a.value.integer = x;
        a.bytes = sizeof x;
        return a;
    }
    static ScalarArg of(cl_double x) {
        ScalarArg a{};
        a.value.wide = x;
        a.bytes = sizeof x;
        return a;
    }
    static ScalarArg of(cl_float x) {
        ScalarArg a{};
        a.value.single = x;
        a.bytes = sizeof x;
        return a;
    }
};

inline void set_kernel_arg(cl::Kernel& k, cl_uint index, const ScalarArg& a) { k.setArg(index, a.bytes, &a.value); }

/// One isovalue as the kernels of single_isovalue_options(t) take it (iso_t): long ceil(s)
/// for integer data, double s for float64 data, float(s) for float32 data.
inline ScalarArg isovalue_arg(ValueType t, double s) {
    if (is_integer(t)) return ScalarArg::of(cl_long(integer_isovalue(s)));
    if (t == ValueType::float64) return ScalarArg::of(cl_double(s));
    return ScalarArg::of(cl_float(float(s)));
}

}  // namespace clfractal
