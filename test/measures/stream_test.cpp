// Slice streaming, out-of-core LD and slice readers against the whole-volume results,
// exactly (docs/definitions.md §28 "Slabs, streams and ranks").
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "clfractal/fd.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/span.hpp"
#include "clfractal/stream.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"
#include "baselines.hpp"

namespace fs = std::filesystem;
using namespace clfractal;
using testutil::ctx;

namespace {

// The first n slices of v.
Volume first_slices(const Volume& v, std::size_t n) {
    Volume s(Dims{v.dims().nx, v.dims().ny, n}, v.type());
    std::memcpy(s.data(), v.data(), s.size_bytes());
    return s;
}

const unsigned char* slice_of(const Volume& v, std::size_t z) {
    return static_cast<const unsigned char*>(v.data()) + z * v.dims().nx * v.dims().ny * value_size(v.type());
}

// Same float bits, NaN equal to NaN.
bool same_field(const Volume& a, const Volume& b) {
    if (a.dims() != b.dims()) return false;
    const float* p = a.as<float>();
    const float* q = b.as<float>();
    for (std::size_t i = 0; i < a.vertices(); ++i)
        if (!(p[i] == q[i] || (std::isnan(p[i]) && std::isnan(q[i])))) return false;
    return true;
}

// The bytes of a file.
std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

using testutil::Case;

const Case cases[] = {
    // More slices than a batch (65 slices at 1-4 levels), so that full batches are counted.
    {{7, 5, 150}, ValueType::uint8, 0, 255},  {{1, 6, 12}, ValueType::uint16, 0, 9},
    {{5, 1, 19}, ValueType::int16, -4, 4},     {{2, 2, 11}, ValueType::float32, -6, 6},
    {{13, 3, 37}, ValueType::int16, -300, 40}, {{6, 7, 137}, ValueType::float32, -20, 20},
    {{3, 4, 1}, ValueType::uint8, 0, 3},
    {{5, 4, 70}, ValueType::int32, -2147483647 - 1, 2147483647}, {{4, 6, 23}, ValueType::float64, -9, 9},
    {{6, 3, 21}, ValueType::uint32, 4294967000, 4294967295},     {{3, 5, 17}, ValueType::int8, -128, 127},
};

class TempDir {
public:
    TempDir() {
        static int counter = 0;
        path_ = fs::temp_directory_path() /
                ("clfractal_stream_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
    fs::path path_;
};

void write_bytes(const std::string& path, const void* data, std::size_t n) {
    std::ofstream out(path, std::ios::binary);
    out.write(static_cast<const char*>(data), std::streamsize(n));
}

// Reads the whole file through a SliceReader, `chunk` slices at a time.
Volume read_by_slices(const std::string& spec, std::size_t chunk, const RawOptions& raw = {}) {
    SliceReader r(spec, raw);
    Volume v(r.dims(), r.type());
    for (std::size_t z = 0; z < r.dims().nz; z += chunk) {
        const std::size_t n = std::min(chunk, r.dims().nz - z);
        r.read(static_cast<unsigned char*>(v.data()) + z * r.slice_bytes(), n);
    }
    CHECK(r.next_slice() == r.dims().nz);
    return v;
}

bool same_bytes(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() &&
           std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

}  // namespace

TEST_SUITE("stream") {

TEST_CASE("streamed counts equal whole-volume counts after every slice: all types, awkward sizes, levels 1..3") {
    std::uint32_t seed = 11;
    for (const Case& c : cases) {
        const Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        const IsovalueSet iso = IsovalueSet::for_volume(v, 48);
        for (int levels = 1; levels <= 3; ++levels) {
            CAPTURE(dims_string(c.d));
            CAPTURE(value_type_name(c.t));
            CAPTURE(levels);
            SpanStream stream(ctx(), c.d.nx, c.d.ny, c.t, iso, levels);
            CHECK(stream.slices() == 0);
            for (auto& curve : stream.counts().curves)
                for (auto& level : curve.counts) CHECK(std::all_of(level.begin(), level.end(), [](auto n) { return n == 0; }));
            for (std::size_t z = 0; z < c.d.nz; ++z) {
                stream.push_slice(static_cast<const void*>(slice_of(v, z)));
                const std::size_t n = z + 1;
                // Every slice count around the batch boundaries, and a few more.
                const std::size_t b = stream.batch_slices() - 1;
                if (!(n <= 3 || n % b <= 1 || n % b == b - 1 || n == c.d.nz || n % 5 == 0)) continue;
                CAPTURE(n);
                const Volume part = first_slices(v, n);
                const SpanResult got = stream.counts();
                const SpanResult want =
                    count_spans(ctx(), part, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, levels, 0});
                REQUIRE(got.curves.size() == 2);
                for (int k = 0; k < 2; ++k) {
                    CHECK(got.curves[k].kind == want.curves[k].kind);
                    CHECK(got.curves[k].level_dims == want.curves[k].level_dims);
                    CHECK(got.curves[k].counts == want.curves[k].counts);
                }
            }
            // The whole stream against the plain reference too.
            const SpanResult all = stream.counts();
            for (int l = 0; l < levels; ++l) {
                const Volume lv = ref::level(v, l);
                CHECK(all.get(SpanKind::cubes).counts[l] == ref::cubes_histogram(lv, iso));
                CHECK(all.get(SpanKind::edges).counts[l] == ref::edges_histogram(lv, iso));
            }
        }
    }
}

TEST_CASE("many batches and deep pyramids: counts and curves equal the whole-volume ones") {
    const Volume v = testutil::random_volume(Dims{9, 8, 203}, ValueType::uint8, 0, 40, 5);
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    for (int levels : {2, 4, 5}) {
        CAPTURE(levels);
        SpanStream stream(ctx(), 9, 8, ValueType::uint8, iso, levels);
        CHECK((stream.batch_slices() - 1) % (std::size_t(1) << (levels - 1)) == 0);
        for (std::size_t z = 0; z < v.dims().nz; ++z) {
            stream.push_slice(reinterpret_cast<const std::uint8_t*>(slice_of(v, z)));
            if ((z + 1) % 29 != 0 && z + 1 != v.dims().nz) continue;
            const Volume part = first_slices(v, z + 1);
            const SpanResult want =
                count_spans(ctx(), part, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, levels, 0});
            for (SpanKind kind : {SpanKind::cubes, SpanKind::edges}) {
                const FdCurve got = stream.curve(kind), ref = fd_curve(ctx(), want, kind);
                CHECK(got.counts == ref.counts);
                CHECK(got.level_dims == ref.level_dims);
                REQUIRE(got.fd.size() == ref.fd.size());
                for (std::size_t j = 0; j < got.fd.size(); ++j)
                    CHECK((got.fd[j] == ref.fd[j] || (std::isnan(got.fd[j]) && std::isnan(ref.fd[j]))));
            }
        }
        CHECK(stream.counts().slabs > 1);
    }
}

TEST_CASE("the GPU kernel variants and copied (not zero-copy) slices stream the same counts") {
    const Volume v = testutil::random_volume(Dims{11, 7, 30}, ValueType::uint16, 0, 700, 13);
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    const SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 3, 0};
    const SpanResult want = count_spans(ctx(), v, iso, opt);
    for (const char* variant : {"private", "atomic"})
        for (bool zero_copy : {false, true}) {
            CAPTURE(variant);
            CAPTURE(zero_copy);
            testutil::TuningGuard guard;
            ctx().tuning.span_variant = parse_variant<SpanVariant>(variant);
            ctx().tuning.zero_copy = zero_copy;
            ctx().tuning.local_hist_bytes = 1024;  // 16-bit ranges use global-memory histograms
            SpanStream stream(ctx(), 11, 7, ValueType::uint16, iso, 3);
            for (std::size_t z = 0; z < v.dims().nz; ++z)
                stream.push_slice(reinterpret_cast<const std::uint16_t*>(slice_of(v, z)));
            const SpanResult got = stream.counts();
            CHECK(got.curves[0].counts == want.curves[0].counts);
            CHECK(got.curves[1].counts == want.curves[1].counts);
        }
}

TEST_CASE("one kind only, and the stream's checks") {
    const Volume v = testutil::random_volume(Dims{6, 5, 14}, ValueType::float32, -10, 10, 9);
    const IsovalueSet iso = IsovalueSet::for_volume(v, 32);
    SpanStream stream(ctx(), 6, 5, ValueType::float32, iso, 2, {SpanKind::edges});
    for (std::size_t z = 0; z < v.dims().nz; ++z) stream.push_slice(reinterpret_cast<const float*>(slice_of(v, z)));
    const SpanResult got = stream.counts();
    REQUIRE(got.curves.size() == 1);
    CHECK(got.curves[0].counts == count_spans(ctx(), v, iso, SpanOptions{{SpanKind::edges}, 2, 0}).curves[0].counts);

    std::vector<std::uint8_t> wrong(30, 0);
    CHECK_THROWS_AS(stream.push_slice(wrong.data()), std::logic_error);
    std::vector<float> nan(30, 0.f);
    nan[7] = std::numeric_limits<float>::quiet_NaN();
    try {
        stream.push_slice(nan.data());
        FAIL("no error");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()) == "stream: float data contains 1 NaN value in slice " + std::to_string(v.dims().nz) +
                                           " (the first, NaN, at vertex (1,1," + std::to_string(v.dims().nz) +
                                           ")); counting, filtering and meshing need finite values");
    }
    CHECK(stream.slices() == v.dims().nz);  // the bad slice was not added
    CHECK_THROWS_AS(SpanStream(ctx(), 0, 5, ValueType::uint8, IsovalueSet::integers(0, 3)), InputError);
}

