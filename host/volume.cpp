// Volume, value types and dimension checks (DESIGN §1 "Grid").
#include "clfractal/volume.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

namespace clfractal {

namespace {

struct TypeRow {
    const char* name;
    std::size_t size;
    const char* opencl;
    const char* nrrd;
    bool integer;
    double min, max;
};

// The rows of CLFRACTAL_VALUE_TYPES, indexed by the enumerator.
constexpr TypeRow type_rows[] = {
#define CLFRACTAL_ROW(e, c, cl, nrrd, integer) \
    {#e, sizeof(c), cl, nrrd, integer, double(std::numeric_limits<c>::lowest()), double(std::numeric_limits<c>::max())},
    CLFRACTAL_VALUE_TYPES(CLFRACTAL_ROW)
#undef CLFRACTAL_ROW
};

const TypeRow& row(ValueType t) {
    const auto i = std::size_t(t);
    if (i >= std::size(type_rows)) throw std::logic_error("invalid ValueType " + std::to_string(i));
    return type_rows[i];
}

}  // namespace

std::size_t value_size(ValueType t) { return row(t).size; }
const char* value_type_name(ValueType t) { return row(t).name; }
const char* opencl_type_name(ValueType t) { return row(t).opencl; }
const char* nrrd_type_name(ValueType t) { return row(t).nrrd; }
bool is_integer(ValueType t) { return row(t).integer; }
bool is_wide(ValueType t) { return t == ValueType::int32 || t == ValueType::uint32 || t == ValueType::float64; }
double type_min(ValueType t) { return row(t).min; }
double type_max(ValueType t) { return row(t).max; }

ValueType parse_value_type(std::string_view name) {
    for (ValueType t : all_value_types)
        if (name == value_type_name(t) || name == opencl_type_name(t)) return t;
    throw InputError("unknown value type '" + std::string(name) + "' (expected " + value_type_names() + ")");
}

std::string value_type_names() {
    std::string s;
    for (ValueType t : all_value_types) s += std::string(s.empty() ? "" : ", ") + value_type_name(t);
    return s;
}

std::size_t Dims::cubes() const {
    if (nx < 2 || ny < 2 || nz < 2) return 0;
    return (nx - 1) * (ny - 1) * (nz - 1);
}

std::string dims_string(const Dims& d) {
    return std::to_string(d.nx) + "x" + std::to_string(d.ny) + "x" + std::to_string(d.nz);
}

void check_dims(const Dims& d, const std::string& what) {
    if (d.nx < 1 || d.ny < 1 || d.nz < 1)
        throw InputError(what + ": dims " + dims_string(d) + " must be at least 1 on every axis");
    // Each factor is <= max_vertices, so dividing before multiplying never overflows.
    const bool too_large = d.nx > max_vertices || d.ny > max_vertices / d.nx ||
                           d.nz > max_vertices / (d.nx * d.ny);
    if (too_large)
        throw InputError(what + ": dims " + dims_string(d) + " exceed the maximum of 2^40 vertices");
}

Volume::Volume(Dims dims, ValueType type, std::string name_)
    : name(std::move(name_)), dims_(dims), type_(type) {
    const std::string what = name.empty() ? "volume" : name;
    check_dims(dims, what);
    const std::size_t bytes = dims.vertices() * value_size(type);
    try {
        bytes_.resize(bytes);
    } catch (const std::bad_alloc&) {
        throw HostOutOfMemory(what + ": cannot allocate " + std::to_string(bytes) + " bytes for " +
                         dims_string(dims) + " " + value_type_name(type));
    }
}

double Volume::value(std::size_t i) const {
    return visit(*this, [i](const auto* p) { return static_cast<double>(p[i]); });
}

ValueRange value_range(const Volume& v) {
    const std::size_t n = v.vertices();
    if (n == 0) return {};
    return visit(v, [n](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        T lo = p[0], hi = p[0];
#pragma omp parallel for reduction(min : lo) reduction(max : hi) schedule(static)
        for (std::size_t i = 0; i < n; ++i) {
            lo = std::min(lo, p[i]);
            hi = std::max(hi, p[i]);
        }
        return ValueRange{static_cast<double>(lo), static_cast<double>(hi)};
    });
}

std::size_t first_non_finite(const void* data, ValueType t, std::size_t n) {
    return visit_type(t, [&](auto zero) {
        using T = decltype(zero);
        if constexpr (std::is_integral_v<T>) {
            return n;
        } else {
            const T* p = static_cast<const T*>(data);
            return std::size_t(std::find_if(p, p + n, [](T f) { return !std::isfinite(f); }) - p);
        }
    });
}

void convert_values(const void* src, ValueType from, void* dst, ValueType to, std::size_t n) {
    visit_type(from, [&](auto from_zero) {
        visit_type(to, [&](auto to_zero) {
            using S = decltype(from_zero);
            using D = decltype(to_zero);
            const S* in = static_cast<const S*>(src);
            D* out = static_cast<D*>(dst);
            const double lo = double(std::numeric_limits<D>::lowest()), hi = double(std::numeric_limits<D>::max());
#pragma omp parallel for schedule(static)
            for (long long i = 0; i < (long long)n; ++i) {
                const S x = in[i];
                if constexpr (std::is_integral_v<D>) {
                    // Every value of every type is exact in double, except int64-sized ones we do not have.
                    out[i] = D(std::clamp(std::nearbyint(double(x)), lo, hi));
                } else {
                    out[i] = D(std::clamp(double(x), lo, hi));
                }
            }
        });
    });
}

Volume convert_volume(const Volume& v, ValueType to) {
    Volume out(v.dims(), to, v.name);
    out.spacing = v.spacing;
    convert_values(v.data(), v.type(), out.data(), to, v.vertices());
    return out;
}

}  // namespace clfractal
