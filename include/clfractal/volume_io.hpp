// Reading and writing volumes: raw (dims/type from options or from the
// NAME_XxYxZ_TYPE.raw naming convention), NRRD through teem (attached or detached
// header, raw or gzip encoding, either endianness), and the synthetic:NAME[:N] specs.
#pragma once
#include <optional>
#include <string>

#include "clfractal/volume.hpp"

namespace clfractal {

struct RawOptions {
    std::optional<Dims> dims;        ///< --dims X,Y,Z (otherwise from the file name)
    std::optional<ValueType> type;   ///< --type T (otherwise from the file name)
    bool big_endian = false;         ///< --endian big
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

/// Reads a volume given as a path (.nrrd/.nhdr, or raw) or as "synthetic:NAME[:N]".
/// Float data with NaN or Inf is rejected; with raw.as the values are then converted.
/// Every problem is an InputError whose message names the file and the problem.
Volume read_volume(const std::string& spec, const RawOptions& raw = {});

/// Writes a NRRD (attached header, raw encoding, or gzip when `gzip`) through a
/// temporary file renamed into place, so no half-written file is ever left behind.
void write_nrrd(const Volume& v, const std::string& path, bool gzip = false);

/// Throws InputError if float data holds NaN or Inf (names `what` and the first index).
void check_finite(const Volume& v, const std::string& what);

}  // namespace clfractal
