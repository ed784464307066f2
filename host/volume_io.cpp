// Volume I/O: raw files, NRRD through teem, synthetic:NAME[:N] specs (DESIGN §2 layer 2);
// the other formats in io_*.cpp, chosen by content (io_detect.cpp).
#include "clfractal/output_file.hpp"
#include "clfractal/volume_io.hpp"

#include <fcntl.h>
#include <teem/nrrd.h>
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

#include "clfractal/synthetic.hpp"
#include "io_formats.hpp"
#include "nrrd_types.hpp"
#include "nrrd_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal {
namespace {

constexpr bool host_big_endian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

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

/// NRRD type → ValueType, or an InputError naming the file.
ValueType nrrd_value_type(int nrrd_type, const std::string& path) {
    if (const std::optional<ValueType> t = value_type_of_nrrd(nrrd_type)) return *t;
    std::string names;
    for (ValueType t : all_value_types) names += std::string(names.empty() ? "" : ", ") + nrrd_type_name(t);
    throw InputError(path + ": unsupported NRRD type '" + airEnumStr(nrrdType, nrrd_type) + "' (expected " + names +
                     ")");
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

/// A NRRD space (RAS or LPS, 3D) becomes the LPS origin and unit axes.
void read_nrrd_orientation(const Nrrd* n, io::Geometry& g) {
    const bool ras = n->space == nrrdSpaceRightAnteriorSuperior, lps = n->space == nrrdSpaceLeftPosteriorSuperior;
    if ((!ras && !lps) || n->spaceDim != 3) return;
    const double sign[3] = {ras ? -1.0 : 1.0, ras ? -1.0 : 1.0, 1.0};
    auto axes = g.axes;
    for (unsigned a = 0; a < 3; ++a) {
        double len = 0;
        for (int r = 0; r < 3; ++r) len += n->axis[a].spaceDirection[r] * n->axis[a].spaceDirection[r];
        len = std::sqrt(len);
        if (!(len > 0) || !std::isfinite(len)) return;
        for (int r = 0; r < 3; ++r) axes[a][r] = sign[r] * n->axis[a].spaceDirection[r] / len;
    }
    g.axes = axes;
    for (int r = 0; r < 3; ++r) g.origin[r] = std::isfinite(n->spaceOrigin[r]) ? sign[r] * n->spaceOrigin[r] : 0.0;
    g.oriented = true;
}

void set_geometry(Volume& v, const io::Geometry& g) {
    v.spacing = g.spacing;
    v.oriented = g.oriented;
    v.origin = g.origin;
    v.axes = g.axes;
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

/// Reads exactly `bytes` bytes of `file` from `offset` into `dst` (pread: no buffering, no
/// copy beyond the kernel's); a short file is an InputError naming `name`.
void read_file_data(const std::string& file, std::uint64_t offset, void* dst, std::size_t bytes,
                    const std::string& name) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(printable(name) + ": cannot open " + printable(file) + ": " + std::strerror(errno));
    auto* out = static_cast<unsigned char*>(dst);
    std::size_t done = 0;
    std::string problem;
    while (done < bytes) {
        const ssize_t got = ::pread(fd, out + done, std::min<std::size_t>(bytes - done, std::size_t(1) << 30),
                                    off_t(offset + done));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) problem = std::strerror(errno);
        else if (got == 0) problem = "truncated: " + std::to_string(done) + " of " + std::to_string(bytes) + " data bytes";
        if (!problem.empty()) break;
        done += std::size_t(got);
    }
    ::close(fd);
    if (!problem.empty()) throw InputError(printable(name) + ": cannot read the data: " + problem);
}

}  // namespace

io::Geometry io::nrrd_geometry(const Nrrd* n) {
    io::Geometry g;
    for (unsigned a = 0; a < 3; ++a) g.spacing[a] = axis_spacing(n, a);
    read_nrrd_orientation(n, g);
    return g;
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
    read_file_data(path, 0, v.data(), std::size_t(expected), path);

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
    const ValueType type = nrrd_value_type(header->type, path);
    const Dims dims{header->axis[0].size, header->axis[1].size, header->axis[2].size};
    check_dims(dims, path);

    // Raw or gzip data of one file is read here straight into the volume, exactly the bytes
    // the header claims (the same reading as SliceReader): one pass, no second host copy
    // (teem would allocate, zero and fill its own buffer); the rest through teem.
    NrrdPtr nrrd(nrrdNew());
    const bool one_file = checked.data_files.size() == 1 && checked.line_skip == 0 && checked.byte_skip == 0;
    if (one_file && (checked.encoding == "gzip" || checked.encoding == "raw")) {
        Volume v(dims, type, path);
        const std::size_t value_bytes = checked.value_bytes;
        unsigned char* data = static_cast<unsigned char*>(v.data());
        const std::size_t bytes = v.vertices() * value_bytes;
        const std::uint64_t offset = checked.attached ? checked.data_offset : 0;
        if (checked.encoding == "gzip") read_gzip_data(checked.data_files[0], offset, data, bytes, path);
        else read_file_data(checked.data_files[0], offset, data, bytes, path);
        if (value_bytes > 1 && checked.big_endian != host_big_endian)
            for (std::size_t i = 0; i < bytes; i += value_bytes) std::reverse(data + i, data + i + value_bytes);
        set_geometry(v, io::nrrd_geometry(header.get()));
        return v;
    }
    if (nrrdLoad(nrrd.get(), path.c_str(), nullptr))
        throw InputError(printable(path) + ": cannot read NRRD: " + printable(biff_message()));

    Volume v(dims, type, path);
    std::memcpy(v.data(), nrrd->data, v.size_bytes());
    set_geometry(v, io::nrrd_geometry(nrrd.get()));
    return v;
}

