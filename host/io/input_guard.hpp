// Bounds on what the format readers (DICOM, NIfTI, TIFF, MetaImage) hand to their libraries
// (private to the library). As for NRRD (nrrd_guard.hpp): only regular files are opened,
// and the data a header claims is checked against the bytes that must hold it before
// anything that size is allocated: at least as many bytes for uncompressed data, and for
// compressed data no more than the codec's largest expansion of the compressed bytes.
#pragma once
#include <cstdint>
#include <string>

namespace clfractal::io {

/// Largest expansions (decoded : encoded bytes) the checks allow.
struct ExpansionLimits {
    static constexpr std::uint64_t deflate = 1032;    ///< zlib/gzip (deflate's own maximum)
    static constexpr std::uint64_t lzw = 3641;        ///< 12-bit LZW: 4096 bytes per 9-bit code at most
    static constexpr std::uint64_t packbits = 64;     ///< 2 bytes for a run of 128
    static constexpr std::uint64_t jpeg = 512;        ///< 2 bits per 8x8 block of 16-bit samples at best
    static constexpr std::uint64_t other = 1u << 15;  ///< codecs without a small bound (zstd, LZMA, JPEG 2000, ...)
};

/// The size of `file`, which must be a regular file (a FIFO would block the reader, a
/// device never ends); otherwise an InputError "<file>: not a regular file (a FIFO)" or
/// "<file>: no such file", or for a file another names, "<name>: data file '<file>' is
/// not a regular file (a FIFO)". `name` is the input the user gave (the file itself, or the
/// header that refers to it).
std::uint64_t regular_file_size(const std::string& file, const std::string& name);

/// Checks that `claimed` decoded bytes can come from `available` bytes of data expanding
/// at most `ratio`:1 (ratio 1: uncompressed, the bytes must be there); otherwise an
/// InputError "<name>: truncated: <layout> is N bytes, but only M are there (<what>)" or
/// "<name>: <layout> is N bytes, more than M compressed bytes (<what>) can expand to".
void check_claim(const std::string& name, const std::string& what, const std::string& layout, std::uint64_t claimed,
                 std::uint64_t available, std::uint64_t ratio);

/// `text` cut to `keep` characters, control characters replaced, in quotes: input quoted in
/// a message.
std::string quote_input(const std::string& text, std::size_t keep = 60);

}  // namespace clfractal::io
