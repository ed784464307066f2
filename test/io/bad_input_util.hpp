// Helpers of the bad-input suites (bad_input_test.cpp, bad_formats_test.cpp).
#pragma once
#include <doctest/doctest.h>
#include <zlib.h>

#include <string>

#include "clfractal/error.hpp"

namespace badinput {

/// `raw` deflated: gzip by default, zlib with window_bits 15.
inline std::string gzip(const std::string& raw, int window_bits = 15 + 16) {
    z_stream z{};
    REQUIRE(deflateInit2(&z, 9, Z_DEFLATED, window_bits, 8, Z_DEFAULT_STRATEGY) == Z_OK);
    std::string out(deflateBound(&z, raw.size()) + 32, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
    z.avail_in = uInt(raw.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

/// The message of the InputError `f` throws ("" if none).
template <class F> std::string refusal(F&& f) {
    try {
        f();
    } catch (const clfractal::InputError& e) {
        return e.what();
    }
    return "";
}

inline bool has_control(const std::string& s) {
    for (unsigned char c : s)
        if (c < 0x20 || c == 0x7f) return true;
    return false;
}

}  // namespace badinput
