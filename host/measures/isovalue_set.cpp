// Isovalue sets: integer ranges, uniform and explicit lists, A:B:STEP ranges.
#include "clfractal/isovalue_set.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "clfractal/error.hpp"
#include "device/type_options.hpp"

namespace clfractal {

namespace {

// Largest list or integer range a set may hold (the histograms have size() + 1 bins).
constexpr std::size_t max_isovalues = std::size_t(1) << 24;

// Drops values that rounding made equal to their predecessor.
template <class F> std::vector<F> increasing(std::vector<F> v) {
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return v;
}

// The list type of data of type t: float64 unless the data is float32.
bool float64_list(ValueType t) { return t != ValueType::float32; }

}  // namespace

IsovalueSet IsovalueSet::integers(std::int64_t vmin, std::int64_t vmax) {
    if (vmax < vmin) throw InputError("isovalues: empty integer range");
    if (std::uint64_t(vmax - vmin) >= max_isovalues)
        throw InputError("isovalues: the integer range " + std::to_string(vmin) + ".." + std::to_string(vmax) +
                         " holds more than 2^24 integers");
    IsovalueSet s;
    s.integer_ = true;
    s.first_ = vmin;
    s.count_ = vmax - vmin + 1;
    return s;
}

IsovalueSet IsovalueSet::doubles(std::vector<double> values) {
    if (values.empty()) throw InputError("isovalues: the list is empty");
    if (values.size() > max_isovalues) throw InputError("isovalues: more than 2^24 isovalues");
    for (std::size_t j = 0; j < values.size(); ++j) {
        if (!std::isfinite(values[j])) throw InputError("isovalues: value " + std::to_string(j) + " is not finite");
        if (j && !(values[j - 1] < values[j]))
            throw InputError("isovalues: the list must be strictly increasing (at index " + std::to_string(j) + ")");
    }
    IsovalueSet s;
    s.integer_ = false;
    s.float64_ = true;
    s.values_ = std::move(values);
    return s;
}

IsovalueSet IsovalueSet::floats(std::vector<float> values) {
    for (std::size_t j = 0; j < values.size(); ++j)
        if (!std::isfinite(values[j])) throw InputError("isovalues: value " + std::to_string(j) + " is not finite");
    IsovalueSet s = doubles(std::vector<double>(values.begin(), values.end()));
    s.float64_ = false;
    return s;
}

IsovalueSet IsovalueSet::uniform(double vmin, double vmax, std::size_t k, ValueType type) {
    if (k == 0) throw InputError("isovalues: --bins must be at least 1");
    if (k > max_isovalues) throw InputError("isovalues: --bins is larger than 2^24");
    std::vector<double> v(k);
    for (std::size_t j = 0; j < k; ++j) v[j] = vmin + double(j + 1) * (vmax - vmin) / double(k);
    if (float64_list(type)) return doubles(increasing(std::move(v)));
    return floats(increasing(std::vector<float>(v.begin(), v.end())));
}

IsovalueSet IsovalueSet::for_range(ValueType type, double vmin, double vmax, std::size_t bins) {
    if (is_integer(type) && vmax - vmin < double(max_default_integers))
        return integers(std::int64_t(vmin), std::int64_t(vmax));
    return uniform(vmin, vmax, bins, type);
}

IsovalueSet IsovalueSet::for_volume(const Volume& v, std::size_t bins) {
    const ValueRange r = value_range(v);
    return for_range(v.type(), r.min, r.max, bins);
}

IsovalueSet IsovalueSet::single(ValueType type, double s) {
    if (!std::isfinite(s)) throw InputError("isovalue must be a finite number");
    if (is_integer(type)) {
        const std::int64_t c = integer_isovalue(s);
        return integers(c, c);
    }
    if (type == ValueType::float64) return doubles({s});
    return floats({float(s)});
}

IsovalueSet IsovalueSet::parse_range(const std::string& spec, ValueType type) {
    double a, b, step;
    char c1, c2;
    std::istringstream in(spec);
    if (!(in >> a >> c1 >> b >> c2 >> step) || c1 != ':' || c2 != ':' || !(in >> std::ws).eof())
        throw InputError("--isovalues '" + spec + "': expected A:B:STEP");
    if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(step) || step <= 0 || b < a)
        throw InputError("--isovalues '" + spec + "': need A <= B and STEP > 0");
    double n = std::floor((b - a) / step * (1 + 1e-12)) + 1;
    if (n > double(max_isovalues)) throw InputError("--isovalues '" + spec + "': more than 2^24 isovalues");
    const bool integer_range = a == std::floor(a) && b == std::floor(b) && step == 1;
    if (is_integer(type) && (integer_range || !is_wide(type))) {
        if (!integer_range)
            throw InputError("--isovalues '" + spec + "': " + value_type_name(type) + " data takes integer A:B:1");
        if (std::fabs(a) > 1e15 || std::fabs(b) > 1e15)
            throw InputError("--isovalues '" + spec + "': integers beyond +-1e15");
        return integers(std::int64_t(a), std::int64_t(b));
    }
    std::vector<double> v(static_cast<std::size_t>(n));
    for (std::size_t j = 0; j < v.size(); ++j) v[j] = a + double(j) * step;
    if (float64_list(type)) return doubles(increasing(std::move(v)));
    return floats(increasing(std::vector<float>(v.begin(), v.end())));
}

bool IsovalueSet::matches(ValueType t) const {
    if (integer_) return is_integer(t);
    return float64_ ? is_wide(t) : t == ValueType::float32;
}

std::string IsovalueSet::text(std::size_t j) const {
    if (integer_) return std::to_string(first_ + std::int64_t(j));
    char buf[40];
    std::snprintf(buf, sizeof buf, float64_ ? "%.17g" : "%.9g", values_[j]);
    return buf;
}

}  // namespace clfractal
