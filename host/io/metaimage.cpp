// MetaImage (.mha, .mhd + .raw/.zraw): a text header of "Key = Value" lines, then the data
// in the same file (ElementDataFile = LOCAL) or in one other file, raw or zlib-compressed.
// Debian ships MetaImage readers only inside ITK and VTK, so this small reader is bounded
// to what a 3D scalar image needs: a header of at most 64 KiB, one data file, one channel.
#include "io/formats.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/input_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal::io {
namespace {

constexpr std::size_t max_header_bytes = 64 * 1024;

struct Header {
    std::map<std::string, std::string> keys;
    std::size_t data_offset = 0;  // bytes from the start of the file, for LOCAL data
};

std::string trim(const std::string& s) {
    const std::size_t b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

Header read_header(const std::string& path) {
    regular_file_size(path, path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
    Header h;
    std::string line;
    while (h.data_offset < max_header_bytes && std::getline(in, line)) {
        h.data_offset += line.size() + 1;
        const std::size_t eq = line.find('=');
        if (eq == std::string::npos) {
            if (trim(line).empty()) continue;
            throw InputError(printable(path) + ": MetaImage header line without '=': " + quote_input(trim(line)));
        }
        const std::string key = trim(line.substr(0, eq));
        h.keys[key] = trim(line.substr(eq + 1));
        if (key == "ElementDataFile") return h;  // the data follows
    }
    throw InputError(path + ": MetaImage header has no ElementDataFile line" +
                     (h.data_offset >= max_header_bytes ? " in its first 64 KiB" : ""));
}

const std::string* find(const Header& h, const char* key) {
    const auto it = h.keys.find(key);
    return it == h.keys.end() ? nullptr : &it->second;
}

std::vector<double> numbers(const std::string& path, const std::string& key, const std::string& text, std::size_t n) {
    std::istringstream in(text);
    std::vector<double> v;
    double x;
    while (in >> x) v.push_back(x);
    if (v.size() != n || !in.eof())
        throw InputError(printable(path) + ": MetaImage " + key + " " + quote_input(text) + ": expected " +
                         std::to_string(n) + " numbers");
    return v;
}

bool truth(const Header& h, const char* key) {
    const std::string* v = find(h, key);
    return v && (*v == "True" || *v == "true" || *v == "TRUE" || *v == "1");
}

StoredKind element_kind(const std::string& path, const std::string& type) {
    static const std::pair<const char*, StoredKind> kinds[] = {
        {"MET_UCHAR", StoredKind::uint8},   {"MET_CHAR", StoredKind::int8},    {"MET_USHORT", StoredKind::uint16},
        {"MET_SHORT", StoredKind::int16},   {"MET_UINT", StoredKind::uint32},  {"MET_INT", StoredKind::int32},
        {"MET_FLOAT", StoredKind::float32}, {"MET_DOUBLE", StoredKind::float64}};
    for (const auto& [name, kind] : kinds)
        if (type == name) return kind;
    throw InputError(printable(path) + ": MetaImage ElementType " + quote_input(type) +
                     " is not a scalar type clfractal reads");
}

/// `count` bytes of `file` from `offset` on (the caller checked that they are there).
std::vector<unsigned char> read_bytes(const std::string& file, std::uint64_t offset, std::uint64_t count,
                                      const std::string& path) {
    std::vector<unsigned char> b(static_cast<std::size_t>(count));
    std::ifstream in(file, std::ios::binary);
    in.seekg(std::streamoff(offset));
    in.read(reinterpret_cast<char*>(b.data()), std::streamsize(b.size()));
    if (!in || std::size_t(in.gcount()) != b.size())
        throw InputError(printable(path) + ": cannot read " + quote_input(file, 200));
    return b;
}

/// A whole number of bytes in a header field (HeaderSize may also be -1).
long long byte_count(const std::string& path, const char* key, const std::string& text, long long least) {
    long long v = 0;
    const char* first = text.data();
    const auto [next, ec] = std::from_chars(first, first + text.size(), v);
    if (text.empty() || ec != std::errc() || next != first + text.size() || v < least || v > (1ll << 40))
        throw InputError(printable(path) + ": MetaImage " + key + " " + quote_input(text) + " is not a byte count");
    return v;
}

/// Inflates a zlib (or gzip) stream into exactly `expected` bytes.
std::vector<unsigned char> inflate_exact(const std::vector<unsigned char>& in, std::size_t expected, const std::string& path) {
    std::vector<unsigned char> out(expected);
    z_stream z{};
    if (inflateInit2(&z, 15 + 32) != Z_OK) throw InputError(path + ": cannot start zlib");
    std::size_t done_in = 0, done_out = 0;
    int rc = Z_OK;
    while (rc == Z_OK) {
        const std::size_t cin = std::min<std::size_t>(in.size() - done_in, 1u << 30);
        const std::size_t cout = std::min<std::size_t>(expected - done_out, 1u << 30);
        z.next_in = const_cast<unsigned char*>(in.data()) + done_in;
        z.avail_in = unsigned(cin);
        z.next_out = out.data() + done_out;
        z.avail_out = unsigned(cout);
        rc = inflate(&z, Z_NO_FLUSH);
        done_in += cin - z.avail_in;
        done_out += cout - z.avail_out;
        if (rc == Z_OK && z.avail_in == cin && z.avail_out == cout) break;  // no progress
        if (rc == Z_OK && done_out == expected) {
            // Full: the stream must end here.
            unsigned char extra;
            z.next_out = &extra;
            z.avail_out = 1;
            rc = inflate(&z, Z_NO_FLUSH);
            if (rc == Z_OK && z.avail_out == 0) rc = Z_DATA_ERROR;
        }
    }
    inflateEnd(&z);
    if (rc != Z_STREAM_END || done_out != expected)
        throw InputError(path + ": MetaImage compressed data " +
                         (rc == Z_STREAM_END || rc == Z_OK || rc == Z_BUF_ERROR
                              ? "holds " + std::string(done_out < expected ? "fewer" : "more") + " than the expected " +
                                    std::to_string(expected) + " bytes"
                              : std::string("corrupt: ") + (z.msg ? z.msg : "zlib error")));
    return out;
}

/// NDims, ObjectType and ElementNumberOfChannels: a 3D scalar image.
void check_image_kind(const Header& h, const std::string& path) {
    const std::string* ndims = find(h, "NDims");
    if (!ndims) throw InputError(path + ": MetaImage header has no NDims");
    if (*ndims != "3")
        throw InputError(printable(path) + ": MetaImage NDims = " + quote_input(*ndims) + "; only 3D volumes are supported");
    if (const std::string* ot = find(h, "ObjectType"); ot && *ot != "Image")
        throw InputError(printable(path) + ": MetaImage ObjectType " + quote_input(*ot) + " is not an Image");
    if (const std::string* ch = find(h, "ElementNumberOfChannels"); ch && *ch != "1")
        throw InputError(printable(path) + ": MetaImage has " + quote_input(*ch) +
                         " channels per element; only scalar data is supported");
}

/// DimSize (with ElementType present), checked against the volume limits.
Dims image_dims(const Header& h, const std::string& path) {
    const std::string* dim_text = find(h, "DimSize");
    const std::string* type_text = find(h, "ElementType");
    if (!dim_text || !type_text) throw InputError(path + ": MetaImage header lacks DimSize or ElementType");
    const std::vector<double> size = numbers(path, "DimSize", *dim_text, 3);
    for (double s : size)
        if (!(s >= 1) || s != std::floor(s) || s > 1e12)
            throw InputError(printable(path) + ": MetaImage DimSize " + quote_input(*dim_text) +
                             " must be positive integers");
    const Dims dims{std::size_t(size[0]), std::size_t(size[1]), std::size_t(size[2])};
    check_dims(dims, path);
    return dims;
}

/// The stored values (in host byte order) from ElementDataFile, after the header or in a
/// file of their own, raw or compressed.
std::vector<unsigned char> read_values(const Header& h, const std::string& path, const Dims& dims, StoredKind kind) {
    const std::uint64_t bytes = dims.vertices() * stored_kind_size(kind);
    const std::string layout = dims_string(dims) + " " + stored_kind_name(kind);

    const std::string& data_name = h.keys.at("ElementDataFile");
    if (data_name == "LIST" || data_name.find('%') != std::string::npos || data_name.find(' ') != std::string::npos ||
        data_name.size() > 400 || data_name.empty())
        throw InputError(printable(path) + ": MetaImage ElementDataFile " + quote_input(data_name) +
                         ": only LOCAL or one data file is supported");
    const bool local = data_name == "LOCAL";
    const std::string data_file = local ? path : (fs::path(path).parent_path() / data_name).string();
    const std::uint64_t file_size = regular_file_size(data_file, path);
    std::uint64_t offset = local ? h.data_offset : 0;
    const bool compressed = truth(h, "CompressedData");
    if (const std::string* hs = find(h, "HeaderSize"); hs && !compressed) {
        const long long skip = byte_count(path, "HeaderSize", *hs, -1);
        if (skip == -1) offset = file_size >= bytes ? file_size - bytes : 0;  // the data ends the file
        else offset += std::uint64_t(skip);
    }
    if (offset > file_size) throw InputError(printable(path) + ": MetaImage data truncated (no data after the header)");
    std::vector<unsigned char> raw;
    if (compressed) {
        std::uint64_t n = file_size - offset;
        if (const std::string* cs = find(h, "CompressedDataSize")) {
            const long long given = byte_count(path, "CompressedDataSize", *cs, 0);
            if (given > 0) n = std::min<std::uint64_t>(n, std::uint64_t(given));  // 0: not recorded
        }
        check_claim(path, "the compressed data", "the MetaImage data (" + layout + ")", bytes, n, ExpansionLimits::deflate);
        raw = inflate_exact(read_bytes(data_file, offset, n, path), bytes, path);
    } else {
        check_claim(path, "after the header", "the MetaImage data (" + layout + ")", bytes, file_size - offset, 1);
        raw = read_bytes(data_file, offset, bytes, path);
    }
    const bool msb = truth(h, "BinaryDataByteOrderMSB") || truth(h, "ElementByteOrderMSB");
    const std::size_t vs = stored_kind_size(kind);
    if (msb != (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__) && vs > 1)
        for (std::size_t i = 0; i < dims.vertices(); ++i) std::reverse(&raw[i * vs], &raw[i * vs] + vs);
    return raw;
}

/// Spacing, origin and axes from the header's geometry fields.
void read_geometry(const Header& h, const std::string& path, Volume& v) {
    const std::string* spacing = find(h, "ElementSpacing");
    if (!spacing) spacing = find(h, "ElementSize");
    if (spacing) {
        const std::vector<double> s = numbers(path, "ElementSpacing", *spacing, 3);
        for (int a = 0; a < 3; ++a) v.spacing[a] = std::isfinite(s[a]) && s[a] != 0 ? std::fabs(s[a]) : 1.0;
    }
    const std::string* origin = find(h, "Offset");
    if (!origin) origin = find(h, "Origin");
    if (!origin) origin = find(h, "Position");
    const std::string* matrix = find(h, "TransformMatrix");
    if (!matrix) matrix = find(h, "Rotation");
    if (!matrix) matrix = find(h, "Orientation");
    if (origin || matrix) {
        // ITK: LPS coordinates; row i of TransformMatrix is the direction of axis i.
        v.oriented = true;
        if (origin) {
            const std::vector<double> o = numbers(path, "Offset", *origin, 3);
            std::copy(o.begin(), o.end(), v.origin.begin());
        }
        if (matrix) {
            const std::vector<double> m = numbers(path, "TransformMatrix", *matrix, 9);
            for (int a = 0; a < 3; ++a)
                for (int r = 0; r < 3; ++r) v.axes[a][r] = m[std::size_t(3 * a + r)];
        }
    }
}

}  // namespace

Volume read_metaimage(const std::string& path) {
    const Header h = read_header(path);
    check_image_kind(h, path);
    const Dims dims = image_dims(h, path);
    const StoredKind kind = element_kind(path, *find(h, "ElementType"));
    const ValueType type = value_type_for(kind, path);
    const std::vector<unsigned char> raw = read_values(h, path, dims, kind);

    Volume v(dims, type, path);
    convert_values(raw.data(), kind, dims.vertices(), v.data(), type);
    read_geometry(h, path, v);
    return v;
}

}  // namespace clfractal::io
