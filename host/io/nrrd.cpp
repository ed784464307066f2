// NRRD through teem: reading (header checked by nrrd_guard before teem sees it, raw and
// gzip data read straight into the volume), writing and the slice-by-slice NrrdWriter.
#include "clfractal/volume_io.hpp"

#include <teem/nrrd.h>

#include <fcntl.h>
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
#include "io/nrrd_guard.hpp"
#include "io/nrrd_types.hpp"
#include "io/output_file.hpp"

namespace clfractal {
namespace {

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

}  // namespace

io::Geometry io::nrrd_geometry(const Nrrd* n) {
    io::Geometry g;
    for (unsigned a = 0; a < 3; ++a) g.spacing[a] = axis_spacing(n, a);
    read_nrrd_orientation(n, g);
    return g;
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
        else io::read_file_data(checked.data_files[0], offset, data, bytes, path);
        if (value_bytes > 1 && checked.big_endian != io::host_big_endian)
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

}  // namespace

void io::write_nrrd_grid(const Volume& v, const std::string& path, bool gzip, const io::Geometry& g) {
    const std::string tmp = temporary_path(path);
    std::unique_ptr<Nrrd, NrrdNix> nrrd(nrrdNew());
    const bool failed = describe_grid(nrrd.get(), v.data(), v.dims(), v.type(), g) ||
                        nrrdSave(tmp.c_str(), nrrd.get(), nrrd_io(gzip, false).get());
    if (failed) discard_temporary(tmp, path, "cannot write NRRD: " + biff_message());
    rename_into_place(tmp, path);
}

void write_nrrd(const Volume& v, const std::string& path, bool gzip) {
    io::write_nrrd_grid(v, path, gzip, io::geometry_of(v));
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

}  // namespace clfractal
