// What the format readers share: stored types, the rescale rule, detection by content.
#include "io/formats.hpp"
#include "io/input_guard.hpp"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace fs = std::filesystem;

namespace clfractal::io {

const char* stored_kind_name(StoredKind kind) {
    switch (kind) {
    case StoredKind::uint8: return "uint8";
    case StoredKind::int8: return "int8";
    case StoredKind::uint16: return "uint16";
    case StoredKind::int16: return "int16";
    case StoredKind::uint32: return "uint32";
    case StoredKind::int32: return "int32";
    case StoredKind::float32: return "float32";
    case StoredKind::float64: return "float64";
    }
    return "?";
}

std::size_t stored_kind_size(StoredKind kind) {
    switch (kind) {
    case StoredKind::uint8:
    case StoredKind::int8: return 1;
    case StoredKind::uint16:
    case StoredKind::int16: return 2;
    case StoredKind::uint32:
    case StoredKind::int32:
    case StoredKind::float32: return 4;
    case StoredKind::float64: return 8;
    }
    return 0;
}

ValueType value_type_for(StoredKind kind, const std::string& file) {
    // Every stored kind is one of the library's value types.
    switch (kind) {
    case StoredKind::uint8: return ValueType::uint8;
    case StoredKind::int8: return ValueType::int8;
    case StoredKind::uint16: return ValueType::uint16;
    case StoredKind::int16: return ValueType::int16;
    case StoredKind::uint32: return ValueType::uint32;
    case StoredKind::int32: return ValueType::int32;
    case StoredKind::float32: return ValueType::float32;
    case StoredKind::float64: return ValueType::float64;
    }
    throw InputError(file + ": " + stored_kind_name(kind) + " values are not supported");
}

namespace {

template <class F> decltype(auto) visit_stored(const void* p, StoredKind kind, F&& f) {
    switch (kind) {
    case StoredKind::uint8: return f(static_cast<const std::uint8_t*>(p));
    case StoredKind::int8: return f(static_cast<const std::int8_t*>(p));
    case StoredKind::uint16: return f(static_cast<const std::uint16_t*>(p));
    case StoredKind::int16: return f(static_cast<const std::int16_t*>(p));
    case StoredKind::uint32: return f(static_cast<const std::uint32_t*>(p));
    case StoredKind::int32: return f(static_cast<const std::int32_t*>(p));
    case StoredKind::float32: return f(static_cast<const float*>(p));
    default: return f(static_cast<const double*>(p));
    }
}

/// f(T*) with the destination values of type t.
template <class F> void visit_type(void* p, ValueType t, F&& f) {
    clfractal::visit_type(t, [&](auto zero) { f(static_cast<decltype(zero)*>(p)); });
}

struct IntegerRange {
    StoredKind kind;
    double lo, hi;
};
constexpr IntegerRange integer_ranges[] = {
    {StoredKind::uint8, 0, 255},           {StoredKind::int8, -128, 127},
    {StoredKind::uint16, 0, 65535},        {StoredKind::int16, -32768, 32767},
    {StoredKind::uint32, 0, 4294967295.0}, {StoredKind::int32, -2147483648.0, 2147483647.0},
};

bool holds(StoredKind kind, double lo, double hi) {
    for (const IntegerRange& r : integer_ranges)
        if (r.kind == kind) return r.lo <= lo && hi <= r.hi;
    return true;  // float types hold every value of an integral map of integer data
}

}  // namespace

void convert_values(const void* src, StoredKind kind, std::size_t n, void* dst, ValueType type) {
    visit_stored(src, kind, [&](const auto* in) {
        visit_type(dst, type, [&](auto* out) {
            using T = std::remove_pointer_t<decltype(out)>;
            for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<T>(in[i]);
        });
    });
}

bool Rescale::integral() const { return slope == 1.0 && std::isfinite(intercept) && intercept == std::floor(intercept); }

ValueType rescale_type(StoredKind kind, const std::vector<Rescale>& maps, double lo, double hi,
                       const std::string& file) {
    const bool integral = std::all_of(maps.begin(), maps.end(), [](const Rescale& m) { return m.integral(); });
    const bool integer_data = kind != StoredKind::float32 && kind != StoredKind::float64;
    if (!integral || !integer_data) {
        // Float results; float32 data with the identity map keeps its own type.
        const bool identity = std::all_of(maps.begin(), maps.end(), [](const Rescale& m) { return m.identity(); });
        return identity ? value_type_for(kind, file) : ValueType::float32;
    }
    double rlo = lo, rhi = hi;
    if (!maps.empty()) {
        rlo = std::numeric_limits<double>::infinity();
        rhi = -rlo;
        for (const Rescale& m : maps) {
            rlo = std::min(rlo, lo + m.intercept);
            rhi = std::max(rhi, hi + m.intercept);
        }
    }
    if (holds(kind, rlo, rhi)) return value_type_for(kind, file);
    for (StoredKind s : {StoredKind::int8, StoredKind::int16, StoredKind::int32})
        if (holds(s, rlo, rhi)) return value_type_for(s, file);
    throw InputError(file + ": rescaled values " + std::to_string(rlo) + " .. " + std::to_string(rhi) +
                     " do not fit a 32-bit integer");
}

void rescale_values(const void* src, StoredKind kind, std::size_t n, const Rescale& map, void* dst,
                    ValueType type) {
    visit_stored(src, kind, [&](const auto* in) {
        visit_type(dst, type, [&](auto* out) {
            using T = std::remove_pointer_t<decltype(out)>;
            if (map.integral() && !std::is_floating_point<T>::value) {
                const long long b = static_cast<long long>(map.intercept);
                for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<T>(static_cast<long long>(in[i]) + b);
            } else {
                for (std::size_t i = 0; i < n; ++i)
                    out[i] = static_cast<T>(double(in[i]) * map.slope + map.intercept);
            }
        });
    });
}

void stored_range(const void* src, StoredKind kind, std::size_t n, double& lo, double& hi) {
    visit_stored(src, kind, [&](const auto* in) {
        for (std::size_t i = 0; i < n; ++i) {
            const double x = double(in[i]);
            lo = std::min(lo, x);
            hi = std::max(hi, x);
        }
    });
}

bool natural_less(const std::string& a, const std::string& b) {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        const bool da = std::isdigit(static_cast<unsigned char>(a[i])), db = std::isdigit(static_cast<unsigned char>(b[j]));
        if (da && db) {
            std::size_t ie = i, je = j;
            while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
            while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
            // Compare digit runs by value: strip leading zeros, then by length, then text.
            std::size_t ia = i, jb = j;
            while (ia + 1 < ie && a[ia] == '0') ++ia;
            while (jb + 1 < je && b[jb] == '0') ++jb;
            if (ie - ia != je - jb) return ie - ia < je - jb;
            const int c = a.compare(ia, ie - ia, b, jb, je - jb);
            if (c != 0) return c < 0;
            i = ie;
            j = je;
        } else {
            if (a[i] != b[j]) return a[i] < b[j];
            ++i;
            ++j;
        }
    }
    if ((a.size() - i) != (b.size() - j)) return a.size() - i < b.size() - j;
    return a < b;
}

