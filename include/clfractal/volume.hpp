// Volumes: a 3D grid of nx*ny*nz vertices, x fastest, of one value type
// (docs/definitions.md §1 "Grid", §2 "Value types").
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "clfractal/error.hpp"

namespace clfractal {

/// The value types, one row each (docs/definitions.md §2 "Value types"):
///   X(enumerator, C++ type, OpenCL C type, NRRD type name, integer?)
/// Everything type-dependent (sizes, names, the kernels' -DT=..., teem's types, the C ABI's
/// clf_type, the ranges integer results saturate to) is derived from this table; adding a
/// type is one row here plus one enumerator in clfractal.h.
#define CLFRACTAL_VALUE_TYPES(X)                                  \
    X(uint8, std::uint8_t, "uchar", "unsigned char", true)        \
    X(uint16, std::uint16_t, "ushort", "unsigned short", true)    \
    X(int16, std::int16_t, "short", "short", true)                \
    X(float32, float, "float", "float", false)                    \
    X(int8, std::int8_t, "char", "signed char", true)             \
    X(int32, std::int32_t, "int", "int", true)                    \
    X(uint32, std::uint32_t, "uint", "unsigned int", true)        \
    X(float64, double, "double", "double", false)

/// Enumerators in table order (their values are those of the C ABI's clf_type).
enum class ValueType {
#define CLFRACTAL_ENUMERATOR(e, c, cl, nrrd, integer) e,
    CLFRACTAL_VALUE_TYPES(CLFRACTAL_ENUMERATOR)
#undef CLFRACTAL_ENUMERATOR
};

/// Every value type, in table order.
constexpr ValueType all_value_types[] = {
#define CLFRACTAL_LIST(e, c, cl, nrrd, integer) ValueType::e,
    CLFRACTAL_VALUE_TYPES(CLFRACTAL_LIST)
#undef CLFRACTAL_LIST
};

/// Bytes per value.
std::size_t value_size(ValueType t);
/// "uint8", "int32", "float64", ...: the names of NAME_XxYxZ_TYPE.raw files and messages.
const char* value_type_name(ValueType t);
/// The OpenCL C type of the values, for -DT=...: "uchar", "int", "double", ...
const char* opencl_type_name(ValueType t);
/// The NRRD "type:" name teem reads and writes ("signed char", "unsigned int", ...).
const char* nrrd_type_name(ValueType t);
/// Parses a type name (also the OpenCL names "uchar", "int", "float", ...); throws InputError.
ValueType parse_value_type(std::string_view name);
/// "uint8, uint16, ..., float64": the names, for messages.
std::string value_type_names();
/// True for the integer types.
bool is_integer(ValueType t);
/// True for the types whose values a float32 does not hold exactly (int32, uint32,
/// float64): their isovalue lists are float64 and their filters accumulate in double.
bool is_wide(ValueType t);
/// Smallest and largest value of an integer type (integer results saturate to them).
double type_min(ValueType t);
double type_max(ValueType t);

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

/// Host memory for the values of a volume: page-aligned, so that CPU OpenCL devices wrap
/// it in place (CL_MEM_USE_HOST_PTR). Blocks of 1 MiB and more are fresh anonymous
/// mappings with every page mapped at once, zero because the kernel hands out zero pages,
/// not because a pass fills them: a reader that overwrites every byte pays no zero-fill of
/// its own.
class HostBytes {
public:
    HostBytes() = default;
    /// n zero bytes; throws std::bad_alloc when the memory is not there.
    explicit HostBytes(std::size_t n);
    HostBytes(const HostBytes& o);
    HostBytes& operator=(const HostBytes& o);
    HostBytes(HostBytes&& o) noexcept;
    HostBytes& operator=(HostBytes&& o) noexcept;
    ~HostBytes();

    /// The n bytes at p, not owned (never freed; they must outlive every use). A copy owns
    /// a copy of them.
    static HostBytes borrow(void* p, std::size_t n);

