#include "device/program_cache.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace fs = std::filesystem;

namespace clfractal::detail {

namespace {

constexpr char magic[] = "clfractal program binary 1\n";

// FNV-1a, 64 bits, from a given basis: two bases name a file by 128 bits.
std::uint64_t fnv1a(const std::string& s, std::uint64_t h) {
    for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
    return h;
}

std::uint64_t checksum(const std::vector<unsigned char>& b) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned char c : b) h = (h ^ c) * 0x100000001b3ull;
    return h;
}

std::string hex(std::uint64_t x) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)x);
    return buf;
}

void put_u64(std::string& out, std::uint64_t x) {
    for (int i = 0; i < 8; ++i) out.push_back(char((x >> (8 * i)) & 0xff));
}

bool get_u64(const std::string& in, std::size_t& at, std::uint64_t& x) {
    if (in.size() < at + 8) return false;
    x = 0;
    for (int i = 0; i < 8; ++i) x |= std::uint64_t(static_cast<unsigned char>(in[at + std::size_t(i)])) << (8 * i);
    at += 8;
    return true;
}

}  // namespace

std::string program_cache_dir() {
    if (const char* e = std::getenv("CLFRACTAL_PROGRAM_CACHE"); e && *e)
        return std::strcmp(e, "off") == 0 ? "" : std::string(e);
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/clfractal";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/clfractal";
    return "";
}

std::string program_cache_key(const std::string& device_identity, const std::string& source,
                              const std::string& options) {
    return device_identity + "\noptions " + options + "\nsource " + hex(fnv1a(source, 0xcbf29ce484222325ull)) +
           hex(fnv1a(source, 0x84222325cbf29ce4ull)) + " " + std::to_string(source.size()) + "\n";
}

std::string program_cache_file(const std::string& dir, const std::string& key) {
    return dir + "/" + hex(fnv1a(key, 0xcbf29ce484222325ull)) + hex(fnv1a(key, 0x84222325cbf29ce4ull)) + ".bin";
}

std::optional<std::vector<unsigned char>> load_program_binary(const std::string& dir, const std::string& key) {
    if (dir.empty()) return std::nullopt;
    std::ifstream f(program_cache_file(dir, key), std::ios::binary);
    if (!f) return std::nullopt;
    const std::string in((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    // magic, key length, key, binary length, binary, checksum of the binary
    const std::size_t m = sizeof magic - 1;
    if (in.compare(0, m, magic) != 0) return std::nullopt;
    std::size_t at = m;
    std::uint64_t key_length = 0, length = 0, sum = 0;
    if (!get_u64(in, at, key_length) || in.size() - at < key_length || in.compare(at, key_length, key) != 0 ||
        key_length != key.size())
        return std::nullopt;
    at += key_length;
    if (!get_u64(in, at, length) || in.size() - at < length + 8 || length == 0) return std::nullopt;
    std::vector<unsigned char> binary(in.begin() + std::ptrdiff_t(at), in.begin() + std::ptrdiff_t(at + length));
    at += length;
    if (!get_u64(in, at, sum) || sum != checksum(binary) || at != in.size()) return std::nullopt;
    return binary;
}

void store_program_binary(const std::string& dir, const std::string& key, const std::vector<unsigned char>& binary) {
    if (dir.empty() || binary.empty()) return;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return;
    std::string out(magic);
    put_u64(out, key.size());
    out += key;
    put_u64(out, binary.size());
    out.append(binary.begin(), binary.end());
    put_u64(out, checksum(binary));
    const std::string file = program_cache_file(dir, key);
    const std::string temp = file + ".tmp." + std::to_string(::getpid());
    {
        std::ofstream f(temp, std::ios::binary | std::ios::trunc);
        if (!f) return;
        f.write(out.data(), std::streamsize(out.size()));
        if (!f.flush()) {
            f.close();
            fs::remove(temp, ec);
            return;
        }
    }
    fs::rename(temp, file, ec);
    if (ec) fs::remove(temp, ec);
}

}  // namespace clfractal::detail
