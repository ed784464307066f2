// The isovalues a curve is computed for, in the data's own type (docs/definitions.md §5
// "Isovalue set"): every integer of an integer range, or a strictly increasing list.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "clfractal/volume.hpp"

namespace clfractal {

/// The isovalues a curve is computed for (docs/definitions.md §5), in the data's own
/// type. Integer data: every integer in [first, first + count). Otherwise a strictly
/// increasing list: float32 values for float32 data, float64 values for float64 data and
/// for int32/uint32 data whose range holds more than 65,536 integers. Every comparison
/// a < s <= b is exact in that type (int32 and uint32 values convert to double exactly).
class IsovalueSet {
public:
    /// Largest number of integers an integer range keeps as every-integer isovalues by default.
    static constexpr std::int64_t max_default_integers = 65536;

    /// Every integer isovalue vmin..vmax (integer data).
    static IsovalueSet integers(std::int64_t vmin, std::int64_t vmax);
    /// A sorted float32 list (float32 data); throws InputError if empty, unsorted or not finite.
    static IsovalueSet floats(std::vector<float> values);
    /// A sorted float64 list (float64 data, wide int32/uint32 data); same checks.
    static IsovalueSet doubles(std::vector<double> values);
    /// K uniform values vmin + (j + 1)(vmax - vmin) / K, j = 0..K-1, computed in double and
    /// stored in the list type of data of type `type` (float32 for float32, else float64);
    /// duplicates after rounding are dropped.
    static IsovalueSet uniform(double vmin, double vmax, std::size_t k, ValueType type = ValueType::float32);
    /// The default set of data of type `type` with values in [vmin, vmax]: every integer
    /// when the type is an integer type and the range holds at most 65,536 integers, else
    /// `bins` uniform values.
    static IsovalueSet for_range(ValueType type, double vmin, double vmax, std::size_t bins = 256);
    /// for_range over the volume's value range.
    static IsovalueSet for_volume(const Volume& v, std::size_t bins = 256);
    /// The set of the one isovalue s for data of type `type`: integer data ceil(s) (which
    /// selects the same cubes and edges as s), float32 data float(s), float64 data s.
    static IsovalueSet single(ValueType type, double s);
    /// "A:B:STEP": A, A+STEP, ... <= B. 8/16-bit integer data takes integer A:B:1 only;
    /// int32/uint32 data takes integer A:B:1 as integers and any other range as a float64
    /// list; float data a list of its own type.
    static IsovalueSet parse_range(const std::string& spec, ValueType type);

    bool integer() const { return integer_; }
    /// True for a float64 list.
    bool float64() const { return !integer_ && float64_; }
    /// Whether this set counts data of type t (see the class comment).
    bool matches(ValueType t) const;
    std::size_t size() const { return integer_ ? std::size_t(count_) : values_.size(); }
    double value(std::size_t j) const { return integer_ ? double(first_ + std::int64_t(j)) : values_[j]; }
    std::int64_t first() const { return first_; }
    /// The list of a list set (float32 lists hold float32 values, exactly in double).
    const std::vector<double>& list() const { return values_; }
    /// Isovalue j as CSV and messages print it: integers as integers, float32 with 9 and
    /// float64 with 17 significant digits (round trip).
    std::string text(std::size_t j) const;

private:
    bool integer_ = true, float64_ = false;
    std::int64_t first_ = 0, count_ = 0;
    std::vector<double> values_;
};

}  // namespace clfractal