namespace {

std::string lower_extension(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool tiff_magic(const unsigned char* b, std::size_t n) {
    return n >= 4 && ((b[0] == 'I' && b[1] == 'I' && (b[2] == 42 || b[2] == 43) && b[3] == 0) ||
                      (b[0] == 'M' && b[1] == 'M' && b[2] == 0 && (b[3] == 42 || b[3] == 43)));
}

std::int32_t int32_at(const unsigned char* b, bool swap) {
    std::uint32_t u;
    std::memcpy(&u, b, 4);
    if (swap) u = __builtin_bswap32(u);
    return std::int32_t(u);
}

/// A NIfTI-1 (sizeof_hdr 348, magic "n+1"/"ni1" at 344) or NIfTI-2 (540, "n+2"/"ni2" at 4)
/// header, in either byte order.
bool nifti_magic(const unsigned char* b, std::size_t n) {
    if (n < 348) return false;
    for (bool swap : {false, true}) {
        const std::int32_t size = int32_at(b, swap);
        if (size == 348 && (std::memcmp(b + 344, "n+1", 4) == 0 || std::memcmp(b + 344, "ni1", 4) == 0)) return true;
        if (size == 540 && (std::memcmp(b + 4, "n+2", 4) == 0 || std::memcmp(b + 4, "ni2", 4) == 0)) return true;
    }
    return false;
}

/// MetaImage headers are "Key = Value" lines; ObjectType or NDims appear before the data.
bool metaimage_header(const unsigned char* b, std::size_t n) {
    const std::string text(reinterpret_cast<const char*>(b), n);
    for (const char* key : {"ObjectType", "NDims"}) {
        const std::size_t at = text.find(key);
        if (at == std::string::npos || (at > 0 && text[at - 1] != '\n')) continue;
        std::size_t p = at + std::strlen(key);
        while (p < text.size() && text[p] == ' ') ++p;
        if (p < text.size() && text[p] == '=') return true;
    }
    return false;
}

std::vector<unsigned char> head_bytes(const std::string& path, std::size_t n) {
    std::vector<unsigned char> b(n);
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(b.data()), std::streamsize(n));
    b.resize(std::size_t(in.gcount()));
    return b;
}

bool is_dicom_file(const std::string& path) {
    const std::vector<unsigned char> b = head_bytes(path, 132);
    return b.size() == 132 && std::memcmp(b.data() + 128, "DICM", 4) == 0;
}

bool dicom_extension(const fs::path& p) {
    const std::string ext = lower_extension(p);
    return ext == ".dcm" || ext == ".dicom" || ext == ".ima";
}

}  // namespace

