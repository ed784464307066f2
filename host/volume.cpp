// Volume, value types and dimension checks (DESIGN §1 "Grid").
#include "clfractal/volume.hpp"

#include <algorithm>
#include <new>
#include <type_traits>
#include <utility>

namespace clfractal {

std::size_t value_size(ValueType t) {
    switch (t) {
    case ValueType::uint8: return 1;
    case ValueType::uint16:
    case ValueType::int16: return 2;
    case ValueType::float32: return 4;
    }
    throw std::logic_error("value_size: invalid ValueType");
}

const char* value_type_name(ValueType t) {
    switch (t) {
    case ValueType::uint8: return "uint8";
    case ValueType::uint16: return "uint16";
    case ValueType::int16: return "int16";
    case ValueType::float32: return "float32";
    }
    throw std::logic_error("value_type_name: invalid ValueType");
}

const char* opencl_type_name(ValueType t) {
    switch (t) {
    case ValueType::uint8: return "uchar";
    case ValueType::uint16: return "ushort";
    case ValueType::int16: return "short";
    case ValueType::float32: return "float";
    }
    throw std::logic_error("opencl_type_name: invalid ValueType");
}

ValueType parse_value_type(std::string_view name) {
    if (name == "uint8" || name == "uchar") return ValueType::uint8;
    if (name == "uint16" || name == "ushort") return ValueType::uint16;
    if (name == "int16" || name == "short") return ValueType::int16;
    if (name == "float32" || name == "float") return ValueType::float32;
    throw InputError("unknown value type '" + std::string(name) +
                     "' (expected uint8, uint16, int16 or float32)");
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

}  // namespace clfractal
