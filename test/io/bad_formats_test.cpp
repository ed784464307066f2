// Hostile DICOM, NIfTI, TIFF and MetaImage input, one row per class (as bad_input_test.cpp
// does for NRRD): each is refused before its library allocates what the header claims,
// with one line that names the file (or the directory it lies in) first, in bounded time,
// with no control character from the input, and the same way by the in-core reader
// (read_volume) and the streaming one (SliceReader). Files are the valid fixtures of
// format_fixtures.hpp (or NIfTI written by the library), cut or patched.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "clfractal/error.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/volume_io.hpp"
#include "bad_input_util.hpp"
#include "format_fixtures.hpp"

using namespace clfractal;
namespace fs = std::filesystem;
using badinput::has_control;
using badinput::refusal;

namespace {

const fs::path& root() {
    static const fs::path r = [] {
        fs::path p = fs::temp_directory_path() / ("clfractal_badformats_" + std::to_string(::getpid()));
        fs::remove_all(p);
        fs::create_directories(p);
        return p;
    }();
    return r;
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string put(const std::string& name, const std::string& bytes) {
    const fs::path p = root() / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
}

/// `bytes` with the `n` bytes after the first `pattern` replaced by `value`.
std::string patch_after(std::string bytes, const std::string& pattern, const std::string& value) {
    const std::size_t at = bytes.find(pattern);
    REQUIRE(at != std::string::npos);
    bytes.replace(at + pattern.size(), value.size(), value);
    return bytes;
}

/// `bytes` with the first `from` replaced by `to`.
std::string replace(std::string bytes, const std::string& from, const std::string& to) {
    const std::size_t at = bytes.find(from);
    REQUIRE(at != std::string::npos);
    return bytes.replace(at, from.size(), to);
}

/// `bytes` with `value` written at `offset`.
std::string set(std::string bytes, std::size_t offset, const std::string& value) {
    return bytes.replace(offset, value.size(), value);
}

template <class T> std::string le(T v) {
    std::string s(sizeof v, '\0');
    std::memcpy(s.data(), &v, sizeof v);
    return s;
}

/// An implicit-VR little-endian element (group, element, value).
std::string implicit_element(std::uint16_t group, std::uint16_t element, const std::string& value) {
    return le(group) + le(element) + le(std::uint32_t(value.size())) + value;
}
/// Overlay Rows and Columns of plane 6000.
std::string overlay(std::uint16_t rows, std::uint16_t columns) {
    return implicit_element(0x6000, 0x0010, le(rows)) + implicit_element(0x6000, 0x0011, le(columns));
}
/// A DICOM file with elements put before its pixel data (where groups 60xx belong).
std::string before_pixels(const std::string& dcm, const std::string& elements) {
    const std::size_t at = dcm.find(std::string("\xe0\x7f\x10\x00", 4));
    REQUIRE(at != std::string::npos);
    return dcm.substr(0, at) + elements + dcm.substr(at);
}

/// A valid 4x3x2 uint8 NIfTI-1 file written by the library.
std::string nifti_bytes() {
    Volume v(Dims{4, 3, 2}, ValueType::uint8, "v");
    for (std::size_t i = 0; i < v.vertices(); ++i) v.as<std::uint8_t>()[i] = std::uint8_t(i * 9);
    const std::string path = (root() / "valid.nii").string();
    write_volume(v, path);
    return slurp(path);
}

/// NIfTI-1 header fields (little endian, as written here).
std::string nifti_dims(std::string b, std::int16_t d0, std::int16_t d1, std::int16_t d2, std::int16_t d3, std::int16_t d4 = 1) {
    for (int i = 0; i < 5; ++i) {
        const std::int16_t v[5] = {d0, d1, d2, d3, d4};
        b.replace(40 + 2 * std::size_t(i), 2, le(v[i]));
    }
    return b;
}

/// One valid CT slice of 4x3 uint16 values, written by GDCM (implicit VR little endian).
std::string dicom_slice(const std::string& file, double z) {
    fixtures::DicomSlice s{file, "1.2.3.4", 4, 3, {}, z, 1.0, 0.0};
    for (std::size_t i = 0; i < 12; ++i) s.values.push_back(std::uint16_t(100 + i));
    fixtures::write_dicom(s);
    return slurp(file);
}

/// One uint8 page of 20 x `ny` (strips of 3 rows, or 16x16 tiles).
std::string tiff_file(const std::string& file, std::uint32_t ny, bool tiled, int compression) {
    std::vector<std::uint8_t> v(20 * ny);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::uint8_t(i);
    fixtures::write_tiff_pages(file, {{20, ny, 8, 1, v.data(), tiled, compression}});
    return slurp(file);
}

/// TIFF tag `tag`'s value field (the 4 bytes at 8 of its 12-byte IFD entry, little endian).
std::string tiff_patch(const std::string& bytes, std::uint16_t tag, std::uint32_t value) {
    // Entries follow the IFD's count; find "tag, type" at an entry boundary.
    std::uint32_t ifd = 0;
    std::memcpy(&ifd, bytes.data() + 4, 4);
    std::uint16_t n = 0;
    std::memcpy(&n, bytes.data() + ifd, 2);
    for (std::uint16_t i = 0; i < n; ++i) {
        const std::size_t at = ifd + 2 + 12 * std::size_t(i);
        std::uint16_t t = 0, type = 0;
        std::memcpy(&t, bytes.data() + at, 2);
        std::memcpy(&type, bytes.data() + at + 2, 2);
        if (t != tag) continue;
        return type == 3 ? set(bytes, at + 8, le(std::uint16_t(value))) : set(bytes, at + 8, le(value));  // SHORT or LONG
    }
    FAIL("tag " << tag << " not in the TIFF");
    return bytes;
}

std::string mha(const std::string& dims, const std::string& type, const std::string& extra, const std::string& data_file) {
    return "ObjectType = Image\nNDims = 3\nDimSize = " + dims + "\nElementType = " + type + "\n" + extra +
           "ElementDataFile = " + data_file + "\n";
}

}  // namespace

TEST_SUITE("badinput") {

TEST_CASE("every class of hostile DICOM, NIfTI, TIFF and MetaImage input: refused before allocation, one line") {
    ::mkfifo((root() / "fifo.img").c_str(), 0600);
    ::mkfifo((root() / "fifo.raw").c_str(), 0600);
    ::mkfifo((root() / "fifo.nii").c_str(), 0600);
    fs::create_directories(root() / "folder.raw");
    const std::string nii = nifti_bytes();
    const std::string dcm = dicom_slice((root() / "valid.dcm").string(), 0);
    const std::string rows_tag("\x28\x00\x10\x00\x02\x00\x00\x00", 8), bits_tag("\x28\x00\x00\x01\x02\x00\x00\x00", 8);
    // One strip (3 rows), so that the strip's offset and byte count are the tags' own values.
    const std::string strips = tiff_file((root() / "strips.tif").string(), 3, false, 1);
    const std::string deflate = tiff_file((root() / "deflate.tif").string(), 3, false, 8);
    const std::string tiles = tiff_file((root() / "tiles.tif").string(), 16, true, 1);
    std::string dicom_dir;  // a series of three slices and a FIFO named like a slice
    {
        const fs::path d = root() / "series_fifo";
        fs::create_directories(d);
        for (int z = 0; z < 3; ++z) dicom_slice((d / ("s" + std::to_string(z) + ".dcm")).string(), 2.0 * z);
        ::mkfifo((d / "z.dcm").c_str(), 0600);
        dicom_dir = d.string();
    }

    struct Row {
        const char* what;
        std::string path, reason;
        bool same_streamed = true;  // the streaming reader refuses when it opens the file
    };
    const std::vector<Row> rows = {
        // ---- special files named as the input
        {"FIFO as the input", (root() / "fifo.nii").string(), "not a regular file"},
        {"character device as the input", "/dev/zero", "not a regular file"},
        // ---- NIfTI
        {"NIfTI: 400 bytes claiming 2 GiB", put("claim.nii", nifti_dims(nii, 3, 2048, 1024, 1024)),
         "truncated: the NIfTI header and data (2048x1024x1024 uint8) is 2147484000 bytes, but only 376 are there"},
        {"NIfTI: gzip bomb claim", put("bomb.nii.gz", badinput::gzip(nifti_dims(nii, 3, 10000, 10000, 1000))),
         "more than"},
        {"NIfTI: absurd dimensions", put("absurd.nii", nifti_dims(nii, 3, 30000, 30000, 30000)),
         "exceed the maximum of 2^40"},
        {"NIfTI: dim[0] out of range", put("dim0.nii", nifti_dims(nii, 9, 4, 3, 2)), "dim[0] = 9; must be 1 to 7"},
        {"NIfTI: a zero axis", put("dim2.nii", nifti_dims(nii, 3, 4, 0, 2)), "dim[2] = 0"},
        {"NIfTI: 4D", put("4d.nii", nifti_dims(nii, 4, 4, 3, 2, 5)), "only 3D scalar volumes are supported"},
        {"NIfTI: RGB datatype", put("rgb.nii", set(nii, 70, le(std::int16_t(128)))),
         "is not a scalar type clfractal reads"},
        {"NIfTI: negative vox_offset", put("offset.nii", set(nii, 108, le(-352.0f))),
         "vox_offset -352.000000 is not a file offset"},
        {"NIfTI: truncated header", put("short.nii", nii.substr(0, 200)), "cannot read the NIfTI header"},
        {"NIfTI: truncated data", put("cut.nii", nii.substr(0, nii.size() - 5)), "truncated"},
        {"NIfTI: FIFO as the .img", put("fifo.hdr", nii.substr(0, 348)), "fifo.img' is not a regular file (a FIFO)"},
        {"NIfTI: missing .img", put("alone.hdr", nii.substr(0, 348)), "alone.img' does not exist"},
        // ---- DICOM
        {"DICOM: Rows claiming 60000 in a 900-byte slice", put("claim/a.dcm", patch_after(dcm, rows_tag, le(std::uint16_t(60000)))),
         "truncated: the pixel data (4x60000, 16 bits allocated) is 480000 bytes, but only 24 are there"},
        {"DICOM: BitsAllocated 64 over 16-bit data", put("bits/a.dcm", patch_after(dcm, bits_tag, le(std::uint16_t(64)))),
         "is 96 bytes, but only 24 are there"},
        {"DICOM: SamplesPerPixel 5 (GDCM asserts on it)",
         put("spp/a.dcm", patch_after(dcm, std::string("\x28\x00\x02\x00\x02\x00\x00\x00", 8), le(std::uint16_t(5)))),
         "5 samples per pixel; only greyscale DICOM is supported"},
        // The Study Time element (0008,0030) renamed 0008,0010: a Recognition Code holding a
        // time, not an ACR-NEMA code.
        {"DICOM: a Recognition Code that is not ACR-NEMA's (GDCM asserts on it)",
         put("recognition/a.dcm", replace(dcm, std::string("\x08\x00\x30\x00", 4), std::string("\x08\x00\x10\x00", 4))),
         "a Recognition Code (0008,0010) that is not ACR-NEMA's"},
        // GDCM asserts on an overlay attribute it does not know, on a plane without its data and
        // on curves.
        {"DICOM: an overlay with Overlay Activation Layer (60xx,1001)",
         put("overlay1001/a.dcm", before_pixels(dcm, overlay(3, 4) + implicit_element(0x6000, 0x1001, "1 ") +
                                                         implicit_element(0x6000, 0x3000, std::string(2, '\xff')))),
         "an overlay plane, group 60xx, without its Overlay Data or with attributes GDCM does not read"},
        {"DICOM: an overlay in the pixel data's unused bits (retired)",
         put("overlaybits/a.dcm", before_pixels(dcm, overlay(3, 4) + implicit_element(0x6000, 0x0100, le(std::uint16_t(16))))),
         "an overlay plane, group 60xx, without its Overlay Data"},
        {"DICOM: a curve (50xx, retired; GDCM asserts when it counts its groups otherwise than it reads them)",
         put("curve/a.dcm", before_pixels(dcm, implicit_element(0x5000, 0x3000, std::string(4, '\0')) +
                                                   implicit_element(0x5002, 0x0005, le(std::uint16_t(2))))),
         "a curve, group 50xx"},
        {"DICOM: BitsAllocated 0", put("bits0/a.dcm", patch_after(dcm, bits_tag, le(std::uint16_t(0)))),
         "BitsAllocated 0.000000 is not 1 to 64"},
        {"DICOM: cut in the pixel data", put("cut/a.dcm", dcm.substr(0, dcm.size() - 7)), "truncated DICOM file"},
        {"DICOM: not DICOM at all", put("text/a.dcm", "hello\x1b]0;x\x07\n"), "not a readable DICOM file"},
        // GDCM guesses the encoding of a file whose meta information does not come first: a
        // 900-byte file of this kind made its scanner allocate 0.8 GB for 2 s.
        {"DICOM: the meta information not first", put("meta/a.dcm", set(dcm, 132, std::string("\x28\x00", 2))),
         "the file meta information, group 0002 with the transfer syntax, must come first"},
        {"DICOM: a sequence in the meta information (GDCM asserts on it)",
         put("metasq/a.dcm", patch_after(dcm, std::string("\x02\x00\x01\x00", 4), "SQ")),
         "must come first and hold no sequences"},
        {"DICOM: PALETTE COLOR (GDCM asserts without its lookup tables)",
         put("palette/a.dcm", replace(dcm, std::string("\x28\x00\x04\x00\x0c\x00\x00\x00MONOCHROME2 ", 20),
                                      std::string("\x28\x00\x04\x00\x0e\x00\x00\x00PALETTE COLOR ", 22))),
         "PhotometricInterpretation 'PALETTE COLOR'; only greyscale"},
        // ---- TIFF
        {"TIFF: width claiming 60000 from an uncompressed strip (libtiff sizes the strip by the page)", put("wide.tif", tiff_patch(strips, 256, 60000)),
         "strip 0 (60000 bytes at 8) lies past the end of the file"},
        {"TIFF: a deflate strip claiming 65535 x 3", put("bomb.tif", tiff_patch(deflate, 256, 65535)),
         "can expand to (at most 1032:1)"},
        {"TIFF: strip past the end of the file", put("offset.tif", tiff_patch(strips, 273, 1u << 30)),
         "lies past the end of the file"},
        {"TIFF: tiles larger than the page", put("tile.tif", tiff_patch(tiles, 322, 48)),
         "tiles of 48x16 for a page of 20x16"},
        {"TIFF: cut", put("cut.tif", strips.substr(0, 100)), "cannot read TIFF"},
        // ---- MetaImage
        {"MetaImage: 8 bytes claiming 1 GB", put("claim.mha", mha("1000 1000 1000", "MET_UCHAR", "", "LOCAL") + "12345678"),
         "truncated: the MetaImage data (1000x1000x1000 uint8) is 1000000000 bytes, but only 8 are there"},
        {"MetaImage: zlib bomb claim", put("bomb.mha", mha("10000 10000 10000", "MET_UCHAR", "CompressedData = True\n", "LOCAL") +
                                                           badinput::gzip(std::string(64, '\0'), 15)),
         "can expand to (at most 1032:1)"},
        {"MetaImage: absurd DimSize", put("absurd.mha", mha("100000 100000 100000", "MET_UCHAR", "", "LOCAL")),
         "exceed the maximum of 2^40"},
        {"MetaImage: HeaderSize 1e300", put("skip.mha", mha("2 2 2", "MET_UCHAR", "HeaderSize = 1e300\n", "LOCAL") + "12345678"),
         "HeaderSize '1e300' is not a byte count"},
        {"MetaImage: FIFO as the data file", put("fifo.mhd", mha("2 2 2", "MET_UCHAR", "", "fifo.raw")),
         "data file '" + (root() / "fifo.raw").string() + "' is not a regular file (a FIFO)"},
        {"MetaImage: folder as the data file", put("folder.mhd", mha("2 2 2", "MET_UCHAR", "", "folder.raw")),
         "is not a regular file (a directory)"},
        {"MetaImage: missing data file", put("missing.mhd", mha("2 2 2", "MET_UCHAR", "", "nope.raw")), "nope.raw' does not exist"},
        {"MetaImage: 4 dimensions", put("ndims.mha", "ObjectType = Image\nNDims = 4\nElementDataFile = LOCAL\n"),
         "only 3D volumes are supported"},
        {"MetaImage: control characters in a value",
         put("ctl.mha", mha("2 2 2", "MET_\x1b]0;owned\x07", "", "LOCAL") + "12345678"), "ElementType 'MET_?]0;owned?'"},
        {"MetaImage: no ElementDataFile in 64 KiB", put("endless.mha", std::string(70000, '\n')), "no ElementDataFile"},
    };
    for (const Row& row : rows) {
        CAPTURE(row.what);
        const auto t0 = std::chrono::steady_clock::now();
        const std::string core = refusal([&] { read_volume(row.path); });
        const std::string stream = refusal([&] { SliceReader r(row.path); });
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        CHECK_MESSAGE(core.find(row.reason) != std::string::npos, core);
        CHECK_MESSAGE(core.rfind(printable(row.path), 0) == 0, core);  // names the file first
        CHECK(core.find('\n') == std::string::npos);
        CHECK_FALSE(has_control(core));
        if (row.same_streamed) CHECK(stream == core);
        CHECK(seconds < 2.0);
    }

    // Describing a FIFO (clfractal info) refuses it too, without opening it (it would block).
    CHECK(refusal([&] { describe_volume_file((root() / "fifo.nii").string()); }).find("not a regular file") !=
          std::string::npos);

    // An overlay plane with its Overlay Data, in two groups, still reads.
    {
        const std::string planes = overlay(3, 4) + implicit_element(0x6000, 0x0040, "G ") +
                                   implicit_element(0x6000, 0x3000, std::string(2, '\xff')) +
                                   implicit_element(0x6002, 0x0010, le(std::uint16_t(3))) +
                                   implicit_element(0x6002, 0x0011, le(std::uint16_t(4))) +
                                   implicit_element(0x6002, 0x3000, std::string(2, '\x01'));
        const Volume o = read_volume(put("overlay/a.dcm", before_pixels(dcm, planes)));
        CHECK(o.value(11) == 111);
    }
    // A DICOM file with an ACR-NEMA Recognition Code (as some scanners write) still reads.
    {
        const std::string tag("\x08\x00\x30\x00", 4);
        const std::size_t at = dcm.find(tag);
        REQUIRE(at != std::string::npos);
        std::uint32_t length = 0;
        std::memcpy(&length, dcm.data() + at + 4, 4);
        REQUIRE(length >= 12);
        std::string acr = set(dcm, at, std::string("\x08\x00\x10\x00", 4));
        acr = set(acr, at + 8, ("ACR-NEMA 2.0" + std::string(length - 12, ' ')));
        const Volume a = read_volume(put("acr_nema/a.dcm", acr));
        CHECK(a.dims().nx == 4);
        CHECK(a.value(11) == 111);
    }

    // A FIFO among a series' files is passed over, not opened (it would block): the series reads.
    const Volume v = read_volume(dicom_dir);
    CHECK(v.dims().nz == 3);
    CHECK(v.value(0) == 100);
}

}  // TEST_SUITE
