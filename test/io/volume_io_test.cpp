// Volume files: raw and NRRD reading and writing, bad files, non-finite values, --as, the
// shared real data.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "clfractal/volume.hpp"
#include "clfractal/volume_io.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using namespace clfractal;
using testutil::check_same;
using testutil::contains;
using testutil::input_error;

namespace {

const auto& all_types = all_value_types;

/// A fresh directory under the system temp directory, removed with its contents.
class TempDir {
public:
    TempDir() {
        static int counter = 0;
        path_ = fs::temp_directory_path() / ("clfractal_volume_io_test_" + std::to_string(::getpid()) +
                                             "_" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::string path() const { return path_.string(); }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

private:
    fs::path path_;
};

void write_file(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    REQUIRE(out.good());
}

std::string bytes_of(const void* data, std::size_t n) {
    return std::string(static_cast<const char*>(data), n);
}

/// Reverses the bytes of every element of `size` bytes (host little endian → big endian).
std::string swap_elements(std::string bytes, std::size_t size) {
    for (std::size_t i = 0; i + size <= bytes.size(); i += size)
        std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(i),
                     bytes.begin() + static_cast<std::ptrdiff_t>(i + size));
    return bytes;
}

/// A volume whose values cover each type's extremes and negative values.
Volume pattern(Dims d, ValueType t) {
    Volume v(d, t, "pattern");
    visit(v, [n = v.vertices()](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t i = 0; i < n; ++i) {
            if constexpr (std::is_floating_point_v<T>)
                p[i] = static_cast<T>(i) * T(0.37) - T(5.5);  // float64: not float32 values
            else if (i == 0)
                p[i] = std::numeric_limits<T>::min();
            else if (i == 1)
                p[i] = std::numeric_limits<T>::max();
            else
                p[i] = static_cast<T>(i * 2654435761u);
        }
    });
    return v;
}

std::string nrrd_header(const std::string& type, const std::string& sizes,
                        const std::string& extra = "encoding: raw\n") {
    return "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: " + sizes + "\n" + extra + "\n";
}

// gzip (python: gzip.compress(struct.pack('<12H', *values), mtime=0)) of the uint16 values:
const std::uint16_t gzip_values[12] = {0, 1, 2, 300, 65535, 7, 8, 9, 1000, 11, 12, 13};
const unsigned char gzip_payload[44] = {
    0x1f, 0x8b, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x03, 0x63, 0x60, 0x60, 0x64, 0x60,
    0x62, 0xd0, 0x61, 0xfc, 0xff, 0x9f, 0x9d, 0x81, 0x83, 0x81, 0x93, 0xe1, 0x05, 0x33, 0x37,
    0x03, 0x0f, 0x03, 0x2f, 0x03, 0x00, 0xc3, 0xe0, 0xaa, 0xc2, 0x18, 0x00, 0x00, 0x00};
const std::string gzip_header =
    nrrd_header("ushort", "3 2 2", "endian: little\nencoding: gzip\n");

}  // namespace

