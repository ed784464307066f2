// Volume I/O: raw files, NRRD through teem, synthetic:NAME[:N] specs (DESIGN §2 layer 2).
#include "clfractal/output_file.hpp"
#include "clfractal/volume_io.hpp"

#include <teem/nrrd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
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

#include "clfractal/synthetic.hpp"
#include "nrrd_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal {
namespace {

constexpr bool host_big_endian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

/// Only the canonical names appear in NAME_XxYxZ_TYPE.raw, so no aliases here.
std::optional<ValueType> canonical_value_type(std::string_view text) {
    for (ValueType t : {ValueType::uint8, ValueType::uint16, ValueType::int16, ValueType::float32})
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
        }
    }
}

/// teem's error stack for NRRD as one line: biff writes one "[nrrd] function: reason"
/// line per level; the "[nrrd] " tags and levels without a reason are left out.
std::string biff_message() {
    char* err = biffGetDone(NRRD);
    std::istringstream lines(err ? err : "");
    std::free(err);
    const std::string tag = "[nrrd] ";
    std::string message;
    for (std::string line; std::getline(lines, line);) {
        if (line.compare(0, tag.size(), tag) == 0) line.erase(0, tag.size());
        while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
        if (line.empty() || line.back() == ':') continue;
        message += (message.empty() ? "" : "; ") + line;
    }
    return message;
}

struct NrrdNuke {
    void operator()(Nrrd* n) const { nrrdNuke(n); }
};
/// For nrrds wrapped around memory teem does not own.
struct NrrdNix {
    void operator()(Nrrd* n) const { nrrdNix(n); }
};
struct NrrdIoStateNix {
    void operator()(NrrdIoState* nio) const { nrrdIoStateNix(nio); }
};
using NrrdPtr = std::unique_ptr<Nrrd, NrrdNuke>;
using NrrdIoPtr = std::unique_ptr<NrrdIoState, NrrdIoStateNix>;

int nrrd_type_of(ValueType t) {
    switch (t) {
    case ValueType::uint8: return nrrdTypeUChar;
    case ValueType::uint16: return nrrdTypeUShort;
    case ValueType::int16: return nrrdTypeShort;
    case ValueType::float32: return nrrdTypeFloat;
    }
    throw std::logic_error("nrrd_type_of: invalid ValueType");
}

/// NRRD type → ValueType; float64 is read as float32 (DESIGN §1).
ValueType value_type_of_nrrd(int nrrd_type, const std::string& path) {
    switch (nrrd_type) {
    case nrrdTypeUChar: return ValueType::uint8;
    case nrrdTypeUShort: return ValueType::uint16;
    case nrrdTypeShort: return ValueType::int16;
    case nrrdTypeFloat:
    case nrrdTypeDouble: return ValueType::float32;
    default:
        throw InputError(path + ": unsupported NRRD type '" + airEnumStr(nrrdType, nrrd_type) +
                         "' (expected uchar, ushort, short, float or double)");
    }
}

/// Spacing of one axis: the scalar spacing or the length of the space direction.
/// NRRD allows negative spacings (a flipped axis); clfractal only needs the magnitude.
double axis_spacing(const Nrrd* n, unsigned axis) {
    double spacing = 1.0;
    double direction[NRRD_SPACE_DIM_MAX];
    switch (nrrdSpacingCalculate(n, axis, &spacing, direction)) {
    case nrrdSpacingStatusScalarNoSpace:
    case nrrdSpacingStatusScalarWithSpace:
    case nrrdSpacingStatusDirection: break;
    default: return 1.0;
    }
    spacing = std::fabs(spacing);
    return std::isfinite(spacing) && spacing > 0 ? spacing : 1.0;
}

bool has_nrrd_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".nrrd" || ext == ".nhdr";
}

/// synthetic:NAME[:N], N in [2, 2048] (default 128).
Volume read_synthetic(const std::string& spec, std::size_t prefix_length) {
    const std::string rest = spec.substr(prefix_length);
    const std::size_t colon = rest.find(':');
    SyntheticOptions opt;
    if (colon != std::string::npos) {
        const std::string size_text = rest.substr(colon + 1);
        const char* first = size_text.data();
        const char* last = first + size_text.size();
        std::size_t n = 0;
        const auto [next, ec] = std::from_chars(first, last, n);
        if (first == last || ec != std::errc() || next != last || n < 2 || n > 2048)
            throw InputError(spec + ": size '" + size_text +
                             "' must be an integer from 2 to 2048");
        opt.size = n;
    }
    return make_synthetic(rest.substr(0, colon), opt);
}

}  // namespace

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
                                 "' in the file name (expected uint8, uint16, int16 or float32)");
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
    std::ifstream in(path, std::ios::binary);
    in.read(static_cast<char*>(v.data()), static_cast<std::streamsize>(expected));
    if (!in || static_cast<std::uintmax_t>(in.gcount()) != expected)
        throw InputError(path + ": cannot read " + std::to_string(expected) + " bytes: " +
                         std::strerror(errno));

    if (opt.big_endian != host_big_endian)
        visit(v, [n = v.vertices()](auto* p) { byte_swap(p, n); });
    return v;
}

