// The one name <-> enum mechanism behind variant_name, parse_variant and all_variants
// (clfractal/device.hpp). Each enum has its table beside its code: a specialisation of
// NameTable and CLFRACTAL_NAME_TABLE(E) for the three functions. Private to the library.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/error.hpp"

namespace clfractal {
namespace detail {

/// The names of enum E, specialised once per enum:
///   static constexpr const char* what = "span variant";  // the subject of parse errors
///   static constexpr std::pair<E, const char*> names[] = {{E::a, "a"}, ...};
/// Every value in declaration order; a value may have further names (aliases) after its
/// first, which variant_name gives.
template <class E> struct NameTable;

}  // namespace detail

template <class E> const char* variant_name(E v) {
    for (const auto& [e, name] : detail::NameTable<E>::names)
        if (e == v) return name;
    throw std::logic_error(std::string("unknown ") + detail::NameTable<E>::what);
}

/// InputError "<what> '<name>': expected one of <every name>" for a name of no value.
template <class E> E parse_variant(const std::string& name) {
    std::string all;
    for (const auto& [e, n] : detail::NameTable<E>::names) {
        if (name == n) return e;
        all += std::string(all.empty() ? "" : ", ") + n;
    }
    throw InputError(std::string(detail::NameTable<E>::what) + " '" + name + "': expected one of " + all);
}

template <class E> std::vector<E> all_variants() {
    std::vector<E> out;
    for (const auto& entry : detail::NameTable<E>::names)
        if (out.empty() || out.back() != entry.first) out.push_back(entry.first);
    return out;
}

}  // namespace clfractal

/// The three functions of enum E, instantiated where its NameTable is (at namespace scope,
/// inside namespace clfractal).
#define CLFRACTAL_NAME_TABLE(E)                      \
    template const char* variant_name<E>(E);         \
    template E parse_variant<E>(const std::string&); \
    template std::vector<E> all_variants<E>();
