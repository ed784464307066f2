// NIfTI-1/2 through nifticlib (.nii, .nii.gz, .hdr/.img): stored voxel order, spacing from
// pixdim, scl_slope/scl_inter applied only when asked (docs/definitions.md §27).
#include "io/formats.hpp"

#include <nifti2_io.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "io/output_file.hpp"
#include "io/input_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal::io {
namespace {

struct NimFree {
    void operator()(nifti_image* n) const { nifti_image_free(n); }
};
using NimPtr = std::unique_ptr<nifti_image, NimFree>;

StoredKind stored_kind_of(int datatype, const std::string& path) {
    switch (datatype) {
    case DT_UINT8: return StoredKind::uint8;
    case DT_INT8: return StoredKind::int8;
    case DT_UINT16: return StoredKind::uint16;
    case DT_INT16: return StoredKind::int16;
    case DT_UINT32: return StoredKind::uint32;
    case DT_INT32: return StoredKind::int32;
    case DT_FLOAT32: return StoredKind::float32;
    case DT_FLOAT64: return StoredKind::float64;
    default:
        throw InputError(path + ": NIfTI datatype " + nifti_datatype_string(datatype) + " (" +
                         std::to_string(datatype) + ") is not a scalar type clfractal reads");
    }
}

int datatype_of(ValueType t) {
    switch (t) {
    case ValueType::uint8: return DT_UINT8;
    case ValueType::int8: return DT_INT8;
    case ValueType::uint16: return DT_UINT16;
    case ValueType::int16: return DT_INT16;
    case ValueType::uint32: return DT_UINT32;
    case ValueType::int32: return DT_INT32;
    case ValueType::float32: return DT_FLOAT32;
    case ValueType::float64: return DT_FLOAT64;
    }
    throw std::logic_error("datatype_of: invalid ValueType");
}

/// nifticlib finds files by their extension, and looks for x.nii before x.nii.gz (so it
/// would take the data of a neighbour x.nii for x.nii.gz): a single-file NIfTI is read
/// through a temporary link of its own, named .nii or .nii.gz by its content; only
/// .hdr/.img pairs are read where they are.
struct NiftiName {
    std::string name, link;
    explicit NiftiName(const std::string& path) : name(path) {
        std::string ext = fs::path(path).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (ext == ".hdr" || ext == ".img") return;
        unsigned char magic[2] = {0, 0};
        if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
            if (std::fread(magic, 1, 2, f) != 2) magic[0] = 0;
            std::fclose(f);
        }
        static std::atomic<unsigned> counter{0};
        link = (fs::temp_directory_path() / ("clfractal-" + std::to_string(::getpid()) + "-" +
                                             std::to_string(counter++) +
                                             (magic[0] == 0x1f && magic[1] == 0x8b ? ".nii.gz" : ".nii")))
                   .string();
        std::error_code ec;
        fs::create_symlink(fs::absolute(path, ec), link, ec);
        if (ec) throw InputError(path + ": cannot read NIfTI under this name (rename it .nii or .nii.gz)");
        name = link;
    }
    ~NiftiName() {
        std::error_code ec;
        if (!link.empty()) fs::remove(link, ec);
    }
};

/// The header and data files of `path`: x.hdr and x.img for an ANALYZE/NIfTI pair, else
/// the file itself.
std::pair<std::string, std::string> pair_files(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".hdr" && ext != ".img") return {path, path};
    auto with = [&](const char* lower, const char* upper) {
        const std::string e = fs::path(path).extension().string();
        const bool caps = !e.empty() && std::isupper(static_cast<unsigned char>(e.back()));
        return fs::path(path).replace_extension(caps ? upper : lower).string();
    };
    return {with(".hdr", ".HDR"), with(".img", ".IMG")};
}

