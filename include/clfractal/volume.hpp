// Volumes: a 3D grid of nx*ny*nz vertices, x fastest, of one value type.
// (DESIGN §1 "Grid".)
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "clfractal/error.hpp"

namespace clfractal {

enum class ValueType { uint8, uint16, int16, float32 };

/// Bytes per value.
std::size_t value_size(ValueType t);
/// "uint8", "uint16", "int16", "float32".
const char* value_type_name(ValueType t);
/// The OpenCL C type of the values, for -DT=...: "uchar", "ushort", "short", "float".
const char* opencl_type_name(ValueType t);
/// Parses a type name (also accepts "uchar", "ushort", "short", "float"); throws InputError.
ValueType parse_value_type(std::string_view name);
/// True for the integer types, whose isovalue set is every integer in the value range.
inline bool is_integer(ValueType t) { return t != ValueType::float32; }

struct Dims {
    std::size_t nx = 0, ny = 0, nz = 0;
    std::size_t vertices() const { return nx * ny * nz; }
    /// (nx-1)(ny-1)(nz-1), 0 when any axis has fewer than 2 vertices.
    std::size_t cubes() const;
    bool operator==(const Dims& o) const { return nx == o.nx && ny == o.ny && nz == o.nz; }
    bool operator!=(const Dims& o) const { return !(*this == o); }
};

/// "XxYxZ", as in file names and messages.
std::string dims_string(const Dims& d);

/// Largest accepted vertex count per volume (2^40): anything larger is treated as a
/// malformed header rather than an allocation attempt.
constexpr std::size_t max_vertices = std::size_t(1) << 40;

/// Checks that every axis is >= 1 and the vertex count neither overflows nor exceeds
/// max_vertices; throws InputError naming `what` otherwise.
void check_dims(const Dims& d, const std::string& what);

/// A host volume. Owns its values (native endianness), x fastest.
class Volume {
public:
    Volume() = default;
    /// Zero-filled volume; validates dims with check_dims.
    Volume(Dims dims, ValueType type, std::string name = {});

    const Dims& dims() const { return dims_; }
    ValueType type() const { return type_; }
    std::size_t vertices() const { return dims_.vertices(); }
    std::size_t size_bytes() const { return bytes_.size(); }
    void* data() { return bytes_.data(); }
    const void* data() const { return bytes_.data(); }

    /// Typed access; throws std::logic_error if T does not match type().
    template <class T> T* as();
    template <class T> const T* as() const;

    /// Value at linear index i, converted to double.
    double value(std::size_t i) const;
    std::size_t index(std::size_t x, std::size_t y, std::size_t z) const {
        return x + dims_.nx * (y + dims_.ny * z);
    }

    /// Where the volume came from (a path or "synthetic:NAME:N"), used in messages.
    std::string name;
    /// Vertex spacing (1,1,1 unless a header says otherwise).
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    /// Where the file places the grid, when it says (DICOM, NIfTI, MetaImage, NRRD with a
    /// space): patient coordinates in LPS (DICOM's), the position of vertex (0,0,0) and the
    /// unit direction of each axis. Written back by the NIfTI and NRRD writers.
    bool oriented = false;
    std::array<double, 3> origin{0.0, 0.0, 0.0};
    std::array<std::array<double, 3>, 3> axes{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};

private:
    Dims dims_{};
    ValueType type_ = ValueType::uint8;
    std::vector<unsigned char> bytes_;
};

struct ValueRange {
    double min = 0, max = 0;
};
/// Smallest and largest value (for float data NaN must not be present).
ValueRange value_range(const Volume& v);

/// Maps a C++ type to its ValueType.
template <class T> struct value_type_of;
template <> struct value_type_of<std::uint8_t> { static constexpr ValueType value = ValueType::uint8; };
template <> struct value_type_of<std::uint16_t> { static constexpr ValueType value = ValueType::uint16; };
template <> struct value_type_of<std::int16_t> { static constexpr ValueType value = ValueType::int16; };
template <> struct value_type_of<float> { static constexpr ValueType value = ValueType::float32; };

/// Calls f(T*) / f(const T*) with the volume's typed data.
template <class F> decltype(auto) visit(Volume& v, F&& f);
template <class F> decltype(auto) visit(const Volume& v, F&& f);

// ---- implementation of the templates ----
template <class T> T* Volume::as() {
    if (value_type_of<T>::value != type_) throw std::logic_error("Volume::as: type mismatch");
    return reinterpret_cast<T*>(bytes_.data());
}
template <class T> const T* Volume::as() const {
    if (value_type_of<T>::value != type_) throw std::logic_error("Volume::as: type mismatch");
    return reinterpret_cast<const T*>(bytes_.data());
}
template <class F> decltype(auto) visit(Volume& v, F&& f) {
    switch (v.type()) {
    case ValueType::uint8: return f(v.as<std::uint8_t>());
    case ValueType::uint16: return f(v.as<std::uint16_t>());
    case ValueType::int16: return f(v.as<std::int16_t>());
    default: return f(v.as<float>());
    }
}
template <class F> decltype(auto) visit(const Volume& v, F&& f) {
    switch (v.type()) {
    case ValueType::uint8: return f(v.as<std::uint8_t>());
    case ValueType::uint16: return f(v.as<std::uint16_t>());
    case ValueType::int16: return f(v.as<std::int16_t>());
    default: return f(v.as<float>());
    }
}

}  // namespace clfractal