Volume read_nrrd(const std::string& path) {
    // teem only sees a header that check_nrrd bounded, with data files that can hold it.
    const NrrdHeader checked = check_nrrd(path);
    // Header first, so that absurd sizes are rejected before teem allocates the data.
    NrrdPtr header(nrrdNew());
    NrrdIoPtr nio(nrrdIoStateNew());
    nio->skipData = AIR_TRUE;
    if (nrrdLoad(header.get(), path.c_str(), nio.get()))
        throw InputError(printable(path) + ": cannot read NRRD: " + printable(biff_message()));
    if (header->dim != 3)
        throw InputError(path + ": NRRD has " + std::to_string(header->dim) +
                         " axes; only 3D scalar volumes are supported");
    const ValueType type = value_type_of_nrrd(header->type, path);
    const Dims dims{header->axis[0].size, header->axis[1].size, header->axis[2].size};
    check_dims(dims, path);

    // gzip data of one file is decompressed here, exactly the bytes the header claims (the
    // same zlib reading as SliceReader); the rest through teem.
    NrrdPtr nrrd(nrrdNew());
    const bool own_gzip = checked.encoding == "gzip" && checked.data_files.size() == 1 && checked.line_skip == 0 &&
                          checked.byte_skip == 0;
    if (own_gzip) {
        Volume v(dims, type, path);
        const std::size_t value_bytes = checked.value_bytes;
        std::vector<unsigned char> staging(header->type == nrrdTypeDouble ? v.vertices() * 8 : 0);
        unsigned char* data = staging.empty() ? static_cast<unsigned char*>(v.data()) : staging.data();
        const std::size_t bytes = v.vertices() * value_bytes;
        read_gzip_data(checked.data_files[0], checked.data_offset, data, bytes, path);
        if (value_bytes > 1 && checked.big_endian != host_big_endian)
            for (std::size_t i = 0; i < bytes; i += value_bytes) std::reverse(data + i, data + i + value_bytes);
        float* out = staging.empty() ? nullptr : v.as<float>();
        for (std::size_t i = 0; i < staging.size() / 8; ++i) {
            double d;
            std::memcpy(&d, data + 8 * i, 8);
            out[i] = static_cast<float>(d);
        }
        for (unsigned a = 0; a < 3; ++a) v.spacing[a] = axis_spacing(header.get(), a);
        return v;
    }
    if (nrrdLoad(nrrd.get(), path.c_str(), nullptr))
        throw InputError(printable(path) + ": cannot read NRRD: " + printable(biff_message()));

    Volume v(dims, type, path);
    if (nrrd->type == nrrdTypeDouble) {
        const double* in = static_cast<const double*>(nrrd->data);
        float* out = v.as<float>();
        const std::size_t n = v.vertices();
        for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(in[i]);
    } else {
        std::memcpy(v.data(), nrrd->data, v.size_bytes());
    }
    for (unsigned a = 0; a < 3; ++a) v.spacing[a] = axis_spacing(nrrd.get(), a);
    return v;
}

Volume read_volume(const std::string& spec, const RawOptions& raw) {
    const std::string synthetic_prefix = "synthetic:";
    Volume v;
    if (spec.compare(0, synthetic_prefix.size(), synthetic_prefix) == 0) {
        v = read_synthetic(spec, synthetic_prefix.size());
    } else {
        std::error_code ec;
        if (!fs::exists(spec, ec)) throw InputError(spec + ": no such file");
        if (!fs::is_regular_file(spec, ec)) throw InputError(spec + ": not a regular file");
        v = has_nrrd_extension(spec) ? read_nrrd(spec) : read_raw(spec, raw);
    }
    check_finite(v, spec);
    v.name = spec;
    return v;
}

void write_nrrd(const Volume& v, const std::string& path, bool gzip) {
    const std::string tmp = temporary_path(path);

    // teem only reads the data when writing; the wrap does not take ownership.
    std::unique_ptr<Nrrd, NrrdNix> nrrd(nrrdNew());
    const std::size_t sizes[3] = {v.dims().nx, v.dims().ny, v.dims().nz};
    NrrdIoPtr nio(nrrdIoStateNew());
    nio->format = nrrdFormatNRRD;
    nio->encoding = gzip ? nrrdEncodingGzip : nrrdEncodingRaw;
    bool failed =
        nrrdWrap_nva(nrrd.get(), const_cast<void*>(v.data()), nrrd_type_of(v.type()), 3, sizes);
    if (!failed) {
        nrrdAxisInfoSet_nva(nrrd.get(), nrrdAxisInfoSpacing, v.spacing.data());
        failed = nrrdSave(tmp.c_str(), nrrd.get(), nio.get());
    }
    if (failed) discard_temporary(tmp, path, "cannot write NRRD: " + biff_message());
    rename_into_place(tmp, path);
}

void check_finite(const Volume& v, const std::string& what) {
    if (v.type() != ValueType::float32) return;
    const float* p = v.as<float>();
    const std::size_t n = v.vertices();
    // A branch-free parallel pass for the common all-finite case; the first bad index
    // is only searched for when there is one.
    std::size_t bad = 0;
#pragma omp parallel for reduction(+ : bad) schedule(static)
    for (std::size_t i = 0; i < n; ++i) bad += !std::isfinite(p[i]);
    if (bad == 0) return;

    const std::size_t i =
        static_cast<std::size_t>(std::find_if(p, p + n, [](float f) { return !std::isfinite(f); }) - p);
    const Dims& d = v.dims();
    const char* kind = std::isnan(p[i]) ? "NaN" : (p[i] > 0 ? "Inf" : "-Inf");
    throw InputError(what + ": float data contains " + kind + " at vertex (" +
                     std::to_string(i % d.nx) + "," + std::to_string(i / d.nx % d.ny) + "," +
                     std::to_string(i / (d.nx * d.ny)) + ")");
}

}  // namespace clfractal