TEST_SUITE("volume") {

TEST_CASE("raw names: NAME_XxYxZ_TYPE.raw") {
    Dims d;
    ValueType t;
    REQUIRE(parse_raw_name("bonsai_256x256x256_uint8.raw", d, t));
    CHECK(d == Dims{256, 256, 256});
    CHECK(t == ValueType::uint8);
    REQUIRE(parse_raw_name("/some/dir_1x1x1_uint8/neghip_slc_66x65x64_uint16.raw", d, t));
    CHECK(d == Dims{66, 65, 64});
    CHECK(t == ValueType::uint16);
    REQUIRE(parse_raw_name("stent_128x128x256_int16.raw", d, t));
    CHECK(t == ValueType::int16);
    REQUIRE(parse_raw_name("m4_31x22x25_float32.raw", d, t));
    CHECK(d == Dims{31, 22, 25});
    CHECK(t == ValueType::float32);
    REQUIRE(parse_raw_name("sim_4x5x6_float64.raw", d, t));
    CHECK(t == ValueType::float64);
    REQUIRE(parse_raw_name("ct_4x5x6_int32.raw", d, t));
    CHECK(t == ValueType::int32);
    REQUIRE(parse_raw_name("ct_4x5x6_uint32.raw", d, t));
    CHECK(t == ValueType::uint32);
    REQUIRE(parse_raw_name("ct_4x5x6_int8.raw", d, t));
    CHECK(t == ValueType::int8);

    for (const char* bad : {"bonsai.raw", "bonsai_256x256_uint8.raw", "bonsai_256x256x256x2_uint8.raw",
                            "bonsai_256x256x256_int64.raw", "bonsai_256x256x256_uchar.raw",
                            "bonsai_256x256x256_double.raw",
                            "bonsai_256x256x256_uint8.dat", "bonsai_256x256x256_uint8.raw.gz",
                            "_256x256x256_uint8.raw", "b_256xx256x256_uint8.raw",
                            "b_256x256x256x_uint8.raw", "b_+2x2x2_uint8.raw", "b_2x2x2z_uint8.raw",
                            "b_-2x2x2_uint8.raw", "b_2x2x2_.raw", "256x256x256_uint8.raw"}) {
        CAPTURE(bad);
        CHECK_FALSE(parse_raw_name(bad, d, t));
    }
}

TEST_CASE("raw round trip: every type, both endiannesses") {
    TempDir dir;
    for (ValueType t : all_types) {
        for (bool big : {false, true}) {
            CAPTURE(value_type_name(t));
            CAPTURE(big);
            const Volume v = pattern(Dims{5, 4, 3}, t);
            std::string bytes = bytes_of(v.data(), v.size_bytes());
            if (big) bytes = swap_elements(bytes, value_size(t));

            // Dims and type from the name.
            const std::string named = dir.file(std::string("p_5x4x3_") + value_type_name(t) + ".raw");
            write_file(named, bytes);
            RawOptions opt;
            opt.big_endian = big;
            const Volume a = read_raw(named, opt);
            check_same(a, v);
            CHECK(a.name == named);
            check_same(read_volume(named, opt), v);

            // Dims and type from the options.
            const std::string plain = dir.file("data.bin");
            write_file(plain, bytes);
            opt.dims = Dims{5, 4, 3};
            opt.type = t;
            check_same(read_raw(plain, opt), v);
        }
    }
}

TEST_CASE("raw options override the name") {
    TempDir dir;
    const Volume v = pattern(Dims{6, 2, 2}, ValueType::uint8);
    const std::string path = dir.file("x_2x2x6_uint16.raw");  // same byte count as 6x2x2 uint8 x2
    write_file(path, bytes_of(v.data(), v.size_bytes()) + bytes_of(v.data(), v.size_bytes()));
    RawOptions opt;
    opt.type = ValueType::uint8;
    opt.dims = Dims{12, 2, 2};
    const Volume a = read_raw(path, opt);
    CHECK(a.dims() == Dims{12, 2, 2});
    CHECK(a.type() == ValueType::uint8);
    RawOptions only_type;
    only_type.type = ValueType::int16;
    CHECK(read_raw(path, only_type).dims() == Dims{2, 2, 6});
}

TEST_CASE("NRRD round trip: every type, raw and gzip, spacing kept") {
    for (ValueType t : all_types) {
        for (bool gzip : {false, true}) {
            CAPTURE(value_type_name(t));
            CAPTURE(gzip);
            TempDir dir;
            Volume v = pattern(Dims{7, 5, 3}, t);
            v.spacing = {0.1, 1.0 / 3, 2.0};  // written with full precision by teem
            const std::string path = dir.file("v.nrrd");
            write_nrrd(v, path, gzip);
            CHECK(dir.entries() == std::vector<std::string>{"v.nrrd"});  // no temporary left

            std::ifstream in(path, std::ios::binary);
            const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            CHECK(text.compare(0, 4, "NRRD") == 0);  // attached header
            CHECK(contains(text, gzip ? "encoding: gzip" : "encoding: raw"));

            const Volume r = read_nrrd(path);
            check_same(r, v);
            CHECK(r.spacing == v.spacing);
            CHECK(r.name == path);
            check_same(read_volume(path), v);

            write_nrrd(r, path, gzip);  // overwriting an existing file
            check_same(read_nrrd(path), v);
        }
    }
}

TEST_CASE("NRRD: detached header, both endiannesses") {
    TempDir dir;
    const std::uint16_t u16[12] = {0, 1, 258, 300, 65535, 7, 8, 9, 1000, 11, 12, 40000};
    const float f32[12] = {-1.5f, 0, 1, 2.25f, 1e30f, -1e-30f, 6, 7, 8, 9, 10, 11};
    for (bool big : {false, true}) {
        CAPTURE(big);
        for (ValueType t : {ValueType::uint16, ValueType::float32}) {
            const bool is16 = t == ValueType::uint16;
            std::string bytes = is16 ? bytes_of(u16, sizeof u16) : bytes_of(f32, sizeof f32);
            if (big) bytes = swap_elements(bytes, value_size(t));
            write_file(dir.file("data.raw"), bytes);
            const std::string header = dir.file("d.nhdr");
            write_file(header, nrrd_header(nrrd_type_name(t), "3 2 2",
                                           std::string("spacings: 1 2 3\nendian: ") +
                                               (big ? "big" : "little") +
                                               "\nencoding: raw\ndata file: data.raw\n"));
            const Volume v = read_volume(header);
            REQUIRE(v.dims() == Dims{3, 2, 2});
            REQUIRE(v.type() == t);
            for (std::size_t i = 0; i < 12; ++i) CHECK(v.value(i) == (is16 ? u16[i] : f32[i]));
            CHECK(v.spacing == std::array<double, 3>{1.0, 2.0, 3.0});
        }
    }
}

TEST_CASE("NRRD: hand-written gzip, space directions, float64") {
    TempDir dir;
    const std::string gz = dir.file("g.nrrd");
    write_file(gz, gzip_header + bytes_of(gzip_payload, sizeof gzip_payload));
    const Volume g = read_volume(gz);
    REQUIRE(g.dims() == Dims{3, 2, 2});
    REQUIRE(g.type() == ValueType::uint16);
    for (std::size_t i = 0; i < 12; ++i) CHECK(g.value(i) == gzip_values[i]);

    const std::string sd = dir.file("sd.nrrd");
    write_file(sd, nrrd_header("uchar", "2 2 2",
                               "space: right-anterior-superior\n"
                               "space directions: (0.5,0,0) (0,0,-2) (0,3,4)\nencoding: raw\n") +
                       "abcdefgh");
    const Volume s = read_nrrd(sd);
    CHECK(s.spacing[0] == doctest::Approx(0.5));
    CHECK(s.spacing[1] == doctest::Approx(2.0));
    CHECK(s.spacing[2] == doctest::Approx(5.0));
    CHECK(s.value(7) == 'h');

    const double d64[8] = {-1.25, 0, 1, 2, 3, 4, 5, 1e10};
    const std::string f64 = dir.file("f64.nrrd");
    write_file(f64, nrrd_header("double", "2 2 2", "endian: little\nencoding: raw\n") +
                        bytes_of(d64, sizeof d64));
    const Volume d = read_volume(f64);
    REQUIRE(d.type() == ValueType::float64);
    for (std::size_t i = 0; i < 8; ++i) CHECK(d.value(i) == d64[i]);
    RawOptions as;
    as.as = ValueType::float32;
    const Volume df = read_volume(f64, as);
    REQUIRE(df.type() == ValueType::float32);
    for (std::size_t i = 0; i < 8; ++i) CHECK(df.value(i) == double(static_cast<float>(d64[i])));
}

TEST_CASE("big files are read in parts on every core, byte for byte") {
    // 40 MiB: above the size from which the data is read in one part a core.
    TempDir dir;
    const Volume v = testutil::random_volume(Dims{1024, 1024, 20}, ValueType::uint16, 0, 65535, 3);
    const std::string raw = dir.file("big_1024x1024x20_uint16.raw");
    write_file(raw, bytes_of(v.data(), v.size_bytes()));
    const Volume r = read_volume(raw);
    REQUIRE(r.size_bytes() == v.size_bytes());
    CHECK(std::memcmp(r.data(), v.data(), v.size_bytes()) == 0);
    const std::string nrrd = dir.file("big.nrrd");  // an attached header: data at an odd offset
    write_nrrd(v, nrrd);
    const Volume n = read_volume(nrrd);
    REQUIRE(n.size_bytes() == v.size_bytes());
    CHECK(std::memcmp(n.data(), v.data(), v.size_bytes()) == 0);
}

TEST_CASE("bad raw files name the file and the problem") {
    TempDir dir;
    const std::string truncated = dir.file("t_4x4x4_uint16.raw");
    write_file(truncated, std::string(100, 'a'));
    std::string m = input_error([&] { read_volume(truncated); });
    CHECK(m == truncated + ": truncated: expected 128 bytes (4x4x4 uint16), found 100");

    const std::string too_long = dir.file("t_4x4x4_uint8.raw");
    write_file(too_long, std::string(65, 'a'));
    m = input_error([&] { read_volume(too_long); });
    CHECK(m == too_long + ": too long: expected 64 bytes (4x4x4 uint8), found 65");

    const std::string unnamed = dir.file("volume.bin");
    write_file(unnamed, std::string(64, 'a'));
    m = input_error([&] { read_volume(unnamed); });
    CHECK(contains(m, unnamed));
    CHECK(contains(m, "needs --dims and --type"));

    const std::string unknown_type = dir.file("t_4x4x4_int64.raw");
    write_file(unknown_type, std::string(512, 'a'));
    m = input_error([&] { read_volume(unknown_type); });
    CHECK(contains(m, unknown_type));
    CHECK(contains(m, "unknown value type 'int64'"));

    const std::string zero = dir.file("t_0x4x4_uint8.raw");
    write_file(zero, "");
    CHECK(contains(input_error([&] { read_volume(zero); }), zero + ": dims 0x4x4"));

    const std::string overflow = dir.file("t_4294967296x4294967296x4294967296_uint8.raw");
    write_file(overflow, "abc");
    m = input_error([&] { read_volume(overflow); });
    CHECK(contains(m, overflow));
    CHECK(contains(m, "exceed the maximum of 2^40 vertices"));
    RawOptions opt;
    opt.dims = Dims{100000, 100000, 100000};
    opt.type = ValueType::uint8;
    CHECK(contains(input_error([&] { read_volume(unnamed, opt); }),
                   unnamed + ": dims 100000x100000x100000 exceed"));

    const std::string missing = dir.file("missing_4x4x4_uint8.raw");
    CHECK(input_error([&] { read_volume(missing); }) == missing + ": no such file");
    CHECK(contains(input_error([&] { read_volume(dir.path()); }), "not a regular file"));
}

TEST_CASE("NaN and Inf in float data are rejected with the vertex") {
    TempDir dir;
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity()};
    const char* kinds[] = {"NaN", "Inf", "-Inf"};
    // How many of each: the reported one at (1,2,1), and specials[(k + 1) % 3] at the end.
    const char* counts[] = {"1 NaN and 1 infinite values", "2 infinite values", "1 NaN and 1 infinite values"};
    for (int k = 0; k < 3; ++k) {
        CAPTURE(kinds[k]);
        std::vector<float> values(4 * 3 * 2, 1.0f);
        values[1 + 4 * (2 + 3 * 1)] = specials[k];  // vertex (1,2,1)
        values.back() = specials[(k + 1) % 3];      // a later bad vertex is not the one reported
        const std::string path = dir.file("f_4x3x2_float32.raw");
        write_file(path, bytes_of(values.data(), values.size() * sizeof(float)));
        CHECK(input_error([&] { read_volume(path); }) ==
              path + ": float data contains " + counts[k] + " (the first, " + kinds[k] +
                  ", at vertex (1,2,1)); counting, filtering and meshing need finite values");
        // `info` keeps them (FiniteCheck::keep) and counts them.
        const Volume kept = read_volume(path, {}, FiniteCheck::keep);
        const NonFinite nf = count_non_finite(kept.data(), kept.type(), kept.vertices());
        CHECK(nf.nan + nf.inf == 2);
        CHECK(nf.nan == (k == 1 ? 0u : 1u));
        CHECK(nf.first == 1 + 4 * (2 + 3 * 1));
        const Volume raw = read_raw(path);  // read_raw alone does not check
        CHECK(contains(input_error([&] { check_finite(raw, "X"); }), "X: float data contains"));
    }
    std::vector<float> values(8, 0.0f);
    values[0] = std::numeric_limits<float>::quiet_NaN();
    const std::string nrrd = dir.file("nan.nrrd");
    write_file(nrrd, nrrd_header("float", "2 2 2", "endian: little\nencoding: raw\n") +
                         bytes_of(values.data(), 32));
    CHECK(input_error([&] { read_volume(nrrd); }) ==
          nrrd + ": float data contains 1 NaN value (the first, NaN, at vertex (0,0,0)); counting, filtering and "
                 "meshing need finite values");
}

