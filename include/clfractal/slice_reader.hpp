// Reading a volume slice by slice from disk, so that host memory stays bounded by a few slices
// however large the file (docs/definitions.md §28): raw files and raw-encoded NRRD data through
// memory maps of a window of slices, gzip-encoded NRRD data decompressed sequentially (zlib),
// DICOM series and TIFF stacks (multi-page or a directory of slices) one slice file or page at
// a time. Other inputs (synthetic:NAME[:N], NIfTI, MetaImage, NRRD with line/byte skips or
// several data files) are read whole and then served slice by slice.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "clfractal/volume.hpp"
#include "clfractal/volume_io.hpp"

namespace clfractal {

/// The size and value type of a volume, as its header states them.
struct VolumeShape {
    Dims dims;
    ValueType type = ValueType::uint8;
    /// How the data is stored, as SliceReader::method() names it: "mmap" (uncompressed, read
    /// as it lies), "gzip", "dicom" or "tiff".
    std::string method;
    std::uint64_t bytes() const { return std::uint64_t(dims.vertices()) * value_size(type); }
};

class SliceReader {
public:
    /// Opens `spec` like read_volume (same header checks and InputErrors: no such file,
    /// truncated, bad header) without reading the data.
    explicit SliceReader(const std::string& spec, const RawOptions& raw = {});
    ~SliceReader();
    SliceReader(const SliceReader&) = delete;
    SliceReader& operator=(const SliceReader&) = delete;

    const Dims& dims() const;
    ValueType type() const;
    const std::array<double, 3>& spacing() const;
    std::size_t slice_bytes() const;
    /// "mmap", "gzip", "dicom", "tiff" or "memory" (read whole).
    const char* method() const;

    /// Reads the next `count` slices into `dst` (count * slice_bytes() bytes), converted to
    /// native endianness (float64 NRRD data to float32). Float data with NaN or Inf is an
    /// InputError naming the file and the vertex; a short or corrupt file is an InputError.
    void read(void* dst, std::size_t count);
    /// The next slice read() returns.
    std::size_t next_slice() const;
    /// Back to slice 0 (gzip data is decompressed again).
    void rewind();
    /// The next read() starts at slice z (raw and NRRD raw data: at once; gzip data is
    /// decompressed up to z; an MPI rank reads only its own z-part this way).
    void seek(std::size_t z);

private:
    friend class SliceWriter;
    friend std::optional<VolumeShape> peek_volume(const std::string&, const RawOptions&);
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The shape of `spec` when its header states it without reading the data: raw files (named
/// or with RawOptions), NRRD with one raw or gzip data file, DICOM series and TIFF stacks,
/// with RawOptions::as applied. Empty for inputs that are read whole to learn it (NIfTI,
/// MetaImage, synthetic:, NRRD with skips). Throws the header's InputErrors, as SliceReader.
std::optional<VolumeShape> peek_volume(const std::string& spec, const RawOptions& raw = {});

/// Writes a NRRD (attached header, raw encoding, native endianness) slice by slice to a
/// temporary name beside `path`, renamed into place by close() once every slice is in; if
/// close() is never reached (an exception), the temporary file is removed.
class NrrdSliceWriter {
public:
    NrrdSliceWriter(const std::string& path, const Dims& dims, ValueType type,
                    const std::array<double, 3>& spacing = {1.0, 1.0, 1.0});
    ~NrrdSliceWriter();
    NrrdSliceWriter(const NrrdSliceWriter&) = delete;
    NrrdSliceWriter& operator=(const NrrdSliceWriter&) = delete;

    /// Appends `count` slices (count * nx * ny values of the type).
    void write(const void* slices, std::size_t count);
    /// Checks that all nz slices were written, flushes and renames into place.
    void close();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Writes a volume slice by slice in the format the extension names (NIfTI for .nii /
/// .nii.gz, NRRD otherwise, as write_volume), with the spacing (and, for NIfTI, the
/// orientation) of the file `grid` reads; temporary file renamed into place by close().
class SliceWriter {
public:
    SliceWriter(const std::string& path, const Dims& dims, ValueType type, const SliceReader& grid);
    ~SliceWriter();
    SliceWriter(const SliceWriter&) = delete;
    SliceWriter& operator=(const SliceWriter&) = delete;
    /// Appends `count` slices (count * nx * ny values of the type).
    void write(const void* slices, std::size_t count);
    /// Checks that all nz slices were written, flushes and renames into place.
    void close();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The value range of the whole file, read slice by slice (one pass, bounded memory);
/// the reader is rewound afterwards.
ValueRange value_range(SliceReader& reader);

}  // namespace clfractal
