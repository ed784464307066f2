// A bounded pre-parse of NRRD headers, run before teem sees a file (private to the library).
// teem trusts its input: an error message over ~1 KiB overflows a fixed buffer inside its
// error reporting (an abort), a header claiming gigabytes makes it allocate and zero-fill
// them before reading a byte, a FIFO named as the data file blocks it forever, and
// key/value lines cost it quadratic time. check_nrrd refuses all of these with one line
// naming the file, and tells both read paths (in core and slice by slice) where the data is.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace clfractal {

/// Limits on what reaches teem.
struct NrrdLimits {
    static constexpr std::size_t header_bytes = 1 << 20;  ///< whole header
    static constexpr std::size_t field_line = 400;         ///< a field line (teem echoes it in errors)
    static constexpr std::size_t key_value_line = 8192;    ///< a key:=value line
    static constexpr std::size_t key_values = 1000;        ///< number of key:=value lines
    static constexpr std::size_t path = 400;               ///< header and data file paths
    static constexpr std::size_t data_files = 65536;       ///< files of a LIST or pattern
    /// Deflate expands at most 1032:1, so gzip data shorter than 1/1032 of the claim
    /// cannot hold it.
    static constexpr std::uint64_t deflate_ratio = 1032;
};

/// What the header says about the data, checked.
struct NrrdHeader {
    std::size_t dimension = 0;
    std::vector<std::size_t> sizes;
    std::string type;            ///< teem's canonical name: uchar, ushort, short, float, double, ...
    std::size_t value_bytes = 0; ///< bytes per value in the file
    std::string encoding;        ///< raw, gzip, ascii, hex
    bool big_endian = false;
    bool attached = true;        ///< data follows the header in the same file
    std::vector<std::string> data_files;  ///< the header's own path when attached; resolved names
    std::uint64_t data_offset = 0;        ///< attached: bytes before the data (after the blank line)
    long long line_skip = 0, byte_skip = 0;
    std::uint64_t values() const;
};

/// Reads the header of `path` (bounded), checks its field syntax, the data files (regular
/// files, present, short enough paths), and the data size the header implies against the
/// files (raw: at least that many bytes; gzip: a gzip stream that can hold it; ascii/hex:
/// enough characters). Throws InputError "<path>: <problem>" with the input sanitised.
NrrdHeader check_nrrd(const std::string& path);

/// Decompresses exactly `bytes` bytes of the gzip data of `file` that starts at `offset`
/// into `dst`, never more; short, corrupt or non-gzip data is an InputError naming `name`.
/// (teem's own gzip reader leaks its stream state on corrupt data.)
void read_gzip_data(const std::string& file, std::uint64_t offset, void* dst, std::uint64_t bytes,
                    const std::string& name);

}  // namespace clfractal