/// The first `n` bytes of `file`, gunzipped when it starts with the gzip magic (`gz`).
std::string head_of(const std::string& file, std::size_t n, bool& gz) {
    const std::vector<unsigned char> b = gunzip_head(file, n);  // gzread reads plain files as they are
    unsigned char magic[2] = {0, 0};
    if (std::FILE* f = std::fopen(file.c_str(), "rb")) {
        if (std::fread(magic, 1, 2, f) != 2) magic[0] = 0;
        std::fclose(f);
    }
    gz = magic[0] == 0x1f && magic[1] == 0x8b;
    return std::string(b.begin(), b.end());
}

/// Checks what nifticlib is about to read, before it reads it: regular files, a NIfTI-1
/// or NIfTI-2 header (either byte order) with 1 to 7 dimensions of at least 1 each, a 3D
/// scalar volume of at most 2^40 vertices of a type clfractal reads, a voxel offset inside
/// the file, and data the file can hold (uncompressed: the bytes are there; gzip: no more
/// than deflate can expand the file to). nifticlib allocates the data size its header
/// claims before reading a byte.
void check_nifti(const std::string& path) {
    const auto [header_file, data_file] = pair_files(path);
    const std::uint64_t header_size = regular_file_size(header_file, path);
    const std::uint64_t data_size = data_file == header_file ? header_size : regular_file_size(data_file, path);
    bool gz = false;
    const std::string h = head_of(header_file, 540, gz);
    auto raw = [&](std::size_t at, std::size_t n, bool swap) {
        unsigned char b[8] = {};
        std::memcpy(b, h.data() + at, n);
        if (swap) std::reverse(b, b + n);
        return std::uint64_t(b[0]) | std::uint64_t(b[1]) << 8 | std::uint64_t(b[2]) << 16 | std::uint64_t(b[3]) << 24 |
               std::uint64_t(b[4]) << 32 | std::uint64_t(b[5]) << 40 | std::uint64_t(b[6]) << 48 | std::uint64_t(b[7]) << 56;
    };
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "NIfTI header check assumes a little-endian host");
    int version = 0;
    bool swap = false;
    for (bool s : {false, true}) {
        if (h.size() >= 348 && raw(0, 4, s) == 348) version = 1, swap = s;
        if (h.size() >= 540 && raw(0, 4, s) == 540) version = 2, swap = s;
        if (version) break;
    }
    if (!version) throw InputError(printable(path) + ": cannot read the NIfTI header (not NIfTI, or truncated)");
    std::int64_t dim[8];
    for (int i = 0; i < 8; ++i)
        dim[i] = version == 1 ? std::int64_t(std::int16_t(raw(40 + 2 * std::size_t(i), 2, swap)))
                              : std::int64_t(raw(16 + 8 * std::size_t(i), 8, swap));
    const int datatype = int(std::int16_t(raw(version == 1 ? 70 : 12, 2, swap)));
    double offset = 0;
    if (version == 1) {
        const std::uint32_t bits = std::uint32_t(raw(108, 4, swap));
        float f;
        std::memcpy(&f, &bits, 4);
        offset = f;
    } else {
        offset = double(std::int64_t(raw(168, 8, swap)));
    }
    if (dim[0] < 1 || dim[0] > 7)
        throw InputError(printable(path) + ": NIfTI dim[0] = " + std::to_string(dim[0]) + "; must be 1 to 7");
    for (int a = 1; a <= dim[0]; ++a) {
        if (dim[a] < 1)
            throw InputError(printable(path) + ": NIfTI dim[" + std::to_string(a) + "] = " + std::to_string(dim[a]));
        if (a >= 4 && dim[a] > 1)
            throw InputError(printable(path) + ": NIfTI has " + std::to_string(dim[0]) + " dimensions with dim[" +
                             std::to_string(a) + "] = " + std::to_string(dim[a]) + "; only 3D scalar volumes are supported");
    }
    const Dims dims{std::size_t(dim[1]), std::size_t(dim[0] >= 2 ? dim[2] : 1), std::size_t(dim[0] >= 3 ? dim[3] : 1)};
    check_dims(dims, printable(path));
    const StoredKind kind = stored_kind_of(datatype, path);
    if (!(offset >= 0 && offset <= double(std::uint64_t(1) << 40)))
        throw InputError(printable(path) + ": NIfTI vox_offset " + std::to_string(offset) + " is not a file offset");
    const std::uint64_t bytes = dims.vertices() * stored_kind_size(kind);
    const bool single = data_file == header_file;
    bool data_gz = gz;
    if (!single) head_of(data_file, 2, data_gz);
    // In a single file the data follows the header whatever vox_offset says.
    const std::uint64_t start = std::max<std::uint64_t>(std::uint64_t(offset), single ? (version == 1 ? 348 : 540) : 0);
    const std::string layout = dims_string(dims) + " " + stored_kind_name(kind);
    if (data_gz) check_claim(path, "the gzip file", "the NIfTI header and data (" + layout + ")", start + bytes, data_size, ExpansionLimits::deflate);
    else check_claim(path, single ? "the file" : "the .img file", "the NIfTI header and data (" + layout + ")", start + bytes, data_size, 1);
}