Volume read_volume(const std::string& spec, const RawOptions& raw, FiniteCheck finite) {
    const std::string synthetic_prefix = "synthetic:";
    Volume v;
    if (spec.compare(0, synthetic_prefix.size(), synthetic_prefix) == 0) {
        v = read_synthetic(spec, synthetic_prefix.size());
    } else {
        std::error_code ec;
        if (!fs::exists(spec, ec)) throw InputError(spec + ": no such file");
        if (!fs::is_regular_file(spec, ec) && !fs::is_directory(spec, ec))
            throw InputError(spec + ": not a regular file");
        switch (io::detect_format(spec)) {
        case io::Format::nrrd: v = read_nrrd(spec); break;
        case io::Format::nifti: v = io::read_nifti(spec, raw.scaled); break;
        case io::Format::dicom:
        case io::Format::directory_dicom: v = io::read_dicom(spec, raw.series); break;
        case io::Format::tiff:
        case io::Format::directory_tiff: v = io::read_tiff(spec); break;
        case io::Format::metaimage: v = io::read_metaimage(spec); break;
        case io::Format::raw: v = read_raw(spec, raw); break;
        }
    }
    if (finite == FiniteCheck::reject) check_finite(v, spec);
    if (raw.as && *raw.as != v.type()) v = convert_volume(v, *raw.as);
    v.name = spec;
    return v;
}

namespace {

// Describes a grid to teem: type, sizes and the spacing, or for oriented grids the LPS
// space directions (axis * spacing) and origin; `data` is wrapped, not owned, and read only
// when teem writes data. Returns teem's failure flag (the message on biff's stack).
bool describe_grid(Nrrd* nrrd, const void* data, const Dims& d, ValueType t, const io::Geometry& g) {
    const std::size_t sizes[3] = {d.nx, d.ny, d.nz};
    bool failed = nrrdWrap_nva(nrrd, const_cast<void*>(data), nrrd_type_of(t), 3, sizes);
    if (!failed && g.oriented) {
        double directions[NRRD_DIM_MAX][NRRD_SPACE_DIM_MAX] = {};
        for (int a = 0; a < 3; ++a)
            for (int r = 0; r < 3; ++r) directions[a][r] = g.axes[a][r] * g.spacing[a];
        failed = nrrdSpaceSet(nrrd, nrrdSpaceLeftPosteriorSuperior) ||
                 nrrdSpaceOriginSet(nrrd, const_cast<double*>(g.origin.data()));
        if (!failed) nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoSpaceDirection, directions);
    } else if (!failed) {
        nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoSpacing, g.spacing.data());
    }
    return failed;
}

NrrdIoPtr nrrd_io(bool gzip, bool skip_data) {
    NrrdIoPtr nio(nrrdIoStateNew());
    nio->format = nrrdFormatNRRD;
    nio->encoding = gzip ? nrrdEncodingGzip : nrrdEncodingRaw;
    nio->skipData = skip_data ? AIR_TRUE : AIR_FALSE;
    return nio;
}

void write_nrrd_grid(const Volume& v, const std::string& path, bool gzip, const io::Geometry& g) {
    const std::string tmp = temporary_path(path);
    std::unique_ptr<Nrrd, NrrdNix> nrrd(nrrdNew());
    const bool failed = describe_grid(nrrd.get(), v.data(), v.dims(), v.type(), g) ||
                        nrrdSave(tmp.c_str(), nrrd.get(), nrrd_io(gzip, false).get());
    if (failed) discard_temporary(tmp, path, "cannot write NRRD: " + biff_message());
    rename_into_place(tmp, path);
}

}  // namespace

void write_nrrd(const Volume& v, const std::string& path, bool gzip) {
    write_nrrd_grid(v, path, gzip, io::geometry_of(v));
}

void write_volume(const Volume& v, const std::string& path, const Volume* grid) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* read_only : {".mha", ".mhd", ".tif", ".tiff", ".dcm", ".hdr", ".img"})
        if (ext == read_only)
            throw InputError(path + ": cannot write " + ext + " files; use .nrrd, .nii or .nii.gz");
    const io::Geometry g = io::geometry_of(grid ? *grid : v);
    if (io::nifti_path(path)) {
        io::NiftiWriter w(path, v.dims(), v.type(), g);
        w.write(v.data(), v.size_bytes());
        return w.close();
    }
    write_nrrd_grid(v, path, false, g);
}