TEST_CASE("streamed LD equals the whole-volume field: all types, windows, batches, delay k/2") {
    const Case ld_cases[] = {
        {{9, 7, 23}, ValueType::uint8, 0, 10},   {{6, 11, 17}, ValueType::uint16, 0, 10},
        {{5, 4, 20}, ValueType::int16, -5, 5},   {{8, 6, 15}, ValueType::float32, -5, 5},
        {{4, 3, 3}, ValueType::uint8, 0, 10},    {{3, 3, 1}, ValueType::uint8, 0, 10},
        {{5, 6, 13}, ValueType::int32, -3, 4},   {{6, 5, 12}, ValueType::float64, -5, 5},
    };
    std::uint32_t seed = 21;
    for (const Case& c : ld_cases) {
        const Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        for (int window : {2, 4, 8}) {
            const Volume want = local_fractal_dimension(ctx(), v, 1.5, window);
            for (std::size_t batch : {1, 3}) {
                CAPTURE(dims_string(c.d));
                CAPTURE(value_type_name(c.t));
                CAPTURE(window);
                CAPTURE(batch);
                Volume got(c.d, ValueType::float32);
                const std::size_t plane = c.d.nx * c.d.ny;
                std::size_t expect_z = 0;
                bool values_ok = true;
                LocalStream* self = nullptr;
                LocalStream stream(
                    ctx(), c.d.nx, c.d.ny, c.t, 1.5, window,
                    [&](std::size_t z, const float* ld, const void* values) {
                        CHECK(z == expect_z++);
                        std::memcpy(got.as<float>() + z * plane, ld, plane * sizeof(float));
                        values_ok &= std::memcmp(values, slice_of(v, z), plane * value_size(c.t)) == 0;
                        // The neighbourhood of radius k/2 is held for a filter to read.
                        const std::size_t h = std::size_t(window / 2);
                        for (std::size_t w = z > h ? z - h : 0; w <= std::min(c.d.nz - 1, z + h); ++w) {
                            const void* in = self->input_slice(w);
                            values_ok &= in && std::memcmp(in, slice_of(v, w), plane * value_size(c.t)) == 0;
                        }
                    },
                    batch);
                self = &stream;
                CHECK(stream.delay() == std::size_t(window / 2) + batch - 1);
                for (std::size_t z = 0; z < c.d.nz; ++z) {
                    stream.push_slice(static_cast<const void*>(slice_of(v, z)));
                    // Slice z - delay is out as soon as slice z is in (batch 1).
                    if (batch == 1 && z >= stream.delay()) CHECK(stream.emitted() == z - stream.delay() + 1);
                }
                stream.finish();
                CHECK(stream.emitted() == c.d.nz);
                CHECK(values_ok);
                CHECK(same_field(got, want));
            }
        }
    }
}