std::vector<unsigned char> gunzip_head(const std::string& path, std::size_t n) {
    std::vector<unsigned char> b(n);
    gzFile gz = gzopen(path.c_str(), "rb");
    if (!gz) return {};
    const int got = gzread(gz, b.data(), unsigned(n));
    gzclose(gz);
    b.resize(got > 0 ? std::size_t(got) : 0);
    return b;
}

Format detect_format(const std::string& path) {
    std::error_code ec;
    // Only regular files are opened: a FIFO blocks the reader, a device never ends.
    if (!fs::is_directory(path, ec)) regular_file_size(path, path);
    if (fs::is_directory(path, ec)) {
        // TIFF slices by their magic, DICOM files by their preamble or extension.
        bool tiff = false, dicom = false;
        for (const auto& e : fs::directory_iterator(path, ec)) {
            if (!e.is_regular_file(ec)) continue;
            const std::string f = e.path().string();
            const std::vector<unsigned char> b = head_bytes(f, 132);
            if (tiff_magic(b.data(), b.size())) tiff = true;
            else if ((b.size() == 132 && std::memcmp(b.data() + 128, "DICM", 4) == 0) || dicom_extension(e.path()))
                dicom = true;
        }
        if (tiff && !dicom) return Format::directory_tiff;
        if (dicom && !tiff) return Format::directory_dicom;
        if (tiff && dicom) throw InputError(path + ": the directory holds both TIFF and DICOM files");
        throw InputError(path + ": a directory, not a regular file, and it holds no DICOM series or TIFF slices");
    }
    // .raw is headerless data by name (NAME_XxYxZ_TYPE.raw, or a MetaImage's data file).
    if (lower_extension(path) == ".raw") return Format::raw;
    const std::vector<unsigned char> b = head_bytes(path, 1024);
    const unsigned char* p = b.data();
    const std::size_t n = b.size();
    if (n >= 7 && std::memcmp(p, "NRRD000", 7) == 0) return Format::nrrd;
    if (is_dicom_file(path)) return Format::dicom;
    if (tiff_magic(p, n)) return Format::tiff;
    if (nifti_magic(p, n)) return Format::nifti;
    if (n >= 2 && p[0] == 0x1f && p[1] == 0x8b) {
        const std::vector<unsigned char> inner = gunzip_head(path, 544);
        if (nifti_magic(inner.data(), inner.size())) return Format::nifti;
        const std::string ext = lower_extension(path);
        if (ext == ".gz" && lower_extension(fs::path(path).stem()) == ".nii") return Format::nifti;  // truncated
    }
    if (metaimage_header(p, n)) return Format::metaimage;
    const std::string ext = lower_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr") return Format::nrrd;
    // A .hdr without the NIfTI magic (ANALYZE 7.5): nifticlib reads it when sizeof_hdr says so.
    if (ext == ".hdr" && n >= 4 && (int32_at(p, false) == 348 || int32_at(p, true) == 348)) return Format::nifti;
    if (ext == ".nii") return Format::nifti;
    if (ext == ".img" && fs::exists(fs::path(path).replace_extension(".hdr"), ec)) return Format::nifti;
    if (ext == ".mha" || ext == ".mhd") return Format::metaimage;
    if (ext == ".tif" || ext == ".tiff") return Format::tiff;
    if (dicom_extension(path)) return Format::dicom;
    return Format::raw;
}

const char* format_name(Format f) {
    switch (f) {
    case Format::raw: return "raw";
    case Format::nrrd: return "NRRD";
    case Format::nifti: return "NIfTI";
    case Format::dicom: return "DICOM";
    case Format::tiff: return "TIFF";
    case Format::metaimage: return "MetaImage";
    case Format::directory_dicom: return "DICOM series";
    case Format::directory_tiff: return "TIFF slices";
    }
    return "?";
}

Volume read_all_slices(SliceSource& source, const std::string& name) {
    Volume v(source.dims, source.type, name);
    const std::size_t slice = source.dims.nx * source.dims.ny * value_size(source.type);
    for (std::size_t z = 0; z < source.dims.nz; ++z)
        source.read_slice(z, static_cast<unsigned char*>(v.data()) + z * slice);
    v.spacing = source.spacing;
    v.oriented = source.oriented;
    v.origin = source.origin;
    v.axes = source.axes;
    return v;
}

}  // namespace clfractal::io
