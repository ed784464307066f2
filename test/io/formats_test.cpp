// File formats: fixtures written at test time by the libraries that own the formats (GDCM,
// nifticlib, libtiff; MetaImage by hand, checked field by field), read back through
// read_volume and SliceReader and compared value for value with the arrays that made them;
// span counts on them equal the reference. Real files of ../shared/data/formats must
// decode byte for byte to their reference .raw files.
#include <doctest/doctest.h>

#include <gdcmAttribute.h>
#include <gdcmImageChangeTransferSyntax.h>
#include <gdcmImageReader.h>
#include <gdcmImageWriter.h>
#include <gdcmWriter.h>
#include <nifti2_io.h>
#include <tiffio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <vector>

#include "clfractal/slice_reader.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"
#include "format_fixtures.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;
using fixtures::DicomSlice;
using fixtures::TiffPage;
using fixtures::write_dicom;
using fixtures::write_tiff_pages;
namespace fs = std::filesystem;

namespace {

/// A fresh directory under the build tree's temp area, removed at the end of the test.
struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name) {
        path = fs::temp_directory_path() / ("clfractal_formats_" + std::to_string(::getpid()) + "_" + name);
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    std::string operator/(const std::string& f) const { return (path / f).string(); }
};

template <class T> std::vector<T> random_values(std::size_t n, long lo, long hi, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<long> d(lo, hi);
    std::vector<T> v(n);
    for (T& x : v) x = T(d(rng));
    return v;
}

/// The span counts of the device equal the reference's, levels 0 and 1, cubes and edges.
void check_counts(const Volume& v) {
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    const SpanResult r = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 2, 0});
    for (int l = 0; l < 2; ++l) {
        const Volume lv = ref::level(v, l);
        CHECK(r.get(SpanKind::cubes).counts[l] == ref::cubes_brute(lv, iso));
        CHECK(r.get(SpanKind::edges).counts[l] == ref::edges_brute(lv, iso));
    }
}

template <class T> void check_values(const Volume& v, const std::vector<T>& expected) {
    REQUIRE(v.type() == value_type_of<T>::value);
    REQUIRE(v.vertices() == expected.size());
    CHECK(std::memcmp(v.data(), expected.data(), expected.size() * sizeof(T)) == 0);
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

/// A series of nz slices (stored uint16 values 0..max), written in shuffled file order;
/// returns the stored values in z order.
std::vector<std::uint16_t> write_series(const TempDir& dir, const std::string& uid, std::size_t nx, std::size_t ny,
                                        std::size_t nz, long max, double slope, double intercept, std::uint32_t seed,
                                        const std::string& prefix = "img") {
    const std::vector<std::uint16_t> all = random_values<std::uint16_t>(nx * ny * nz, 0, max, seed);
    std::vector<std::size_t> order(nz);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::mt19937(seed + 1));
    for (std::size_t k = 0; k < nz; ++k) {
        const std::size_t z = order[k];
        DicomSlice s{dir / (prefix + std::to_string(k) + ".dcm"), uid, nx, ny, {}, 100.0 + 2.5 * double(z), slope,
                     intercept};
        s.values.assign(all.begin() + std::ptrdiff_t(z * nx * ny), all.begin() + std::ptrdiff_t((z + 1) * nx * ny));
        write_dicom(s);
    }
    return all;
}

// ---------------------------------------------------------------- NIfTI (nifticlib writes)

void write_nifti_file(const std::string& path, int datatype, void* data, std::size_t nx, std::size_t ny,
                      std::size_t nz, double slope = 0, double inter = 0) {
    const int64_t dims[8] = {3, int64_t(nx), int64_t(ny), int64_t(nz), 1, 1, 1, 1};
    nifti_image* nim = nifti_make_new_nim(dims, datatype, 0);
    REQUIRE(nim);
    nim->dx = nim->pixdim[1] = 0.5;
    nim->dy = nim->pixdim[2] = 0.7;
    nim->dz = nim->pixdim[3] = 1.5;
    nim->scl_slope = slope;
    nim->scl_inter = inter;
    nim->data = data;
    REQUIRE(nifti_set_filenames(nim, path.c_str(), 0, 1) == 0);
    nifti_image_write(nim);
    nim->data = nullptr;
    nifti_image_free(nim);
}