TEST_CASE("out-of-core LD: tiny z-slabs give the in-core field exactly") {
    std::uint32_t seed = 31;
    for (ValueType t : {ValueType::uint8, ValueType::uint16, ValueType::int16, ValueType::float32}) {
        const Dims d{7, 9, 31};
        const Volume v = testutil::random_volume(d, t, 0, 12, seed++);
        for (int window : {2, 8}) {
            CAPTURE(value_type_name(t));
            CAPTURE(window);
            const Volume want = local_fractal_dimension(ctx(), v, 6, window);
            for (std::size_t slices : {1, 12, 20}) {
                CAPTURE(slices);
                testutil::TuningGuard guard;
                ctx().tuning.slab_bytes = slices * d.nx * d.ny * value_size(t);
                CHECK(same_field(local_fractal_dimension(ctx(), v, 6, window), want));
            }
        }
    }
    // 64-bit tables, copies instead of zero-copy, and the GPU kernel variants, in slabs.
    {
        const Volume v = testutil::random_volume(Dims{8, 6, 29}, ValueType::int16, -6, 6, 17);
        const Volume want = local_fractal_dimension(ctx(), v, 0.5, 4);
        testutil::TuningGuard guard;
        ctx().tuning.slab_bytes = 9 * 8 * 6 * 2;
        ctx().tuning.sat_max_32bit = 10;
        ctx().tuning.zero_copy = false;
        CHECK(same_field(local_fractal_dimension(ctx(), v, 0.5, 4), want));
        ctx().tuning.local_variant = parse_variant<LocalVariant>("vertices");
        ctx().tuning.sat_variant = parse_variant<SatVariant>("workgroup");
        ctx().tuning.sat_work_group = 4;
        CHECK(same_field(local_fractal_dimension(ctx(), v, 0.5, 4), want));
    }
    // Against the brute-force-checked OpenMP baseline as well.
    const Volume v = testutil::random_volume(Dims{12, 5, 26}, ValueType::uint8, 0, 9, 3);
    testutil::TuningGuard guard;
    ctx().tuning.slab_bytes = 12 * 5 * 3;
    const Volume got = local_fractal_dimension(ctx(), v, 4.5, 6), base = local_fractal_dimension_openmp(v, 4.5, 6);
    std::size_t defined = 0;
    for (std::size_t i = 0; i < v.vertices(); ++i) {
        const float a = got.as<float>()[i], b = base.as<float>()[i];
        CHECK(std::isnan(a) == std::isnan(b));
        if (!std::isnan(a)) CHECK(std::fabs(a - b) <= 1e-6);
        defined += !std::isnan(a);
    }
    CHECK(defined > v.vertices() / 2);
}

