// Reading and writing volumes: raw (dims/type from options or from the
// NAME_XxYxZ_TYPE.raw naming convention), NRRD through teem (attached or detached
// header, raw or gzip encoding, either endianness), NIfTI-1/2 (nifticlib), DICOM series
// (GDCM), TIFF (libtiff), MetaImage, and the synthetic:NAME[:N] specs.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/volume.hpp"

namespace clfractal {

struct RawOptions {
    std::optional<Dims> dims;        ///< --dims X,Y,Z (otherwise from the file name)
    std::optional<ValueType> type;   ///< --type T (otherwise from the file name)
    bool big_endian = false;         ///< --endian big
    std::array<double, 3> spacing{1.0, 1.0, 1.0};  ///< --spacing SX,SY,SZ (raw files only)
    std::string series;              ///< --series UID: the DICOM series of a directory to read
    bool scaled = false;             ///< --scaled: apply NIfTI scl_slope/scl_inter
    /// --as T: convert the values to T on read, whatever the format (convert_values: may
    /// round, e.g. float64 -> float32, and saturates to T's range).
    std::optional<ValueType> as;
};

/// Parses NAME_XxYxZ_TYPE.raw (the directory part is ignored). Returns false when the
/// name does not follow the convention.
bool parse_raw_name(const std::string& path, Dims& dims, ValueType& type);

/// Reads a headerless raw file. The file size must equal nx*ny*nz*size(type) exactly.
Volume read_raw(const std::string& path, const RawOptions& opt = {});

/// Reads a NRRD file (.nrrd or .nhdr) with teem. 3D scalar data only, of the eight value
/// types (NRRD signed char, unsigned char, short, unsigned short, int, unsigned int, float,
/// double); 64-bit integers are rejected.
Volume read_nrrd(const std::string& path);

/// Whether read_volume rejects float data holding NaN or Inf (everything that counts,
/// filters or meshes) or keeps it (`clfractal info`, which reports it).
enum class FiniteCheck { reject, keep };

/// Reads a volume given as a path or as "synthetic:NAME[:N]". The format is told by the
/// content: NRRD, DICOM (a file, or a directory of a series), NIfTI (also gzip), TIFF (a
/// multi-page file, or a directory of slices), MetaImage; anything else is raw.
/// Float data with NaN or Inf is rejected unless `finite` is keep; with raw.as the values
/// are then converted. Every problem is an
/// InputError whose message names the file and the problem.
Volume read_volume(const std::string& spec, const RawOptions& raw = {}, FiniteCheck finite = FiniteCheck::reject);

/// The format of `spec` and header facts the Volume does not carry (DICOM series in the
/// directory, NIfTI scaling and orientation), one line each, for `clfractal info`.
std::vector<std::string> describe_volume_file(const std::string& spec, const RawOptions& raw = {});

/// Writes `v` in the format the extension names: NIfTI for .nii / .nii.gz, NRRD otherwise
/// (.nrrd, .nhdr, or any other name), with the spacing and orientation of `grid` (an input
/// whose grid `v` shares: LD fields, filtered and smoothed volumes), else of `v`. Atomic
/// (temporary + rename). Formats clfractal only reads (.mha, .tif, .dcm, ...) are an InputError.
void write_volume(const Volume& v, const std::string& path, const Volume* grid = nullptr);

/// Writes a NRRD (attached header, raw encoding, or gzip when `gzip`) through a
/// temporary file renamed into place, so no half-written file is ever left behind.
void write_nrrd(const Volume& v, const std::string& path, bool gzip = false);

}  // namespace clfractal