TEST_CASE("float64 NaN is rejected; --as converts any type, rounding and saturating") {
    TempDir dir;
    std::vector<double> values(24, 0.5);
    values[3 + 4 * (1 + 3 * 1)] = -std::numeric_limits<double>::infinity();  // vertex (3,1,1)
    const std::string path = dir.file("f_4x3x2_float64.raw");
    write_file(path, bytes_of(values.data(), values.size() * sizeof(double)));
    CHECK(input_error([&] { read_volume(path); }) == path + ": float data contains 1 infinite value (the first, -Inf, at vertex (3,1,1)); counting, filtering and meshing need finite values");
    RawOptions as;
    as.as = ValueType::uint8;  // the check comes first, on the stored values
    CHECK(contains(input_error([&] { read_volume(path, as); }), "-Inf, at vertex (3,1,1)"));

    // Every conversion of the rules: integers round to nearest even and saturate; floats
    // round to nearest and saturate to +-max.
    const double in[] = {-1e300, -3e9, -2.5, -0.5, 0.5, 1.5, 2.5, 1e-300, 16777217.0, 4294967295.0, 5e9, 1e300};
    Volume v(Dims{12, 1, 1}, ValueType::float64);
    std::copy(std::begin(in), std::end(in), v.as<double>());
    const Volume i8 = convert_volume(v, ValueType::int8), u32 = convert_volume(v, ValueType::uint32),
                 i32 = convert_volume(v, ValueType::int32), f32 = convert_volume(v, ValueType::float32);
    const double want_i8[] = {-128, -128, -2, -0.0, 0, 2, 2, 0, 127, 127, 127, 127};
    const double want_u32[] = {0, 0, 0, 0, 0, 2, 2, 0, 16777217, 4294967295.0, 4294967295.0, 4294967295.0};
    const double want_i32[] = {-2147483648.0, -2147483648.0, -2, 0, 0, 2, 2, 0, 16777217, 2147483647, 2147483647,
                               2147483647};
    for (std::size_t i = 0; i < 12; ++i) {
        CAPTURE(in[i]);
        CHECK(i8.value(i) == want_i8[i]);
        CHECK(u32.value(i) == want_u32[i]);
        CHECK(i32.value(i) == want_i32[i]);
        CHECK(std::isfinite(f32.value(i)));
        CHECK(f32.value(i) == double(float(std::clamp(in[i], -3.4028234663852886e38, 3.4028234663852886e38))));
    }
    // Exact whenever the target holds the value: int32 -> float64 -> int32.
    Volume w(Dims{3, 1, 1}, ValueType::int32);
    w.as<std::int32_t>()[0] = std::numeric_limits<std::int32_t>::min();
    w.as<std::int32_t>()[1] = 16777217;  // not a float32
    w.as<std::int32_t>()[2] = std::numeric_limits<std::int32_t>::max();
    const Volume back = convert_volume(convert_volume(w, ValueType::float64), ValueType::int32);
    CHECK(std::memcmp(back.data(), w.data(), w.size_bytes()) == 0);

    // --as on a raw file: int32 read as int16 saturates, as float32 rounds.
    const std::string raw = dir.file("w_3x1x1_int32.raw");
    write_file(raw, bytes_of(w.data(), w.size_bytes()));
    as.as = ValueType::int16;
    const Volume s = read_volume(raw, as);
    REQUIRE(s.type() == ValueType::int16);
    CHECK(s.value(0) == -32768);
    CHECK(s.value(1) == 32767);
    as.as = ValueType::float32;
    CHECK(read_volume(raw, as).value(1) == 16777216.0);
}