TEST_CASE("slice readers equal read_volume: raw, big-endian raw, NRRD raw/gzip, detached header, float64") {
    TempDir dir;
    std::uint32_t seed = 41;
    for (ValueType t : all_value_types) {
        CAPTURE(value_type_name(t));
        const Volume v = testutil::random_volume(Dims{11, 6, 9}, t, -100, 200, seed++);
        const std::string raw = dir.file(std::string("v_11x6x9_") + value_type_name(t) + ".raw");
        write_bytes(raw, v.data(), v.size_bytes());
        const std::string nrrd = dir.file("v.nrrd"), gz = dir.file("v_gz.nrrd");
        write_nrrd(v, nrrd);
        write_nrrd(v, gz, true);
        for (std::size_t chunk : {1, 4, 9}) {
            CAPTURE(chunk);
            CHECK(same_bytes(read_by_slices(raw, chunk), v));
            CHECK(same_bytes(read_by_slices(nrrd, chunk), v));
            CHECK(same_bytes(read_by_slices(gz, chunk), v));
        }
        // seek: any slice, forwards and backwards, for every reading method.
        for (const std::string& path : {raw, nrrd, gz}) {
            SliceReader r(path);
            const std::size_t slice = r.slice_bytes();
            std::vector<unsigned char> buf(2 * slice);
            for (std::size_t z : {5, 2, 7, 0, 8}) {
                CAPTURE(path); CAPTURE(z);
                r.seek(z);
                const std::size_t n = z + 2 <= 9 ? 2 : 1;
                r.read(buf.data(), n);
                CHECK(r.next_slice() == z + n);
                CHECK(std::memcmp(buf.data(), static_cast<const unsigned char*>(v.data()) + z * slice, n * slice) == 0);
            }
        }
        CHECK(std::string(SliceReader(raw).method()) == "mmap");
        CHECK(std::string(SliceReader(nrrd).method()) == "mmap");
        CHECK(std::string(SliceReader(gz).method()) == "gzip");
        SliceReader r(gz);
        const ValueRange a = value_range(r), b = value_range(v);
        CHECK(a.min == b.min);
        CHECK(a.max == b.max);
        CHECK(r.next_slice() == 0);

        // Big-endian raw with --dims/--type.
        if (value_size(t) > 1) {
            Volume swapped = v;
            auto* p = static_cast<unsigned char*>(swapped.data());
            for (std::size_t i = 0; i < v.vertices(); ++i) std::reverse(p + i * value_size(t), p + (i + 1) * value_size(t));
            const std::string be = dir.file("big.bin");
            write_bytes(be, swapped.data(), swapped.size_bytes());
            RawOptions opt;
            opt.dims = v.dims();
            opt.type = t;
            opt.big_endian = true;
            CHECK(same_bytes(read_by_slices(be, 4, opt), v));
            CHECK(same_bytes(read_by_slices(be, 4, opt), read_volume(be, opt)));
        }
    }

    // A detached header pointing at a raw file of float64 data (values float32 does not
    // hold), read as it is and converted on read (--as float32, --as int16).
    Volume f(Dims{5, 4, 6}, ValueType::float64);
    const Volume base = testutil::random_volume(f.dims(), ValueType::float32, -9, 9, 7);
    for (std::size_t i = 0; i < f.vertices(); ++i) f.as<double>()[i] = base.value(i) + 1e-9 * double(i);
    write_bytes(dir.file("d.raw"), f.data(), f.size_bytes());
    {
        std::ofstream h(dir.file("d.nhdr"));
        h << "NRRD0004\ntype: double\ndimension: 3\nsizes: 5 4 6\nencoding: raw\nendian: little\ndata file: d.raw\n";
    }
    CHECK(std::string(SliceReader(dir.file("d.nhdr")).method()) == "mmap");
    CHECK(same_bytes(read_by_slices(dir.file("d.nhdr"), 2), f));
    CHECK(same_bytes(read_by_slices(dir.file("d.nhdr"), 2), read_volume(dir.file("d.nhdr"))));
    for (ValueType as : {ValueType::float32, ValueType::int16}) {
        RawOptions opt;
        opt.as = as;
        CHECK(SliceReader(dir.file("d.nhdr"), opt).type() == as);
        CHECK(same_bytes(read_by_slices(dir.file("d.nhdr"), 4, opt), convert_volume(f, as)));
        CHECK(same_bytes(read_by_slices(dir.file("d.nhdr"), 4, opt), read_volume(dir.file("d.nhdr"), opt)));
    }

    // synthetic: specs are read whole and served slice by slice.
    CHECK(std::string(SliceReader("synthetic:sphere:12").method()) == "memory");
    CHECK(same_bytes(read_by_slices("synthetic:sphere:12", 5), read_volume("synthetic:sphere:12")));
}