void write_text(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

}  // namespace

TEST_SUITE("formats") {

TEST_CASE("DICOM series by GDCM: shuffled files, rescale to int16, spacing, orientation, counts, streaming") {
    TempDir dir("dicom");
    const std::size_t nx = 13, ny = 11, nz = 7;
    const std::vector<std::uint16_t> stored = write_series(dir, "1.2.3.4.5", nx, ny, nz, 3000, 1, -1024, 7);
    write_text(dir / "README.txt", "not DICOM: ignored\n");
    std::vector<std::int16_t> hu(stored.size());
    for (std::size_t i = 0; i < hu.size(); ++i) hu[i] = std::int16_t(int(stored[i]) - 1024);

    const Volume v = read_volume(dir.path.string());
    CHECK(v.dims() == Dims{nx, ny, nz});
    check_values(v, hu);
    CHECK(v.spacing[0] == doctest::Approx(0.75));
    CHECK(v.spacing[1] == doctest::Approx(0.5));
    CHECK(v.spacing[2] == doctest::Approx(2.5));
    CHECK(v.oriented);
    CHECK(v.origin[2] == doctest::Approx(100.0));
    check_counts(v);

    // One file of the series names the whole series.
    const Volume one = read_volume(dir / "img3.dcm");
    check_values(one, hu);

    // Streaming: slice by slice, the same values.
    SliceReader reader(dir.path.string());
    CHECK(std::string(reader.method()) == "dicom");
    CHECK(reader.type() == ValueType::int16);
    std::vector<std::int16_t> streamed(hu.size());
    for (std::size_t z = 0; z < nz; ++z) reader.read(&streamed[z * nx * ny], 1);
    CHECK(streamed == hu);

    // NIfTI and NRRD written from it keep spacing and orientation.
    for (const char* name : {"out.nii.gz", "out.nrrd"}) {
        CAPTURE(name);
        write_volume(v, dir / name);
        const Volume back = read_volume(dir / name);
        check_values(back, hu);
        CHECK(back.oriented);
        for (int a = 0; a < 3; ++a) {
            CHECK(back.spacing[a] == doctest::Approx(v.spacing[a]));
            CHECK(back.origin[a] == doctest::Approx(v.origin[a]));
            for (int r = 0; r < 3; ++r) CHECK(back.axes[a][r] == doctest::Approx(v.axes[a][r]));
        }
    }
}

TEST_CASE("DICOM compressed transfer syntaxes that GDCM decodes: JPEG lossless, RLE") {
    for (const gdcm::TransferSyntax::TSType ts :
         {gdcm::TransferSyntax::JPEGLosslessProcess14_1, gdcm::TransferSyntax::RLELossless}) {
        CAPTURE(gdcm::TransferSyntax::GetTSString(ts));
        TempDir dir("dicom_ts");
        const std::vector<std::uint16_t> stored = write_series(dir, "1.2.3.40", 10, 9, 5, 4000, 1, -1024, 17);
        for (const auto& e : fs::directory_iterator(dir.path)) {
            gdcm::ImageReader r;
            r.SetFileName(e.path().c_str());
            REQUIRE(r.Read());
            gdcm::ImageChangeTransferSyntax change;
            change.SetTransferSyntax(ts);
            change.SetInput(r.GetImage());
            REQUIRE(change.Change());
            gdcm::ImageWriter w;
            w.SetFile(r.GetFile());
            w.SetImage(change.GetOutput());
            w.SetFileName(e.path().c_str());
            REQUIRE(w.Write());
        }
        std::vector<std::int16_t> hu(stored.size());
        for (std::size_t i = 0; i < hu.size(); ++i) hu[i] = std::int16_t(int(stored[i]) - 1024);
        check_values(read_volume(dir.path.string()), hu);
    }
}

TEST_CASE("DICOM rescale rule: stored type kept, float32 for a fractional slope, int32 not yet") {
    SUBCASE("intercept 0: uint16 kept") {
        TempDir dir("dicom_u16");
        const auto stored = write_series(dir, "1.2.3.6", 9, 8, 4, 60000, 1, 0, 11);
        check_values(read_volume(dir.path.string()), stored);
    }
    SUBCASE("slope 0.5, intercept 10: float32") {
        TempDir dir("dicom_f32");
        const auto stored = write_series(dir, "1.2.3.7", 9, 8, 4, 4000, 0.5, 10, 12);
        std::vector<float> expected(stored.size());
        for (std::size_t i = 0; i < stored.size(); ++i) expected[i] = float(double(stored[i]) * 0.5 + 10);
        const Volume v = read_volume(dir.path.string());
        check_values(v, expected);
        check_counts(v);
    }
    SUBCASE("uint16 up to 60000 with intercept -1024 needs int32") {
        TempDir dir("dicom_i32");
        const auto stored = write_series(dir, "1.2.3.8", 9, 8, 4, 60000, 1, -1024, 13);
        std::vector<std::int32_t> expected(stored.size());
        for (std::size_t i = 0; i < stored.size(); ++i) expected[i] = std::int32_t(stored[i]) - 1024;
        const Volume v = read_volume(dir.path.string());
        CHECK(v.type() == ValueType::int32);
        check_values(v, expected);
        check_counts(v);
    }
}

TEST_CASE("DICOM bad folders: a missing slice, mixed series, a non-image file") {
    SUBCASE("missing slice names the gap") {
        TempDir dir("dicom_gap");
        const std::size_t nx = 6, ny = 5;
        for (int z : {0, 1, 2, 4, 5}) {
            DicomSlice s{dir / ("s" + std::to_string(z) + ".dcm"), "1.2.9", nx, ny,
                         random_values<std::uint16_t>(nx * ny, 0, 100, z), 2.0 * z};
            write_dicom(s);
        }
        const std::string e = error_of([&] { read_volume(dir.path.string()); });
        CHECK(e.find("uneven slice spacing: 4 between s2.dcm (at 4) and s4.dcm (at 8)") != std::string::npos);
        CHECK(e.find("1 slice(s) missing") != std::string::npos);
    }
    SUBCASE("two series: the larger one, or --series; a tie is an error") {
        TempDir dir("dicom_mixed");
        const auto a = write_series(dir, "1.2.10", 5, 4, 3, 500, 1, 0, 21, "a");
        const auto b = write_series(dir, "1.2.11", 5, 4, 4, 500, 1, 0, 22, "b");
        check_values(read_volume(dir.path.string()), b);
        RawOptions o;
        o.series = "1.2.10";
        check_values(read_volume(dir.path.string(), o), a);
        o.series = "9.9";
        CHECK(error_of([&] { read_volume(dir.path.string(), o); }).find("no DICOM series with UID 9.9") !=
              std::string::npos);
        write_series(dir, "1.2.12", 5, 4, 4, 500, 1, 0, 23, "c");
        CHECK(error_of([&] { read_volume(dir.path.string()); }).find("choose one with --series UID") !=
              std::string::npos);
    }
    SUBCASE("a .dcm that is not DICOM, and a DICOM file without pixel data") {
        TempDir dir("dicom_nonimage");
        write_series(dir, "1.2.13", 5, 4, 3, 500, 1, 0, 24);
        write_text(dir / "notes.dcm", "just text");
        CHECK(error_of([&] { read_volume(dir.path.string()); }) == dir / "notes.dcm" + ": not a readable DICOM file (no DICOM Part 10 \"DICM\" preamble)");
        fs::remove(dir / "notes.dcm");
        // A DICOM object of the series without pixel data (a report, say).
        gdcm::Writer w;
        gdcm::DataSet& ds = w.GetFile().GetDataSet();
        gdcm::Attribute<0x0008, 0x0016> sop_class = {"1.2.840.10008.5.1.4.1.1.88.11"};
        gdcm::Attribute<0x0008, 0x0018> sop = {"1.2.13.99"};
        gdcm::Attribute<0x0020, 0x000e> series = {"1.2.13"};
        gdcm::Attribute<0x0020, 0x0032> ipp = {{-20.0, 10.0, 107.5}};
        gdcm::Attribute<0x0020, 0x0037> iop = {{1, 0, 0, 0, 1, 0}};
        for (const gdcm::DataElement& de : {sop_class.GetAsDataElement(), sop.GetAsDataElement(),
                                            series.GetAsDataElement(), ipp.GetAsDataElement(), iop.GetAsDataElement()})
            ds.Insert(de);
        w.GetFile().GetHeader().SetDataSetTransferSyntax(gdcm::TransferSyntax::ExplicitVRLittleEndian);
        w.SetFileName((dir / "report.dcm").c_str());
        REQUIRE(w.Write());
        const std::string e = error_of([&] { read_volume(dir.path.string()); });
        CHECK(e.find("report.dcm") != std::string::npos);
    }
}

TEST_CASE("NIfTI by nifticlib: .nii.gz, .nii, .hdr/.img; scl_slope only under --scaled") {
    TempDir dir("nifti");
    const std::size_t nx = 12, ny = 7, nz = 9;
    auto i16 = random_values<std::int16_t>(nx * ny * nz, -300, 300, 31);
    auto u8 = random_values<std::uint8_t>(nx * ny * nz, 0, 255, 32);
    auto f32 = random_values<float>(nx * ny * nz, -50, 50, 33);
    for (float& x : f32) x /= 4;
    write_nifti_file(dir / "a.nii.gz", DT_INT16, i16.data(), nx, ny, nz);
    write_nifti_file(dir / "b.hdr", DT_UINT8, u8.data(), nx, ny, nz);
    write_nifti_file(dir / "c.nii", DT_FLOAT32, f32.data(), nx, ny, nz);
    const Volume a = read_volume(dir / "a.nii.gz");
    check_values(a, i16);
    CHECK(a.spacing[0] == 0.5);
    CHECK(a.spacing[1] == doctest::Approx(0.7));  // pixdim is float32 in NIfTI-1
    CHECK(a.spacing[2] == 1.5);
    check_counts(a);
    check_values(read_volume(dir / "b.hdr"), u8);
    check_values(read_volume(dir / "b.img"), u8);
    const Volume c = read_volume(dir / "c.nii");
    check_values(c, f32);
    check_counts(c);

    // NIfTI-2 (540-byte header, made by nifticlib).
    {
        const int64_t dims[8] = {3, int64_t(nx), int64_t(ny), int64_t(nz), 1, 1, 1, 1};
        nifti_2_header* h = nifti_make_new_n2_header(dims, DT_INT16);
        REQUIRE(h);
        h->vox_offset = 544;
        std::memcpy(h->magic, "n+2\0\r\n\032\n", 8);
        std::string file(reinterpret_cast<const char*>(h), 540);
        std::free(h);
        file += std::string(4, '\0') + std::string(reinterpret_cast<const char*>(i16.data()), i16.size() * 2);
        gzFile g = gzopen((dir / "n2.nii.gz").c_str(), "wb");
        REQUIRE(gzwrite(g, file.data(), unsigned(file.size())) == int(file.size()));
        gzclose(g);
    }
    check_values(read_volume(dir / "n2.nii.gz"), i16);
    CHECK(describe_volume_file(dir / "n2.nii.gz")[1].find("NIfTI-2, stored INT16") != std::string::npos);
    // The writer uses NIfTI-2 where an axis exceeds 32767 vertices.
    Volume wide(Dims{40000, 2, 2}, ValueType::uint8);
    for (std::size_t i = 0; i < wide.vertices(); ++i) static_cast<std::uint8_t*>(wide.data())[i] = std::uint8_t(i % 251);
    write_volume(wide, dir / "wide.nii.gz");
    const Volume wide_back = read_volume(dir / "wide.nii.gz");
    CHECK(wide_back.dims() == wide.dims());
    CHECK(std::memcmp(wide_back.data(), wide.data(), wide.size_bytes()) == 0);
    CHECK(describe_volume_file(dir / "wide.nii.gz")[1].find("NIfTI-2") != std::string::npos);

    // A .raw file is raw data whatever its first bytes look like.
    std::string tiff_like = "II*";
    tiff_like += std::string(4 * 4 * 4 - 3, '\0');
    write_text(dir / "looks_4x4x4_uint8.raw", tiff_like);
    CHECK(read_volume(dir / "looks_4x4x4_uint8.raw").value(0) == 'I');

    // Found by content, whatever the name.
    fs::copy_file(dir / "a.nii.gz", dir / "scan.data");
    check_values(read_volume(dir / "scan.data"), i16);

    // Scaling: stored by default; slope 1 + integer intercept stays integer; else float32.
    write_nifti_file(dir / "s1.nii", DT_UINT8, u8.data(), nx, ny, nz, 1, -100);
    write_nifti_file(dir / "s2.nii", DT_INT16, i16.data(), nx, ny, nz, 0.5, 3);
    check_values(read_volume(dir / "s1.nii"), u8);
    RawOptions scaled;
    scaled.scaled = true;
    std::vector<std::int16_t> s1(u8.size());
    for (std::size_t i = 0; i < u8.size(); ++i) s1[i] = std::int16_t(u8[i] - 100);
    check_values(read_volume(dir / "s1.nii", scaled), s1);
    std::vector<float> s2(i16.size());
    for (std::size_t i = 0; i < i16.size(); ++i) s2[i] = float(double(i16[i]) * 0.5 + 3);
    check_values(read_volume(dir / "s2.nii", scaled), s2);

    // int32 and float64 are read as they are stored.
    auto i32 = random_values<std::int32_t>(nx * ny * nz, -100000, 100000, 34);
    write_nifti_file(dir / "i32.nii", DT_INT32, i32.data(), nx, ny, nz);
    check_values(read_volume(dir / "i32.nii"), i32);
    auto f64 = random_values<double>(nx * ny * nz, -5, 5, 35);
    for (double& x : f64) x += 1e-12;  // below float32 precision
    write_nifti_file(dir / "f64.nii", DT_FLOAT64, f64.data(), nx, ny, nz);
    check_values(read_volume(dir / "f64.nii"), f64);

    // NaN and Inf are kept (nifticlib's loader alone makes them 0) and refused by counting
    // with the one-line error every reader gives (check_finite).
    std::vector<float> fn(nx * ny * nz, 1.5f);
    fn[3] = NAN, fn[10] = INFINITY, fn[11] = -INFINITY;
    std::vector<double> dn(fn.begin(), fn.end());
    write_nifti_file(dir / "nan32.nii", DT_FLOAT32, fn.data(), nx, ny, nz);
    write_nifti_file(dir / "nan64.nii.gz", DT_FLOAT64, dn.data(), nx, ny, nz);
    for (const char* name : {"nan32.nii", "nan64.nii.gz"}) {
        const Volume k = read_volume(dir / name, {}, FiniteCheck::keep);
        const std::vector<double> got = visit_type(k.type(), [&](auto zero) {
            const auto* d = static_cast<const decltype(zero)*>(k.data());
            return std::vector<double>(d, d + k.vertices());
        });
        CHECK(std::isnan(got[3]));
        CHECK(got[10] == INFINITY);
        CHECK(got[11] == -INFINITY);
        CHECK(got[0] == 1.5);
        const std::string e = error_of([&] { read_volume(dir / name); });
        CHECK(e.find("1 NaN and 2 infinite values") != std::string::npos);
    }

    // Truncated gzip: one line naming the file.
    std::ifstream in(dir / "a.nii.gz", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    write_text(dir / "cut.nii.gz", bytes.substr(0, bytes.size() / 2));
    const std::string e = error_of([&] { read_volume(dir / "cut.nii.gz"); });
    CHECK(e.rfind(dir / "cut.nii.gz" + ": ", 0) == 0);
    CHECK(e.find('\n') == std::string::npos);

    // The NIfTI writer, plain and gzip: values and spacing back.
    write_volume(a, dir / "w.nii");
    write_volume(c, dir / "w.nii.gz");
    const Volume wa = read_volume(dir / "w.nii");
    check_values(wa, i16);
    CHECK(wa.spacing == a.spacing);
    check_values(read_volume(dir / "w.nii.gz"), f32);
}

TEST_CASE("TIFF by libtiff: multi-page strips with LZW, a directory of tiled deflate slices, float32") {
    TempDir dir("tiff");
    const std::uint32_t nx = 21, ny = 18;
    const std::size_t nz = 5, plane = std::size_t(nx) * ny;
    const auto u16 = random_values<std::uint16_t>(plane * nz, 0, 4000, 41);
    std::vector<TiffPage> pages;
    for (std::size_t z = 0; z < nz; ++z)
        pages.push_back({nx, ny, 16, SAMPLEFORMAT_UINT, &u16[z * plane], false, COMPRESSION_LZW});
    write_tiff_pages(dir / "stack.tif", pages);
    const Volume v = read_volume(dir / "stack.tif");
    check_values(v, u16);
    check_counts(v);

    // Slices named so that text order differs from natural order.
    TempDir slices("tiff_dir");
    const auto u8 = random_values<std::uint8_t>(plane * 11, 0, 255, 42);
    for (std::size_t z = 0; z < 11; ++z)
        write_tiff_pages(slices / ("slice" + std::to_string(z + 1) + ".tif"),
                         {{nx, ny, 8, SAMPLEFORMAT_UINT, &u8[z * plane], true, COMPRESSION_ADOBE_DEFLATE}});
    write_text(slices / "notes.txt", "ignored");
    const Volume d = read_volume(slices.path.string());
    check_values(d, u8);
    check_counts(d);
    SliceReader reader(slices.path.string());
    CHECK(std::string(reader.method()) == "tiff");
    std::vector<std::uint8_t> streamed(u8.size());
    reader.read(streamed.data(), 11);
    CHECK(streamed == u8);

    auto f32 = random_values<float>(plane * 3, -100, 100, 43);
    std::vector<TiffPage> fpages;
    for (std::size_t z = 0; z < 3; ++z) fpages.push_back({nx, ny, 32, SAMPLEFORMAT_IEEEFP, &f32[z * plane]});
    write_tiff_pages(dir / "float.tiff", fpages);
    check_values(read_volume(dir / "float.tiff"), f32);

    // Slices that differ in size or type: one line naming the file.
    write_tiff_pages(slices / "slice12.tif", {{nx, ny - 1, 8, SAMPLEFORMAT_UINT, &u8[0]}});
    CHECK(error_of([&] { read_volume(slices.path.string()); }) ==
          slices / "slice12.tif" + ": slice is 21x17 uint8, but slice1.tif is 21x18 uint8; every slice must match");
    write_tiff_pages(slices / "slice12.tif", {{nx, ny, 16, SAMPLEFORMAT_UINT, &u16[0]}});
    CHECK(error_of([&] { read_volume(slices.path.string()); }) ==
          slices / "slice12.tif" + ": slice is 21x18 uint16, but slice1.tif is 21x18 uint8; every slice must match");
}

TEST_CASE("MetaImage: LOCAL raw, .mhd + .raw big-endian, zlib CompressedData; a missing data file") {
    TempDir dir("meta");
    const std::size_t nx = 6, ny = 5, nz = 4, n = nx * ny * nz;
    const auto i16 = random_values<std::int16_t>(n, -1000, 1000, 51);
    const std::string header = "ObjectType = Image\nNDims = 3\nDimSize = 6 5 4\nElementType = MET_SHORT\n"
                               "ElementSpacing = 0.5 0.25 2\nOffset = 1 2 3\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n";
    const std::string raw(reinterpret_cast<const char*>(i16.data()), n * 2);
    write_text(dir / "a.mha", header + "BinaryDataByteOrderMSB = False\nElementDataFile = LOCAL\n" + raw);
    const Volume a = read_volume(dir / "a.mha");
    check_values(a, i16);
    CHECK(a.spacing == std::array<double, 3>{0.5, 0.25, 2});
    CHECK(a.origin == std::array<double, 3>{1, 2, 3});
    check_counts(a);

    std::string swapped = raw;
    for (std::size_t i = 0; i < n; ++i) std::swap(swapped[2 * i], swapped[2 * i + 1]);
    write_text(dir / "b.raw", swapped);
    write_text(dir / "b.mhd", header + "BinaryDataByteOrderMSB = True\nElementDataFile = b.raw\n");
    check_values(read_volume(dir / "b.mhd"), i16);

    std::vector<unsigned char> z(compressBound(uLong(raw.size())));
    uLongf zn = uLongf(z.size());
    REQUIRE(compress2(z.data(), &zn, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 6) == Z_OK);
    const std::string zdata(reinterpret_cast<const char*>(z.data()), zn);
    write_text(dir / "c.mha", header + "CompressedData = True\nCompressedDataSize = " + std::to_string(zn) +
                                  "\nElementDataFile = LOCAL\n" + zdata);
    check_values(read_volume(dir / "c.mha"), i16);
    write_text(dir / "d.zraw", zdata);
    write_text(dir / "d.mhd", header + "CompressedData = True\nElementDataFile = d.zraw\n");
    check_values(read_volume(dir / "d.mhd"), i16);
    write_text(dir / "cut.mha", header + "CompressedData = True\nElementDataFile = LOCAL\n" + zdata.substr(0, zn / 2));
    CHECK(error_of([&] { read_volume(dir / "cut.mha"); }).rfind(dir / "cut.mha" + ": MetaImage compressed data", 0) == 0);

    write_text(dir / "missing.mhd", header + "ElementDataFile = gone.raw\n");
    CHECK(error_of([&] { read_volume(dir / "missing.mhd"); }) ==
          dir / "missing.mhd" + ": data file '" + dir / "gone.raw" + "' does not exist");
}

}  // TEST_SUITE("formats")

TEST_SUITE("realdata") {

TEST_CASE("real DICOM, NIfTI and MetaImage files decode byte for byte to their reference .raw") {
    const std::string data = testutil::shared_data();
    if (data.empty() || !fs::exists(data + "/formats/README.md")) {
        MESSAGE("../shared/data/formats is absent: real-format checks skipped");
        return;
    }
    const std::string f = data + "/formats/";
    const std::pair<std::string, std::string> cases[] = {
        {f + "dicom_ct_phantom", f + "dicom_ct_phantom_512x512x28_int16.raw"},
        {f + "dicom_ct_phantom/I150", f + "dicom_ct_phantom_512x512x28_int16.raw"},
        {f + "3DCT_lung_baseline_small.mha", f + "3DCT_lung_baseline_small_57x78x64_int16.raw"},
        {f + "avg152T1_RL_nifti.nii.gz", data + "/mni_avg152t1_91x109x91_uint8.raw"},
        {f + "engine.nii.gz", data + "/engine_256x256x128_uint8.raw"},
    };
    for (const auto& [file, reference] : cases) {
        CAPTURE(file);
        const Volume v = read_volume(file);
        const Volume r = read_raw(reference);
        REQUIRE(v.dims() == r.dims());
        REQUIRE(v.type() == r.type());
        CHECK(std::memcmp(v.data(), r.data(), v.size_bytes()) == 0);
    }
    const Volume ct = read_volume(f + "dicom_ct_phantom");
    CHECK(ct.spacing[0] == doctest::Approx(0.451171875));
    CHECK(ct.spacing[2] == doctest::Approx(5.0));
    CHECK(ct.origin[2] == doctest::Approx(696.21));
    const Volume lung = read_volume(f + "3DCT_lung_baseline_small.mha");
    CHECK(lung.spacing == std::array<double, 3>{2.732, 2.732, 5});

    // Streamed slice by slice: the same bytes.
    SliceReader reader(f + "dicom_ct_phantom");
    CHECK(std::string(reader.method()) == "dicom");
    std::vector<unsigned char> streamed(ct.size_bytes());
    for (std::size_t z = 0; z < ct.dims().nz; ++z) reader.read(&streamed[z * reader.slice_bytes()], 1);
    CHECK(std::memcmp(streamed.data(), ct.data(), ct.size_bytes()) == 0);
}

}  // TEST_SUITE("realdata")
