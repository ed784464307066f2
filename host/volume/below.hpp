// Whether a value lies below an isovalue s, compared as every count compares
// (docs/definitions.md §3, IsovalueSet::single(type, s)): integer data f < ceil(s), float data
// f < s in the data's type, each as one comparison in the data's own type (uint64 data against
// ceil(s) as an int64). Marching cubes' positive vertices are those at or above it.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "clfractal/isovalue_set.hpp"
#include "clfractal/volume.hpp"

namespace clfractal::detail {

template <class T> struct Below {
    using Ref = std::conditional_t<std::is_integral_v<T> && sizeof(T) == 8 && !std::is_signed_v<T>, std::int64_t, T>;
    Ref t;
    bool operator()(T x) const {
        if constexpr (std::is_same_v<Ref, T>) return x < t;
        else return std::int64_t(x) < t;
    }
    /// x >= s: false for NaN, as x < s is.
    bool at_or_above(T x) const {
        if constexpr (std::is_same_v<Ref, T>) return x >= t;
        else return std::int64_t(x) >= t;
    }
};

/// The comparison of isovalue s, or none when every value or none of the type is below s
/// (no grid edge is then crossed).
template <class T> std::optional<Below<T>> below(ValueType type, double s) {
    if constexpr (std::is_integral_v<T>) {
        const std::int64_t c = IsovalueSet::single(type, s).first();
        if constexpr (sizeof(T) < 8 || std::is_signed_v<T>) {
            if (c > std::int64_t(std::numeric_limits<T>::max()) || c <= std::int64_t(std::numeric_limits<T>::min()))
                return std::nullopt;
            return Below<T>{T(c)};
        } else {
            return Below<T>{c};
        }
    } else {
        // An s that rounds to +-Inf in float32 (from half an ulp above its largest value on):
        // every finite value is below +Inf, none below -Inf (the volumes hold finite values
        // only). Converting it would be undefined behaviour; float64 holds every finite s.
        if (std::is_same_v<T, float> && std::abs(s) >= 0x1.ffffffp127) return std::nullopt;
        return Below<T>{T(IsovalueSet::single(type, s).list().front())};
    }
}

}  // namespace clfractal::detail