TEST_CASE("slice readers: batches of 8 MiB and more, copied from the mapping on every core, byte for byte") {
    TempDir dir;
    const Volume v = testutil::random_volume(Dims{1024, 512, 40}, ValueType::uint16, 0, 65535, 5);  // 40 MiB
    const std::string nrrd = dir.file("big.nrrd");  // data at an odd offset
    write_nrrd(v, nrrd);
    for (std::size_t chunk : {std::size_t(9), std::size_t(40)}) {  // 9 MiB batches, one of 40 MiB
        CAPTURE(chunk);
        CHECK(same_bytes(read_by_slices(nrrd, chunk), v));
    }
}

TEST_CASE("slice readers: bad inputs are input errors") {
    TempDir dir;
    CHECK_THROWS_AS(SliceReader(dir.file("missing.raw")), InputError);
    std::vector<std::uint8_t> bytes(100, 1);
    write_bytes(dir.file("short_5x5x5_uint8.raw"), bytes.data(), bytes.size());
    CHECK_THROWS_AS(SliceReader(dir.file("short_5x5x5_uint8.raw")), InputError);
    write_bytes(dir.file("noname.raw"), bytes.data(), bytes.size());
    CHECK_THROWS_AS(SliceReader(dir.file("noname.raw")), InputError);

    // A gzip stream cut short, and a corrupt one.
    const Volume v = testutil::random_volume(Dims{16, 16, 16}, ValueType::uint8, 0, 255, 1);
    write_nrrd(v, dir.file("g.nrrd"), true);
    std::ifstream in(dir.file("g.nrrd"), std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    {
        std::ofstream out(dir.file("cut.nrrd"), std::ios::binary);
        out.write(all.data(), std::streamsize(all.size() - all.size() / 3));
    }
    std::vector<std::uint8_t> dst(v.size_bytes());
    CHECK_THROWS_AS(SliceReader(dir.file("cut.nrrd")).read(dst.data(), 16), InputError);
    std::string corrupt = all;
    for (std::size_t i = all.size() - 200; i < all.size() - 100; ++i) corrupt[i] = char(corrupt[i] ^ 0x5a);
    {
        std::ofstream out(dir.file("bad.nrrd"), std::ios::binary);
        out.write(corrupt.data(), std::streamsize(corrupt.size()));
    }
    CHECK_THROWS_AS(SliceReader(dir.file("bad.nrrd")).read(dst.data(), 16), InputError);

    // NaN in float data, named with its vertex.
    Volume f(Dims{3, 3, 3}, ValueType::float32);
    f.as<float>()[3 + 9 * 2] = std::numeric_limits<float>::quiet_NaN();
    write_bytes(dir.file("nan_3x3x3_float32.raw"), f.data(), f.size_bytes());
    SliceReader r(dir.file("nan_3x3x3_float32.raw"));
    std::vector<float> s(27);
    r.read(s.data(), 2);
    try {
        r.read(s.data(), 1);
        FAIL("no error");
    } catch (const InputError& e) {
        // The in-core wording (check_finite), with the slices scanned.
        CHECK(std::string(e.what()) == dir.file("nan_3x3x3_float32.raw") +
                                           ": float data contains 1 NaN value in slice 2 (the first, NaN, at vertex "
                                           "(0,1,2)); counting, filtering and meshing need finite values");
    }
}

TEST_CASE("LD streamed from a file and written slice by slice equals the in-core field") {
    TempDir dir;
    const Volume v = testutil::random_volume(Dims{12, 10, 27}, ValueType::int16, -8, 8, 99);
    write_nrrd(v, dir.file("in.nrrd"), true);
    SliceReader reader(dir.file("in.nrrd"));
    {
        NrrdSliceWriter writer(dir.file("ld.nrrd"), v.dims(), ValueType::float32);
        LocalStream stream(ctx(), 12, 10, ValueType::int16, 0.5, 6,
                           [&](std::size_t, const float* ld, const void*) { writer.write(ld, 1); }, 4);
        std::vector<std::int16_t> slice(120);
        for (std::size_t z = 0; z < 27; ++z) {
            reader.read(slice.data(), 1);
            stream.push_slice(slice.data());
        }
        stream.finish();
        writer.close();
    }
    const Volume whole = local_fractal_dimension(ctx(), v, 0.5, 6);
    CHECK(same_field(read_volume(dir.file("ld.nrrd")), whole));
    // The file written slice by slice is, byte for byte, the field written whole.
    write_volume(whole, dir.file("ld_whole.nrrd"), &v);
    CHECK(file_bytes(dir.file("ld.nrrd")) == file_bytes(dir.file("ld_whole.nrrd")));
    // A writer that is not closed leaves nothing behind.
    {
        NrrdSliceWriter writer(dir.file("partial.nrrd"), v.dims(), ValueType::int16);
        writer.write(v.data(), 3);
        CHECK_THROWS_AS(writer.close(), std::logic_error);
    }
    CHECK(!fs::exists(dir.file("partial.nrrd")));
    for (auto& e : fs::directory_iterator(fs::path(dir.file("x")).parent_path()))
        CHECK(e.path().filename().string().find("partial") == std::string::npos);
}

TEST_CASE("a NRRD written slice by slice is the file written whole: every type, spacing, orientation") {
    TempDir dir;
    for (ValueType t : all_value_types) {
        for (bool oriented : {false, true}) {
            CAPTURE(value_type_name(t));
            CAPTURE(oriented);
            Volume v = testutil::random_volume(Dims{5, 4, 7}, t, 0, 100, 5);
            v.spacing = {0.5, 1.25, 3.0};
            v.oriented = oriented;
            v.origin = {-10.5, 2.0, 7.25};
            v.axes = {{{0.0, 1.0, 0.0}, {-1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}}};
            write_nrrd(v, dir.file("in.nrrd"));
            const Volume in = read_volume(dir.file("in.nrrd"));
            write_volume(in, dir.file("whole.nrrd"), &in);
            SliceReader reader(dir.file("in.nrrd"));
            SliceWriter writer(dir.file("sliced.nrrd"), in.dims(), t, reader);
            std::vector<unsigned char> slices(3 * reader.slice_bytes());
            for (std::size_t z = 0; z < 7; z += 3) {
                const std::size_t n = std::min<std::size_t>(3, 7 - z);
                reader.read(slices.data(), n);
                writer.write(slices.data(), n);
            }
            writer.close();
            const std::string whole = file_bytes(dir.file("whole.nrrd"));
            CHECK(whole.size() > v.size_bytes());
            CHECK(file_bytes(dir.file("sliced.nrrd")) == whole);
            CHECK((whole.find("space directions") != std::string::npos) == oriented);
            if (!oriented) {  // NrrdSliceWriter, given the spacing, writes the same file
                NrrdSliceWriter w(dir.file("plain.nrrd"), in.dims(), t, in.spacing);
                w.write(in.data(), 7);
                w.close();
                CHECK(file_bytes(dir.file("plain.nrrd")) == whole);
            }
        }
    }
}

TEST_CASE("a file streamed into SpanStream gives the counts of the file read whole") {
    TempDir dir;
    const Volume v = testutil::random_volume(Dims{10, 9, 25}, ValueType::uint16, 0, 300, 77);
    const std::string gz = dir.file("s.nrrd");
    write_nrrd(v, gz, true);
    SliceReader r(gz);
    const ValueRange range = value_range(r);
    const IsovalueSet iso = IsovalueSet::integers(std::int64_t(range.min), std::int64_t(range.max));
    SpanStream stream(ctx(), 10, 9, ValueType::uint16, iso, 3);
    std::vector<std::uint16_t> slice(90);
    for (std::size_t z = 0; z < 25; ++z) {
        r.read(slice.data(), 1);
        stream.push_slice(slice.data());
    }
    const SpanResult want = count_spans(ctx(), v, IsovalueSet::for_volume(v),
                                        SpanOptions{{SpanKind::cubes, SpanKind::edges}, 3, 0});
    const SpanResult got = stream.counts();
    CHECK(got.curves[0].counts == want.curves[0].counts);
    CHECK(got.curves[1].counts == want.curves[1].counts);
}

TEST_CASE("real volumes streamed from disk give the whole-volume counts") {
    const std::string dir = testutil::shared_data_or_skip("real-volume streaming checks");
    if (dir.empty()) return;
    int checked = 0;
    for (const char* file : {"engine_256x256x128_uint8.raw", "hydrogen_3d_orbital_64x64x64_float32.raw",
                             "lobster_301x324x56_uint8.raw"}) {
        const std::string path = dir + "/" + file;
        if (!fs::exists(path)) continue;
        CAPTURE(file);
        SliceReader reader(path);
        const ValueRange r = value_range(reader);
        const IsovalueSet iso = is_integer(reader.type())
                                    ? IsovalueSet::integers(std::int64_t(r.min), std::int64_t(r.max))
                                    : IsovalueSet::uniform(r.min, r.max, 256);
        SpanStream stream(ctx(), reader.dims().nx, reader.dims().ny, reader.type(), iso, 2);
        std::vector<unsigned char> slice(reader.slice_bytes());
        for (std::size_t z = 0; z < reader.dims().nz; ++z) {
            reader.read(slice.data(), 1);
            stream.push_slice(static_cast<const void*>(slice.data()));
        }
        const Volume v = read_volume(path);
        const SpanResult want = count_spans(ctx(), v, IsovalueSet::for_volume(v),
                                            SpanOptions{{SpanKind::cubes, SpanKind::edges}, 2, 0});
        const SpanResult got = stream.counts();
        CHECK(got.curves[0].counts == want.curves[0].counts);
        CHECK(got.curves[1].counts == want.curves[1].counts);
        ++checked;
    }
    MESSAGE("real volumes streamed: " << checked);
}

}  // TEST_SUITE