    unsigned char* data() { return p_; }
    const unsigned char* data() const { return p_; }
    std::size_t size() const { return n_; }
    bool borrowed() const { return borrowed_; }

private:
    void release() noexcept;
    unsigned char* p_ = nullptr;  // the bytes
    std::size_t n_ = 0;
    std::size_t mapped_ = 0;      // bytes mapped at p_ (0: p_ came from aligned_alloc)
    bool borrowed_ = false;       // p_ belongs to the caller (borrow)
};

/// A host volume. Owns its values (native endianness), x fastest.
class Volume {
public:
    Volume() = default;
    /// Zero-filled volume (HostBytes: no pass writes the zeros); validates dims with check_dims.
    Volume(Dims dims, ValueType type, std::string name = {});
    /// A volume over the caller's values at `data` (x fastest, native endianness), read and
    /// written in place, not owned: they must outlive the volume (a NumPy array wrapped by
    /// the Python package). A copy of the volume owns a copy of the values.
    static Volume wrap(void* data, Dims dims, ValueType type, std::string name = {});
    /// Whether the values are the caller's (wrap).
    bool wrapped() const { return bytes_.borrowed(); }

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
    HostBytes bytes_;
};

struct ValueRange {
    double min = 0, max = 0;
};
/// Smallest and largest finite value (0, 0 when there is none).
ValueRange value_range(const Volume& v);

/// What one pass over the values finds: the smallest and largest finite value (0, 0 when
/// there is none) and the NaN and Inf counts (0 for integer types).
struct ValueStats {
    double min = 0, max = 0;
    std::size_t nan = 0, inf = 0;
};
/// The stats of n values of type t at `data`: one vectorised, multi-threaded pass.
ValueStats value_stats(const void* data, ValueType t, std::size_t n);
inline ValueStats value_stats(const Volume& v) { return value_stats(v.data(), v.type(), v.vertices()); }

/// `clfractal info`'s summary of the finite values: their stats, mean, population standard
/// deviation and a histogram of `bins` equal bins over [min, max] (bin
/// min(bins - 1, floor((x - min) / width)), all in bin 0 when min == max). 8- and 16-bit
/// data in one pass (a count per value, from which everything follows exactly), the rest
/// in two (value_stats, then sums and bins).
struct ValueSummary {
    ValueStats stats;
    std::size_t finite = 0;
    double mean = 0, sd = 0;
    std::vector<std::size_t> histogram;
};
ValueSummary summarize_values(const Volume& v, int bins = 16);

/// Index of the first NaN or Inf among the n values of type t at `data`; n when all are
/// finite (always for integer types).
std::size_t first_non_finite(const void* data, ValueType t, std::size_t n);

/// Converts n values of type `from` to type `to` (`--as TYPE`): integer targets round to
/// nearest (ties to even) and saturate to the type's range; float targets round to nearest
/// and saturate to +-max (no value becomes infinite). Exact whenever `to` holds the value.
void convert_values(const void* src, ValueType from, void* dst, ValueType to, std::size_t n);
/// The volume converted to `to` (a copy of name, dims and spacing).
Volume convert_volume(const Volume& v, ValueType to);

/// Maps a C++ type to its ValueType.
template <class T> struct value_type_of;
#define CLFRACTAL_TYPE_OF(e, c, cl, nrrd, integer) \
    template <> struct value_type_of<c> { static constexpr ValueType value = ValueType::e; };
CLFRACTAL_VALUE_TYPES(CLFRACTAL_TYPE_OF)
#undef CLFRACTAL_TYPE_OF

/// Calls f(T()) with a value of the C++ type of `t` (to dispatch on a type alone).
template <class F> decltype(auto) visit_type(ValueType t, F&& f);

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
template <class F> decltype(auto) visit_type(ValueType t, F&& f) {
    switch (t) {
#define CLFRACTAL_CASE(e, c, cl, nrrd, integer) \
    case ValueType::e: return f(c());
        CLFRACTAL_VALUE_TYPES(CLFRACTAL_CASE)
#undef CLFRACTAL_CASE
    }
    throw std::logic_error("visit_type: invalid ValueType");
}
template <class F> decltype(auto) visit(Volume& v, F&& f) {
    return visit_type(v.type(), [&](auto zero) -> decltype(auto) { return f(v.as<decltype(zero)>()); });
}
template <class F> decltype(auto) visit(const Volume& v, F&& f) {
    return visit_type(v.type(), [&](auto zero) -> decltype(auto) { return f(v.as<decltype(zero)>()); });
}

/// The NaN and infinite values of n values of type t (none for integer types), and the
/// index of the first (n when none).
struct NonFinite {
    std::size_t nan = 0, inf = 0, first = 0;
};
NonFinite count_non_finite(const void* data, ValueType t, std::size_t n);

/// The one check for non-finite input (docs/definitions.md §1 "Grid"), used by whole volumes,
/// SliceReader and the stream API: throws InputError if the n values of type t (vertices
/// offset.. of a grid of `d`) hold NaN or Inf, naming `what` (the file, or the API), how many
/// of each, the slices scanned when they are not the whole grid, and the first one's value and
/// vertex.
void check_finite(const void* data, ValueType t, std::size_t n, const Dims& d, std::size_t offset,
                  const std::string& what);

/// check_finite over the whole volume.
void check_finite(const Volume& v, const std::string& what);

}  // namespace clfractal