TEST_CASE("bad NRRD files name the file and teem's reason") {
    TempDir dir;
    const auto check_bad = [&](const std::string& name, const std::string& content,
                               const std::string& reason) {
        CAPTURE(name);
        const std::string path = dir.file(name);
        write_file(path, content);
        const std::string m = input_error([&] { read_volume(path); });
        CHECK(contains(m, path + ": "));
        CHECK_MESSAGE(contains(m, reason), m);
    };
    check_bad("short_data.nrrd", nrrd_header("uchar", "4 4 4") + "abcdefgh",
              "truncated: the header claims 64 bytes (64 values of uchar) of raw data, the file holds 8");
    check_bad("short_data.nrrd", nrrd_header("ushort", "4 4 4") + std::string(127, 'a'), "truncated");
    check_bad("unknown_type.nrrd", nrrd_header("foo", "2 2 2") + "abcdefgh", "foo");
    check_bad("int64.nrrd",
              nrrd_header("long long", "2 2 2", "endian: little\nencoding: raw\n") + std::string(64, 'a'),
              "unsupported NRRD type");
    check_bad("uint64.nrrd",
              nrrd_header("unsigned long long", "2 2 2", "endian: little\nencoding: raw\n") + std::string(64, 'a'),
              "unsupported NRRD type");
    check_bad("huge.nrrd", nrrd_header("uchar", "100000 100000 100000") + "abcdefgh",
              "sizes '100000 100000 100000' exceed the maximum of 2^40 values");
    check_bad("two_d.nrrd",
              "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 2 2\nencoding: raw\n\nabcd",
              "only 3D scalar volumes");
    check_bad("not_nrrd.nrrd", "hello\n", "not a NRRD file");
    check_bad("missing_data.nhdr", nrrd_header("uchar", "2 2 2", "encoding: raw\ndata file: nope.raw\n"),
              "nope.raw' does not exist");

    std::string crc(reinterpret_cast<const char*>(gzip_payload), sizeof gzip_payload);
    crc[crc.size() - 8] ^= 0x5a;  // CRC-32 of the payload
    check_bad("bad_crc.nrrd", gzip_header + crc, "gzip data");
    const std::string cut(reinterpret_cast<const char*>(gzip_payload), 30);
    check_bad("cut_gzip.nrrd", gzip_header + cut, "gzip data");
    std::string deflate(reinterpret_cast<const char*>(gzip_payload), sizeof gzip_payload);
    std::fill(deflate.begin() + 12, deflate.begin() + 20, '\0');
    check_bad("bad_deflate.nrrd", gzip_header + deflate, "gzip data");
}