TEST_SUITE("stream") {

TEST_CASE("streamed targeted filter equals targeted_filter on the whole volume") {
    struct Run {
        Dims d;
        ValueType t;
        FilterSpec spec;
        int window;
        double h;
    };
    const Run runs[] = {
        {{13, 11, 17}, ValueType::uint8, FilterSpec::median(), 8, 2.3},
        {{9, 7, 12}, ValueType::uint16, FilterSpec::median(), 2, 2.0},
        {{8, 9, 10}, ValueType::int16, FilterSpec::gaussian(1.0), 8, 2.2},
        {{10, 6, 11}, ValueType::float32, FilterSpec::gaussian(0.6), 4, 2.7},
        {{7, 5, 2}, ValueType::uint8, FilterSpec::median(), 4, 2.0},
        {{6, 6, 1}, ValueType::float32, FilterSpec::median(), 8, 2.0},
    };
    std::uint32_t seed = 90;
    std::size_t runs_changed = 0;
    for (const Run& r : runs) {
        CAPTURE(value_type_name(r.t)); CAPTURE(r.d.nz); CAPTURE(r.window); CAPTURE(r.spec.describe());
        const bool unsigned_type = r.t == ValueType::uint8 || r.t == ValueType::uint16;
        const Volume v = testutil::random_volume(r.d, r.t, unsigned_type ? 0 : -6, 6, seed++);
        const double iso = 1.5;
        const TargetedResult whole = targeted_filter(ctx(), v, r.spec, iso, r.h, r.window);
        Volume streamed(r.d, r.t);
        const std::size_t slice = r.d.nx * r.d.ny * value_size(r.t);
        std::vector<std::size_t> order;
        TargetedFilterStream stream(ctx(), r.d.nx, r.d.ny, r.t, r.spec, iso, r.h, r.window,
                                    [&](std::size_t z, const void* out, const float*) {
                                        order.push_back(z);
                                        std::memcpy(static_cast<unsigned char*>(streamed.data()) + z * slice, out, slice);
                                    });
        for (std::size_t z = 0; z < r.d.nz; ++z) {
            stream.push_slice(static_cast<const unsigned char*>(v.data()) + z * slice);
            // Output slice z' leaves once slice z' + k/2 is in.
            const std::size_t half = std::size_t(r.window / 2);
            CHECK(stream.emitted() == (z + 1 > half ? z + 1 - half : 0));
        }
        stream.finish();
        REQUIRE(order.size() == r.d.nz);
        for (std::size_t z = 0; z < r.d.nz; ++z) CHECK(order[z] == z);
        CHECK(std::memcmp(streamed.data(), whole.volume.data(), v.size_bytes()) == 0);
        CHECK(stream.selected() == whole.selected);
        CHECK(stream.changed() == whole.changed);
        runs_changed += whole.changed > 0 && whole.changed < v.vertices();
    }
    CHECK(runs_changed >= 4);  // the mask matters: some vertices change, not all
    // A radius beyond k/2 cannot be streamed.
    CHECK_THROWS_AS(TargetedFilterStream(ctx(), 4, 4, ValueType::uint8, FilterSpec::gaussian(1.0), 1, 2, 2,
                                         [](std::size_t, const void*, const float*) {}),
                    InputError);
}

}  // TEST_SUITE

