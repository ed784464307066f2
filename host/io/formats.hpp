// Private to the library: the readers and writers of the file formats beyond raw and NRRD
// (docs/definitions.md §26 "File formats", §27 "Values and orientation"), one file each
// (io/dicom.cpp, io/nifti.cpp, io/tiff.cpp, io/metaimage.cpp), and what they share
// (io/detect.cpp): format detection by content, the one mapping of a file's stored type onto
// ValueType, and the rescale rule.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "clfractal/volume.hpp"
#include "clfractal/volume_io.hpp"

namespace clfractal::io {

constexpr bool host_big_endian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

/// From this size on, read_file_data reads in one part a core: one thread copying a big file
/// out of the page cache is bound by the copy (453 MB: 0.045 s alone, 0.03 s on two cores).
constexpr std::size_t parallel_read_bytes = std::size_t(32) << 20;

/// Reads exactly `bytes` bytes of `file` from `offset` into `dst` (pread: no buffering, no
/// copy beyond the kernel's; from parallel_read_bytes on, a part a core); a short file is an
/// InputError naming `name` (io/raw.cpp).
void read_file_data(const std::string& file, std::uint64_t offset, void* dst, std::size_t bytes,
                    const std::string& name);

struct Geometry;
/// Writes `v` as NRRD with grid `g`, through a temporary file renamed into place (io/nrrd.cpp).
void write_nrrd_grid(const Volume& v, const std::string& path, bool gzip, const Geometry& g);

/// The type of the values as a file stores them.
enum class StoredKind { uint8, int8, uint16, int16, uint32, int32, float32, float64 };

/// "uint8", "int8", ..., "float64".
const char* stored_kind_name(StoredKind kind);
std::size_t stored_kind_size(StoredKind kind);

/// The ValueType that holds values of `kind` exactly. The one place that says which stored
/// types reach the kernels: a type not yet supported is an InputError naming `file`.
ValueType value_type_for(StoredKind kind, const std::string& file);

/// Converts `n` stored values (native byte order) to the Volume's type; exact by
/// construction (the caller chose `dst`'s type with value_type_for or rescale_type).
void convert_values(const void* src, StoredKind kind, std::size_t n, void* dst, ValueType type);

/// A linear map of stored values to the values users mean (DICOM RescaleSlope/Intercept,
/// NIfTI scl_slope/scl_inter).
struct Rescale {
    double slope = 1.0, intercept = 0.0;
    bool identity() const { return slope == 1.0 && intercept == 0.0; }
    /// Slope 1 and an integer intercept: integer values stay integers.
    bool integral() const;
};

/// The type of `stored * slope + intercept` for stored values of `kind` in [lo, hi]
/// (docs/definitions.md §27): with an integral rescale, the stored type when it holds the
/// results, else the narrowest signed integer type that does (uint16 + intercept -1024 →
/// int16); otherwise float32. Routed through value_type_for (`file` names the input).
ValueType rescale_type(StoredKind kind, const std::vector<Rescale>& maps, double lo, double hi,
                       const std::string& file);

/// Applies `map` to `n` stored values of `kind`, writing values of `type` (exact for
/// integral maps, float32 rounding otherwise).
void rescale_values(const void* src, StoredKind kind, std::size_t n, const Rescale& map, void* dst,
                    ValueType type);

/// Smallest and largest of `n` stored values.
void stored_range(const void* src, StoredKind kind, std::size_t n, double& lo, double& hi);

/// Formats recognised by their content (magic bytes), with the extension as a hint only
/// where the content cannot tell (raw data, a NIfTI .img beside its .hdr).
enum class Format { raw, nrrd, nifti, dicom, tiff, metaimage, directory_dicom, directory_tiff };
Format detect_format(const std::string& path);

/// The first `n` bytes of the gzip file `path`, decompressed (fewer if it is shorter; none
/// if it cannot be opened). gzread passes data that is not gzip through unchanged.
std::vector<unsigned char> gunzip_head(const std::string& path, std::size_t n);
const char* format_name(Format f);

/// Sorted natural file-name order ("s2" before "s10"), used for TIFF slice directories.
bool natural_less(const std::string& a, const std::string& b);

Volume read_nifti(const std::string& path, bool scaled);
Volume read_dicom(const std::string& path, const std::string& series_uid);
Volume read_tiff(const std::string& path);
Volume read_metaimage(const std::string& path);

/// Lines for `clfractal info` (header facts the Volume does not carry).
std::vector<std::string> nifti_notes(const std::string& path);
std::vector<std::string> dicom_notes(const std::string& path, const std::string& series_uid);

/// Where a grid lies: spacing and, when known, the LPS origin and axis directions.
struct Geometry {
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    bool oriented = false;
    std::array<double, 3> origin{0.0, 0.0, 0.0};
    std::array<std::array<double, 3>, 3> axes{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
};
Geometry geometry_of(const Volume& v);

/// Writes NIfTI-1 (.nii, or gzip for .nii.gz; NIfTI-2 when an axis exceeds 32767) slice
/// by slice to a temporary file, renamed into place by close(); removed if never closed.
class NiftiWriter {
public:
    NiftiWriter(const std::string& path, const Dims& dims, ValueType type, const Geometry& g);
    ~NiftiWriter();
    NiftiWriter(const NiftiWriter&) = delete;
    NiftiWriter& operator=(const NiftiWriter&) = delete;
    void write(const void* data, std::size_t bytes);
    void close();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Writes a NRRD (attached header, raw encoding, native byte order) data slab by data slab
/// to a temporary file, renamed into place by close(); removed if never closed. teem writes
/// the header, the very header write_volume writes for the same dims, type and geometry, so
/// a volume written in pieces is byte for byte the volume written whole.
class NrrdWriter {
public:
    NrrdWriter(const std::string& path, const Dims& dims, ValueType type, const Geometry& g);
    ~NrrdWriter();
    NrrdWriter(const NrrdWriter&) = delete;
    NrrdWriter& operator=(const NrrdWriter&) = delete;
    void write(const void* data, std::size_t bytes);
    void close();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Writes a whole volume with NiftiWriter.
void write_nifti(const Volume& v, const std::string& path);

/// True for paths ending in .nii or .nii.gz (any case).
bool nifti_path(const std::string& path);

/// A volume that can be read one slice at a time (DICOM series, TIFF stacks).
class SliceSource {
public:
    virtual ~SliceSource() = default;
    Dims dims;
    ValueType type = ValueType::uint8;
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    bool oriented = false;  ///< as Volume::oriented, origin, axes
    std::array<double, 3> origin{0.0, 0.0, 0.0};
    std::array<std::array<double, 3>, 3> axes{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
    /// Reads slice z (nx*ny values of `type`) into dst.
    virtual void read_slice(std::size_t z, void* dst) = 0;
};
std::unique_ptr<SliceSource> open_dicom_slices(const std::string& path, const std::string& series_uid);
std::unique_ptr<SliceSource> open_tiff_slices(const std::string& path);

/// Reads every slice of `source` into a Volume named `name`.
Volume read_all_slices(SliceSource& source, const std::string& name);

}  // namespace clfractal::io
