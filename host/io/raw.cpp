// Raw volumes: NAME_XxYxZ_TYPE.raw names, --dims/--type/--endian options, and the one
// pread loop every reader of uncompressed data uses.
#include "clfractal/volume_io.hpp"

#include <fcntl.h>
#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "io/formats.hpp"

namespace fs = std::filesystem;

namespace clfractal {
namespace {

/// Only the canonical names appear in NAME_XxYxZ_TYPE.raw, so no aliases here.
std::optional<ValueType> canonical_value_type(std::string_view text) {
    for (ValueType t : all_value_types)
        if (text == value_type_name(t)) return t;
    return std::nullopt;
}

/// Splits NAME_XxYxZ_TYPE.raw into dims and the type's text, so that read_raw can
/// report an unknown type rather than a name that does not follow the convention.
bool split_raw_name(const std::string& path, Dims& dims, std::string& type_text) {
    const std::string file = fs::path(path).filename().string();
    const std::string ext = ".raw";
    if (file.size() <= ext.size() || file.compare(file.size() - ext.size(), ext.size(), ext) != 0)
        return false;
    const std::string stem = file.substr(0, file.size() - ext.size());
    const std::size_t type_sep = stem.rfind('_');
    if (type_sep == std::string::npos || type_sep == 0) return false;
    const std::size_t dims_sep = stem.rfind('_', type_sep - 1);
    if (dims_sep == std::string::npos || dims_sep == 0) return false;  // NAME must not be empty

    const char* p = stem.data() + dims_sep + 1;
    const char* end = stem.data() + type_sep;
    std::size_t* axes[3] = {&dims.nx, &dims.ny, &dims.nz};
    for (int a = 0; a < 3; ++a) {
        const auto [next, ec] = std::from_chars(p, end, *axes[a]);
        if (next == p) return false;
        // An absurd count still follows the convention: check_dims reports it.
        if (ec == std::errc::result_out_of_range) *axes[a] = SIZE_MAX;
        p = next;
        if (a < 2) {
            if (p == end || *p != 'x') return false;
            ++p;
        }
    }
    if (p != end) return false;
    type_text = stem.substr(type_sep + 1);
    return true;
}

template <class T> void byte_swap(T* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
        if constexpr (sizeof(T) == 2) {
            std::uint16_t u;
            std::memcpy(&u, &p[i], 2);
            u = __builtin_bswap16(u);
            std::memcpy(&p[i], &u, 2);
        } else if constexpr (sizeof(T) == 4) {
            std::uint32_t u;
            std::memcpy(&u, &p[i], 4);
            u = __builtin_bswap32(u);
            std::memcpy(&p[i], &u, 4);
        } else if constexpr (sizeof(T) == 8) {
            std::uint64_t u;
            std::memcpy(&u, &p[i], 8);
            u = __builtin_bswap64(u);
            std::memcpy(&p[i], &u, 8);
        }
    }
}

// Reads [offset, offset + bytes) of `fd` into `out`; "" or what went wrong.
std::string read_range(int fd, std::uint64_t offset, unsigned char* out, std::size_t bytes) {
    std::size_t done = 0;
    while (done < bytes) {
        const ssize_t got = ::pread(fd, out + done, std::min<std::size_t>(bytes - done, std::size_t(1) << 30),
                                    off_t(offset + done));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) return std::strerror(errno);
        if (got == 0) return "truncated";
        done += std::size_t(got);
    }
    return {};
}

}  // namespace

void io::read_file_data(const std::string& file, std::uint64_t offset, void* dst, std::size_t bytes,
                    const std::string& name) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(printable(name) + ": cannot open " + printable(file) + ": " + std::strerror(errno));
    auto* out = static_cast<unsigned char*>(dst);
    std::string problem;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && std::uint64_t(st.st_size) < offset + bytes)
        problem = "truncated: " + std::to_string(std::uint64_t(st.st_size) > offset ? std::uint64_t(st.st_size) - offset : 0) +
                  " of " + std::to_string(bytes) + " data bytes";
    const int parts = problem.empty() ? (bytes >= io::parallel_read_bytes ? std::max(1, omp_get_max_threads()) : 1) : 0;
    std::vector<std::string> problems(static_cast<std::size_t>(parts));
#pragma omp parallel for num_threads(std::max(parts, 1)) schedule(static, 1) if (parts > 1)
    for (int t = 0; t < parts; ++t) {
        const std::size_t a = bytes * std::size_t(t) / std::size_t(parts), b = bytes * std::size_t(t + 1) / std::size_t(parts);
        problems[std::size_t(t)] = read_range(fd, offset + a, out + a, b - a);
    }
    ::close(fd);
    for (const std::string& p : problems)
        if (problem.empty() && !p.empty()) problem = p == "truncated" ? "truncated while read" : p;
    if (!problem.empty()) throw InputError(printable(name) + ": cannot read the data: " + problem);
}

bool parse_raw_name(const std::string& path, Dims& dims, ValueType& type) {
    Dims d;
    std::string type_text;
    if (!split_raw_name(path, d, type_text)) return false;
    const std::optional<ValueType> t = canonical_value_type(type_text);
    if (!t) return false;
    dims = d;
    type = *t;
    return true;
}

Volume read_raw(const std::string& path, const RawOptions& opt) {
    std::optional<Dims> dims = opt.dims;
    std::optional<ValueType> type = opt.type;
    if (!dims || !type) {
        Dims name_dims;
        std::string type_text;
        if (!split_raw_name(path, name_dims, type_text))
            throw InputError(path +
                             ": raw file needs --dims and --type (or a NAME_XxYxZ_TYPE.raw name)");
        if (!dims) dims = name_dims;
        if (!type) {
            type = canonical_value_type(type_text);
            if (!type)
                throw InputError(path + ": unknown value type '" + type_text +
                                 "' in the file name (expected " + value_type_names() + ")");
        }
    }
    check_dims(*dims, path);

    const std::uintmax_t expected = dims->vertices() * value_size(*type);
    std::error_code ec;
    const std::uintmax_t found = fs::file_size(path, ec);
    if (ec) throw InputError(path + ": cannot read: " + ec.message());
    if (found != expected)
        throw InputError(path + (found < expected ? ": truncated" : ": too long") +
                         ": expected " + std::to_string(expected) + " bytes (" +
                         dims_string(*dims) + " " + value_type_name(*type) + "), found " +
                         std::to_string(found));

    Volume v(*dims, *type, path);
    v.spacing = opt.spacing;
    io::read_file_data(path, 0, v.data(), std::size_t(expected), path);

    if (opt.big_endian != io::host_big_endian)
        visit(v, [n = v.vertices()](auto* p) { byte_swap(p, n); });
    return v;
}

}  // namespace clfractal