TEST_CASE("write_nrrd: failures name the path and leave no temporary") {
    TempDir dir;
    const Volume v = pattern(Dims{2, 2, 2}, ValueType::uint8);
    const std::string no_dir = dir.file("no/such/dir/out.nrrd");
    CHECK(contains(input_error([&] { write_nrrd(v, no_dir); }), no_dir));

    // A non-empty directory where the file should go: the rename fails.
    const std::string blocked = dir.file("blocked.nrrd");
    fs::create_directories(fs::path(blocked) / "inside");
    CHECK(contains(input_error([&] { write_nrrd(v, blocked, true); }), blocked));
    CHECK(dir.entries() == std::vector<std::string>{"blocked.nrrd"});
}

TEST_CASE("shared real data: names, sizes and dims of MANIFEST.tsv") {
    const auto volumes = testutil::real_volumes("the MANIFEST.tsv checks");
    if (volumes.empty()) return;
    int checked = 0;
    for (const testutil::RealVolume& real : volumes) {
        const std::string& path = real.path;
        CAPTURE(path);
        REQUIRE(real.columns.count("dims"));
        REQUIRE(real.columns.count("dtype"));
        Dims d;
        ValueType t;
        REQUIRE(parse_raw_name(path, d, t));
        CHECK(dims_string(d) == real.columns.at("dims"));
        CHECK(value_type_name(t) == real.columns.at("dtype"));
        CHECK(fs::file_size(path) == d.vertices() * value_size(t));
        const Volume v = read_volume(path);
        CHECK(v.dims() == d);
        CHECK(v.type() == t);
        ++checked;
    }
    MESSAGE("read " << checked << " real volumes from " << testutil::shared_data());
    CHECK(checked > 0);
}

}  // TEST_SUITE("volume")