TEST_SUITE("stream") {

TEST_CASE("slices read into the stream's own buffer count as pushed slices") {
    const Dims d{23, 17, 41};
    const Volume v = testutil::random_volume(d, ValueType::uint16, 0, 40, 77);
    const IsovalueSet iso = IsovalueSet::integers(0, 40);
    SpanStream pushed(ctx(), d.nx, d.ny, ValueType::uint16, iso, 3), filled(ctx(), d.nx, d.ny, ValueType::uint16, iso, 3);
    const std::size_t slice = d.nx * d.ny * 2;
    const auto* bytes = static_cast<const unsigned char*>(v.data());
    for (std::size_t z = 0; z < d.nz; ++z) pushed.push_slice(static_cast<const void*>(bytes + z * slice));
    std::size_t chunks = 0;
    for (std::size_t z = 0; z < d.nz;) {
        std::size_t room = 0;
        void* dst = filled.next_slices(room);
        REQUIRE(room >= 1);
        const std::size_t n = std::min({room, d.nz - z, std::size_t(3)});  // also partial fills
        std::memcpy(dst, bytes + z * slice, n * slice);
        filled.push_filled(n);
        z += n;
        ++chunks;
    }
    CHECK(filled.slices() == d.nz);
    // The batch starts on the device's base alignment: a CPU device counts it in place.
    {
        std::size_t room0 = 0;
        SpanStream fresh(ctx(), d.nx, d.ny, ValueType::uint16, iso, 3);
        CHECK(reinterpret_cast<std::uintptr_t>(fresh.next_slices(room0)) % ctx().mem_base_align() == 0);
    }
    const SpanResult a = pushed.counts(), b = filled.counts();
    for (std::size_t k = 0; k < a.curves.size(); ++k) CHECK(a.curves[k].counts == b.curves[k].counts);
    std::size_t room = 0;
    filled.next_slices(room);
    CHECK_THROWS_AS(filled.push_filled(room + 1), std::logic_error);
    CHECK_THROWS_AS(filled.push_filled(0), std::logic_error);

    // A float slice with NaN is refused and not added.
    SpanStream f(ctx(), 4, 3, ValueType::float32, IsovalueSet::floats({0.5f, 1.5f}), 2);
    float* p = static_cast<float*>(f.next_slices(room));
    REQUIRE(room >= 2);
    std::fill(p, p + 24, 1.0f);
    p[17] = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_AS(f.push_filled(2), InputError);
    CHECK(f.slices() == 0);
}

}  // TEST_SUITE("stream")