NimPtr read_header(const std::string& path, const std::string& name) {
    check_nifti(path);
    nifti_set_debug_level(0);  // errors are ours to word, in one line
    NimPtr nim(nifti_image_read(name.c_str(), 0));
    if (!nim) throw InputError(path + ": cannot read the NIfTI header (not NIfTI, or truncated)");
    return nim;
}

/// nifti_image_load, keeping NaN and Inf: nifticlib's nifti_read_buffer replaces every
/// non-finite float32/float64 value with 0, so float data are loaded under the integer type
/// of the same size (the same bytes, swapped the same way, left alone) and the type restored.
/// The values are then the stored ones, and NaN is reported like every other reader's
/// (check_finite).
int load_data(nifti_image& nim) {
    const int datatype = nim.datatype;
    if (datatype == DT_FLOAT32) nim.datatype = DT_INT32;
    if (datatype == DT_FLOAT64) nim.datatype = DT_INT64;
    const int rc = nifti_image_load(&nim);
    nim.datatype = datatype;
    return rc;
}

Rescale scale_of(const nifti_image& nim) {
    Rescale m;
    // slope 0 means "no scaling" (NIfTI-1 standard).
    if (nim.scl_slope != 0 && std::isfinite(nim.scl_slope) && std::isfinite(nim.scl_inter)) {
        m.slope = nim.scl_slope;
        m.intercept = nim.scl_inter;
    }
    return m;
}

}  // namespace

Volume read_nifti(const std::string& path, bool scaled) {
    const NiftiName name(path);
    NimPtr nim = read_header(path, name.name);
    for (int a = 4; a <= 7; ++a)
        if (nim->dim[0] >= a && nim->dim[a] > 1)
            throw InputError(path + ": NIfTI has " + std::to_string(nim->dim[0]) +
                             " dimensions with dim[" + std::to_string(a) + "] = " + std::to_string(nim->dim[a]) +
                             "; only 3D scalar volumes are supported");
    for (int a = 1; a <= 3; ++a)
        if (nim->dim[a] < 1 && nim->dim[0] >= a)
            throw InputError(path + ": NIfTI dim[" + std::to_string(a) + "] = " + std::to_string(nim->dim[a]));
    const Dims dims{std::size_t(std::max<int64_t>(1, nim->nx)), std::size_t(std::max<int64_t>(1, nim->ny)),
                    std::size_t(std::max<int64_t>(1, nim->nz))};
    check_dims(dims, path);
    const StoredKind kind = stored_kind_of(nim->datatype, path);
    const Rescale map = scaled ? scale_of(*nim) : Rescale{};
    if (map.identity()) value_type_for(kind, path);  // unsupported types fail before the data is read

    if (load_data(*nim) != 0 || !nim->data)
        throw InputError(path + ": NIfTI data truncated or unreadable (expected " +
                         std::to_string(dims.vertices() * stored_kind_size(kind)) + " bytes of " +
                         stored_kind_name(kind) + ")");
    const std::size_t n = dims.vertices();
    double lo = INFINITY, hi = -INFINITY;
    stored_range(nim->data, kind, n, lo, hi);
    const ValueType type = rescale_type(kind, {map}, lo, hi, path);
    Volume v(dims, type, path);
    rescale_values(nim->data, kind, n, map, v.data(), type);

    const double pixdim[3] = {nim->dx, nim->dy, nim->dz};
    for (int a = 0; a < 3; ++a) {
        const double s = std::fabs(pixdim[a]);
        v.spacing[a] = std::isfinite(s) && s > 0 ? s : 1.0;
    }
    // sform first, else qform: RAS+ (NIfTI) to LPS (DICOM) by negating x and y.
    const nifti_dmat44* m = nim->sform_code > 0 ? &nim->sto_xyz : nim->qform_code > 0 ? &nim->qto_xyz : nullptr;
    if (m) {
        v.oriented = true;
        const double sign[3] = {-1, -1, 1};
        for (int r = 0; r < 3; ++r) v.origin[r] = sign[r] * m->m[r][3];
        for (int c = 0; c < 3; ++c) {
            double len = 0;
            for (int r = 0; r < 3; ++r) len += m->m[r][c] * m->m[r][c];
            len = std::sqrt(len);
            for (int r = 0; r < 3; ++r) v.axes[c][r] = len > 0 ? sign[r] * m->m[r][c] / len : (r == c);
        }
    }
    return v;
}