namespace io {

struct NrrdWriter::Impl {
    std::string path, tmp;
    std::FILE* file = nullptr;
    std::size_t expected = 0, written = 0;
    bool closed = false;

    [[noreturn]] void fail(const std::string& message) {
        if (file) std::fclose(file);
        file = nullptr;
        discard_temporary(tmp, path, message);
    }
};

NrrdWriter::NrrdWriter(const std::string& path, const Dims& dims, ValueType type, const Geometry& g)
    : impl_(std::make_unique<Impl>()) {
    check_dims(dims, path);
    Impl& w = *impl_;
    w.path = path;
    w.tmp = temporary_path(path);
    w.expected = dims.vertices() * value_size(type);
    w.file = std::fopen(w.tmp.c_str(), "wb");
    if (!w.file) w.fail(std::string("cannot write: ") + std::strerror(errno));
    // teem writes the header alone (skipData): it checks that the grid has data but never
    // reads it, so one byte stands in for the slices that follow.
    static const unsigned char stand_in = 0;
    std::unique_ptr<Nrrd, NrrdNix> nrrd(nrrdNew());
    if (describe_grid(nrrd.get(), &stand_in, dims, type, g) || nrrdWrite(w.file, nrrd.get(), nrrd_io(false, true).get()))
        w.fail("cannot write NRRD: " + biff_message());
}

NrrdWriter::~NrrdWriter() {
    if (impl_->closed) return;
    if (impl_->file) std::fclose(impl_->file);
    remove_temporary(impl_->tmp);
}

void NrrdWriter::write(const void* data, std::size_t bytes) {
    Impl& w = *impl_;
    if (w.closed || w.written + bytes > w.expected) throw std::logic_error("NrrdWriter::write: more data than the grid");
    if (bytes && std::fwrite(data, 1, bytes, w.file) != bytes)
        w.fail(std::string("cannot write: ") + std::strerror(errno));
    w.written += bytes;
}

void NrrdWriter::close() {
    Impl& w = *impl_;
    if (w.written != w.expected) throw std::logic_error("NrrdWriter::close: not all of the data was written");
    const int flushed = std::fclose(w.file);
    w.file = nullptr;
    if (flushed != 0) w.fail(std::string("cannot write: ") + std::strerror(errno));
    w.closed = true;
    rename_into_place(w.tmp, w.path);
}

}  // namespace io

std::vector<std::string> describe_volume_file(const std::string& spec, const RawOptions& raw) {
    if (spec.rfind("synthetic:", 0) == 0) return {"format    synthetic"};
    std::error_code ec;
    if (!fs::exists(spec, ec)) return {};  // read_volume words it
    const io::Format f = io::detect_format(spec);
    std::vector<std::string> lines{std::string("format    ") + io::format_name(f)};
    std::vector<std::string> notes;
    if (f == io::Format::nifti) notes = io::nifti_notes(spec);
    if (f == io::Format::dicom || f == io::Format::directory_dicom) notes = io::dicom_notes(spec, raw.series);
    for (const std::string& n : notes) lines.push_back("          " + n);
    return lines;
}

NonFinite count_non_finite(const void* data, ValueType t, std::size_t n) {
    NonFinite r{0, 0, n};
    if (is_integer(t)) return r;
    // The vectorised pass for the common all-finite case; the first bad index is only
    // searched for when there is one.
    const ValueStats s = value_stats(data, t, n);
    r.nan = s.nan;
    r.inf = s.inf;
    if (s.nan + s.inf) r.first = first_non_finite(data, t, n);
    return r;
}

void check_finite(const void* data, ValueType t, std::size_t n, const Dims& d, std::size_t offset,
                  const std::string& what) {
    const NonFinite nf = count_non_finite(data, t, n);
    if (nf.nan + nf.inf == 0) return;
    std::string counts;
    if (nf.nan) counts = std::to_string(nf.nan) + " NaN";
    if (nf.inf) counts += (counts.empty() ? "" : " and ") + std::to_string(nf.inf) + " infinite";
    counts += nf.nan + nf.inf > 1 ? " values" : " value";
    const std::size_t plane = d.nx * d.ny, z0 = offset / plane, z1 = (offset + n - 1) / plane;
    if (offset != 0 || n != d.vertices())
        counts += z0 == z1 ? " in slice " + std::to_string(z0) : " in slices " + std::to_string(z0) + ".." + std::to_string(z1);
    const double f = visit_type(t, [&](auto zero) { return double(static_cast<const decltype(zero)*>(data)[nf.first]); });
    const std::size_t i = offset + nf.first;
    throw InputError(what + ": float data contains " + counts + " (the first, " +
                     (std::isnan(f) ? "NaN" : f > 0 ? "Inf" : "-Inf") + ", at vertex (" + std::to_string(i % d.nx) + "," +
                     std::to_string(i / d.nx % d.ny) + "," + std::to_string(i / plane) +
                     ")); counting, filtering and meshing need finite values");
}

void check_finite(const Volume& v, const std::string& what) {
    check_finite(v.data(), v.type(), v.vertices(), v.dims(), 0, what);
}

}  // namespace clfractal
