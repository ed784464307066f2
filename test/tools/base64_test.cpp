// The report's base64 encoder against the test vectors of RFC 4648 §10, and every byte
// value (decoded back by a plain table-free decoder).
#include <doctest/doctest.h>

#include <string>

#include "base64.hpp"

namespace {

/// The value of one base64 character (the RFC's table written as ranges).
int sextet(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
}

std::string decoded(const std::string& text) {
    std::string out;
    unsigned bits = 0;
    int held = 0;
    for (char c : text) {
        if (c == '=') break;
        bits = bits << 6 | unsigned(sextet(c));
        held += 6;
        if (held >= 8) {
            held -= 8;
            out += char((bits >> held) & 0xff);
        }
    }
    return out;
}

}  // namespace

TEST_SUITE("base64") {

TEST_CASE("RFC 4648 section 10 test vectors") {
    CHECK(cli::html::base64("") == "");
    CHECK(cli::html::base64("f") == "Zg==");
    CHECK(cli::html::base64("fo") == "Zm8=");
    CHECK(cli::html::base64("foo") == "Zm9v");
    CHECK(cli::html::base64("foob") == "Zm9vYg==");
    CHECK(cli::html::base64("fooba") == "Zm9vYmE=");
    CHECK(cli::html::base64("foobar") == "Zm9vYmFy");
}

TEST_CASE("every byte value, at every position of a group, decodes back") {
    std::string bytes;
    for (int i = 0; i < 256; ++i) bytes += char(i);
    for (std::size_t cut = 0; cut < 3; ++cut) {
        const std::string in = bytes.substr(cut), text = cli::html::base64(in);
        CHECK(text.size() == (in.size() + 2) / 3 * 4);
        CHECK(text.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/=") ==
              std::string::npos);
        CHECK(decoded(text) == in);
    }
    CHECK(cli::html::base64(std::string("\xff\xfe\xfd", 3)) == "//79");
    CHECK(cli::html::base64(std::string(1, '\0')) == "AA==");
}

}