std::vector<std::string> nifti_notes(const std::string& path) {
    const NiftiName name(path);
    NimPtr nim = read_header(path, name.name);
    std::vector<std::string> notes;
    std::ostringstream s;
    int version = 1;
    std::free(nifti_read_header(name.name.c_str(), &version, 0));
    s << (version == 2 ? "NIfTI-2" : version == 1 ? "NIfTI-1" : "ANALYZE 7.5") << ", stored "
      << nifti_datatype_string(nim->datatype) << ", "
      << (nim->byteorder == 2 /* MSB_FIRST */ ? "big" : "little") << "-endian";
    notes.push_back(s.str());
    const Rescale m = scale_of(*nim);
    std::ostringstream sc;
    sc.precision(10);
    sc << "scl_slope " << nim->scl_slope << ", scl_inter " << nim->scl_inter
       << (m.identity() ? " (no scaling)" : " (stored values; --scaled applies them)");
    notes.push_back(sc.str());
    notes.push_back(std::string("orientation ") +
                    (nim->sform_code > 0 ? "sform" : nim->qform_code > 0 ? "qform" : "none (pixdim only)"));
    return notes;
}

bool nifti_path(const std::string& path) {
    std::string lower = fs::path(path).filename().string();
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    auto ends = [&](const std::string& e) {
        return lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0;
    };
    return ends(".nii") || ends(".nii.gz");
}

Geometry geometry_of(const Volume& v) { return Geometry{v.spacing, v.oriented, v.origin, v.axes}; }

static_assert(sizeof(nifti_1_header) == 348 && sizeof(nifti_2_header) == 540, "NIfTI header layout");

struct NiftiWriter::Impl {
    std::string path, tmp;
    znzFile file = nullptr;
    std::size_t expected = 0, written = 0;
    bool closed = false;
};

