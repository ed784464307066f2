// RFC 4648 base64 (the standard alphabet, '=' padding, no line breaks): the report's images
// and mesh arrays inline as text.
#pragma once
#include <cstddef>
#include <string>

namespace cli::html {

/// `bytes` in base64: every 3 bytes become 4 characters, the last group padded with '='.
inline std::string base64(const std::string& bytes) {
    static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 3 <= bytes.size(); i += 3) {
        const unsigned n = unsigned(static_cast<unsigned char>(bytes[i])) << 16 |
                           unsigned(static_cast<unsigned char>(bytes[i + 1])) << 8 |
                           unsigned(static_cast<unsigned char>(bytes[i + 2]));
        out += {alphabet[n >> 18], alphabet[(n >> 12) & 63], alphabet[(n >> 6) & 63], alphabet[n & 63]};
    }
    if (const std::size_t rest = bytes.size() - i) {
        unsigned n = unsigned(static_cast<unsigned char>(bytes[i])) << 16;
        if (rest == 2) n |= unsigned(static_cast<unsigned char>(bytes[i + 1])) << 8;
        out += {alphabet[n >> 18], alphabet[(n >> 12) & 63], rest == 2 ? alphabet[(n >> 6) & 63] : '=', '='};
    }
    return out;
}

}  // namespace cli::html