NiftiWriter::NiftiWriter(const std::string& path, const Dims& dims, ValueType type, const Geometry& g)
    : impl_(std::make_unique<Impl>()) {
    check_dims(dims, path);
    Impl& w = *impl_;
    w.path = path;
    // The temporary name keeps the extension: nifticlib compresses by it.
    const std::string name = fs::path(path).filename().string();
    const bool gz = name.size() > 3 && (name.substr(name.size() - 3) == ".gz" || name.substr(name.size() - 3) == ".GZ");
    const std::size_t ext_len = gz ? 7 : 4;
    w.tmp = temporary_path(path, path.substr(path.size() - ext_len));
    w.expected = dims.vertices() * value_size(type);

    const int64_t nd[8] = {3, int64_t(dims.nx), int64_t(dims.ny), int64_t(dims.nz), 1, 1, 1, 1};
    nifti_set_debug_level(0);
    NimPtr nim(nifti_make_new_nim(nd, datatype_of(type), 0));
    if (!nim) throw InputError(path + ": cannot make a NIfTI header");
    nim->dx = nim->pixdim[1] = g.spacing[0];
    nim->dy = nim->pixdim[2] = g.spacing[1];
    nim->dz = nim->pixdim[3] = g.spacing[2];
    nim->xyz_units = NIFTI_UNITS_MM;
    if (g.oriented) {
        // LPS (DICOM) to RAS+ (NIfTI): negate x and y; columns are axis * spacing.
        const double sign[3] = {-1, -1, 1};
        nifti_dmat44 m{};
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) m.m[r][c] = sign[r] * g.axes[c][r] * g.spacing[c];
            m.m[r][3] = sign[r] * g.origin[r];
        }
        m.m[3][3] = 1;
        nim->sform_code = nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
        nim->sto_xyz = m;
        nim->qto_xyz = m;
        nifti_dmat44_to_quatern(m, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x,
                                &nim->qoffset_y, &nim->qoffset_z, nullptr, nullptr, nullptr, &nim->qfac);
    }
    // nifticlib makes the header (NIfTI-2 only where an axis exceeds NIfTI-1's 16 bits); it
    // is written here, as nifticlib 3.0's own NIfTI-2 writer loses the header of .nii files.
    const bool wide = dims.nx > 32767 || dims.ny > 32767 || dims.nz > 32767;
    nifti_1_header h1{};
    nifti_2_header h2{};
    const void* header = wide ? static_cast<const void*>(&h2) : static_cast<const void*>(&h1);
    const std::size_t header_size = wide ? sizeof h2 : sizeof h1;
    nim->nifti_type = wide ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
    if (wide ? nifti_convert_nim2n2hdr(nim.get(), &h2) : nifti_convert_nim2n1hdr(nim.get(), &h1))
        throw InputError(path + ": cannot make a NIfTI header");
    if (wide) {
        h2.vox_offset = 544;
        std::memcpy(h2.magic, "n+2\0\r\n\032\n", 8);
    } else {
        h1.vox_offset = 352;
        std::memcpy(h1.magic, "n+1", 4);
    }
    w.file = znzopen(w.tmp.c_str(), "wb", gz ? 1 : 0);
    const char no_extension[4] = {0, 0, 0, 0};
    if (znz_isnull(w.file) || znzwrite(header, 1, header_size, w.file) != header_size ||
        znzwrite(no_extension, 1, 4, w.file) != 4) {
        if (!znz_isnull(w.file)) znzclose(w.file);
        discard_temporary(w.tmp, path, "cannot write the NIfTI header");
    }
}

NiftiWriter::~NiftiWriter() {
    if (impl_->closed) return;
    if (!znz_isnull(impl_->file)) znzclose(impl_->file);
    std::error_code ec;
    fs::remove(impl_->tmp, ec);
}

void NiftiWriter::write(const void* data, std::size_t bytes) {
    Impl& w = *impl_;
    if (w.closed || w.written + bytes > w.expected) throw std::logic_error("NiftiWriter::write: too much data");
    if (nifti_write_buffer(w.file, data, int64_t(bytes)) != int64_t(bytes)) {
        znzclose(w.file);
        discard_temporary(w.tmp, w.path, "cannot write the NIfTI data");
    }
    w.written += bytes;
}

void NiftiWriter::close() {
    Impl& w = *impl_;
    if (w.written != w.expected) throw std::logic_error("NiftiWriter::close: not all data was written");
    const int status = znzclose(w.file);
    w.closed = true;
    if (status != 0) discard_temporary(w.tmp, w.path, "cannot write the NIfTI file");
    rename_into_place(w.tmp, w.path);
}

void write_nifti(const Volume& v, const std::string& path) {
    NiftiWriter w(path, v.dims(), v.type(), geometry_of(v));
    w.write(v.data(), v.size_bytes());
    w.close();
}

}  // namespace clfractal::io
