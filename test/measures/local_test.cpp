// Local fractal dimension fields against brute-force window counts (test/reference): the
// same NaN pattern exactly, values within 1e-6.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "clfractal/local.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/local_reference.hpp"
#include "test_util.hpp"
#include "measures/local_queries.hpp"
#include "baselines.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

constexpr double tolerance = 1e-6;

// Compares a float32 field with the reference; returns the number of defined vertices.
std::size_t check_field(const Volume& ld, const std::vector<double>& want) {
    REQUIRE(ld.type() == ValueType::float32);
    REQUIRE(ld.vertices() == want.size());
    const float* p = ld.as<float>();
    std::size_t nan_differs = 0, value_differs = 0, defined = 0, first = want.size();
    double max_error = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
        const bool got_nan = std::isnan(p[i]), want_nan = std::isnan(want[i]);
        if (got_nan != want_nan) {
            ++nan_differs;
        } else if (!want_nan) {
            ++defined;
            const double e = std::fabs(double(p[i]) - want[i]);
            max_error = std::max(max_error, e);
            if (e <= tolerance) continue;
            ++value_differs;
        } else {
            continue;
        }
        first = std::min(first, i);
    }
    if (first < want.size()) MESSAGE("first difference at vertex " << first << ": " << p[first] << " vs " << want[first]);
    CHECK(nan_differs == 0);
    CHECK(value_differs == 0);
    CHECK(max_error <= tolerance);
    return defined;
}

using testutil::Case;

// 1-vertex and 2-vertex axes, odd and even sizes, all four types, narrow value ranges so
// that most windows see intersected cubes.
const Case cases[] = {
    {{1, 1, 1}, ValueType::uint8, 0, 3},        {{2, 2, 2}, ValueType::uint8, 0, 3},
    {{1, 5, 7}, ValueType::uint8, 0, 3},        {{5, 1, 7}, ValueType::uint16, 0, 5},
    {{7, 5, 1}, ValueType::int16, -4, 4},       {{2, 3, 2}, ValueType::float32, -6, 6},
    {{3, 3, 3}, ValueType::int16, -2, 2},       {{13, 7, 11}, ValueType::uint8, 0, 5},
    {{17, 9, 5}, ValueType::uint16, 1000, 1006}, {{11, 13, 7}, ValueType::int16, -5, 5},
    {{19, 6, 9}, ValueType::float32, -8, 8},    {{16, 16, 16}, ValueType::uint8, 0, 3},
    {{15, 14, 13}, ValueType::float32, -3, 3},
    // Revision 2 types: values where a float32 isovalue would round (int32 near 2^31,
    // uint32 near 2^32), int8, float64.
    {{13, 9, 8}, ValueType::int32, 2147483000, 2147483006}, {{9, 11, 7}, ValueType::uint32, 4294967280, 4294967290},
    {{8, 7, 9}, ValueType::int8, -3, 3},                    {{11, 6, 10}, ValueType::float64, -8, 8},
};

// Isovalues of a case: a vertex value, a value between vertex values (for integer data a
// non-integer; for float data one that float32 rounds), the minimum (never intersected:
// all NaN) and one above the maximum.
std::vector<double> isovalues(const Case& c) {
    const double mid = double((c.lo + c.hi) / 2);
    if (is_integer(c.t)) return {mid, mid + 0.5, double(c.lo), double(c.hi) + 1};
    return {mid / 2, mid / 2 + 0.3, double(c.lo) / 2, double(c.hi) / 2 + 0.25};
}

const int windows[] = {2, 4, 6, 8, 40};

}  // namespace

TEST_SUITE("local") {

TEST_CASE("LD equals brute-force window counts: all types, borders, windows 2..40") {
    std::uint32_t seed = 1;
    std::size_t defined = 0;
    for (const Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        for (double iso : isovalues(c))
            for (int k : windows) {
                CAPTURE(dims_string(c.d)); CAPTURE(value_type_name(c.t)); CAPTURE(iso); CAPTURE(k);
                defined += check_field(local_fractal_dimension(ctx(), v, iso, k), ref::local_dimension_brute(v, iso, k));
            }
    }
    CHECK(defined > 10000);  // the comparison is not all NaN
}

TEST_CASE("every kernel variant, 64-bit tables and copies instead of zero-copy give the same field") {
    struct Input {
        Volume v;
        double iso;
        int k;
        std::vector<double> want;
    };
    std::vector<Input> inputs;
    std::uint32_t seed = 50;
    for (const Case& c : {cases[2], cases[3], cases[7], cases[9], cases[10], cases[11], cases[13], cases[16]})
        for (int k : {2, 6}) {
            Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
            const double iso = isovalues(c)[1];
            std::vector<double> want = ref::local_dimension_brute(v, iso, k);
            inputs.push_back({std::move(v), iso, k, std::move(want)});
        }
    testutil::TuningGuard guard;
    for (bool blocks : {true, false})
    for (const char* local_variant : {"rows", "vertices"})
        for (const char* sat_variant : {"sequential", "workgroup"})
            for (std::uint64_t max32 : {std::uint64_t(0xffffffffu), std::uint64_t(0)})
                for (bool zero_copy : {true, false}) {
                    ctx().tuning.local_blocks = blocks;
                    ctx().tuning.local_variant = parse_variant<LocalVariant>(local_variant);
                    ctx().tuning.sat_variant = parse_variant<SatVariant>(sat_variant);
                    ctx().tuning.sat_max_32bit = max32;  // 0: every grid gets 64-bit tables
                    ctx().tuning.zero_copy = zero_copy;
                    ctx().tuning.row_items = max32 ? 3 : 64;  // 64: more work-items than rows
                    ctx().tuning.sat_work_group = 48;
                    for (const Input& in : inputs) {
                        CAPTURE(blocks); CAPTURE(local_variant); CAPTURE(sat_variant); CAPTURE(max32); CAPTURE(zero_copy);
                        CAPTURE(dims_string(in.v.dims())); CAPTURE(in.k);
                        check_field(local_fractal_dimension(ctx(), in.v, in.iso, in.k), in.want);
                    }
                }
    CHECK_THROWS_AS(parse_variant<LocalVariant>("no-such-variant"), InputError);
}

TEST_CASE("float64 LD compares in double: values a float32 cannot tell apart") {
    Volume v(Dims{12, 10, 9}, ValueType::float64);
    const Volume k = testutil::random_volume(v.dims(), ValueType::int16, 0, 40, 61);
    for (std::size_t i = 0; i < v.vertices(); ++i) v.as<double>()[i] = 1 + std::ldexp(k.value(i), -40);
    const double iso = 1 + std::ldexp(20.5, -40);
    CHECK(check_field(local_fractal_dimension(ctx(), v, iso, 4), ref::local_dimension_brute(v, iso, 4)) > 100);
    CHECK(check_field(local_fractal_dimension_openmp(v, iso, 4), ref::local_dimension_brute(v, iso, 4)) > 100);
    // In float32 every value and the isovalue are 1: nothing is intersected.
    const Volume f = convert_volume(v, ValueType::float32);
    const Volume ld = local_fractal_dimension(ctx(), f, iso, 4);
    CHECK(std::all_of(ld.as<float>(), ld.as<float>() + ld.vertices(), [](float x) { return std::isnan(x); }));
}

TEST_CASE("the OpenMP baseline and the summed-area reference equal the brute force") {
    std::uint32_t seed = 90;
    for (const Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        for (double iso : isovalues(c))
            for (int k : {2, 8}) {
                CAPTURE(dims_string(c.d)); CAPTURE(value_type_name(c.t)); CAPTURE(iso); CAPTURE(k);
                const std::vector<double> want = ref::local_dimension_brute(v, iso, k);
                check_field(local_fractal_dimension_openmp(v, iso, k), want);
                const std::vector<double> sat = ref::local_dimension_sat(v, iso, k);
                for (std::size_t i = 0; i < want.size(); ++i)
                    if (!(std::isnan(want[i]) && std::isnan(sat[i])) && want[i] != sat[i]) {
                        FAIL_CHECK("summed-area reference differs at vertex " << i);
                        break;
                    }
            }
    }
}

TEST_CASE("the field stays on the device and equals the host call") {
    Volume v = testutil::random_volume({12, 10, 9}, ValueType::int16, -3, 3, 7);
    v.spacing = {0.5, 1, 2};
    const DeviceVolume values(ctx(), v);
    const DeviceVolume field = local_fractal_dimension(values, -0.5, 4);
    REQUIRE(field.dims() == v.dims());
    CHECK(field.type() == ValueType::float32);
    CHECK(field.spacing == v.spacing);
    Volume host = local_fractal_dimension(ctx(), v, -0.5, 4);
    const Volume dev = field.download();
    CHECK(std::memcmp(dev.data(), host.data(), host.size_bytes()) == 0);
    check_field(host, ref::local_dimension_brute(v, -0.5, 4));
}

TEST_CASE("the window tables are revision 2: W' first, W exactly its region in G") {
    for (std::size_t n = 1; n <= 45; ++n)
        for (int k = 2; k <= 40; k += 2) {
            const std::vector<LocalWindow> w = local_windows(n, k);
            REQUIRE(w.size() == n);
            for (std::size_t x = 0; x < n; ++x) {
                const ref::Range g = ref::window(long(x), long(n), k), sub = ref::window_sub(long(x), long((n - 1) / 2 + 1), k);
                CAPTURE(n); CAPTURE(k); CAPTURE(x);
                CHECK(w[x] == LocalWindow{int(g.lo), int(g.hi), int(sub.lo), int(sub.hi)});
                // The same region, and centred on x to within one cube (away from the borders).
                CHECK(w[x].lo == 2 * w[x].lo_sub);
                CHECK(w[x].hi == 2 * w[x].hi_sub);
                if (w[x].lo > 0 && w[x].hi < int(n) - 2) CHECK(std::abs((w[x].lo + w[x].hi) - 2 * int(x)) <= 2);
            }
        }
    CHECK_THROWS_AS(local_windows(10, 3), InputError);
    CHECK_THROWS_AS(local_windows(10, 0), InputError);
}

TEST_CASE("a plane has LD 2 wherever it is defined, up to the borders") {
    // f = x, s = 10.5: cube column x = 10 is intersected in G, column 5 in G' (10 < s <= 12).
    // W holds G cube column 10 exactly when W' holds G' column 5, and W has twice W''s extent
    // along y and z, so LD = log2(4 I / I) = 2 wherever defined.
    Volume v({32, 32, 32}, ValueType::uint8);
    for (std::size_t i = 0; i < v.vertices(); ++i) v.as<std::uint8_t>()[i] = std::uint8_t(i % 32);
    Volume ld = local_fractal_dimension(ctx(), v, 10.5, 8);
    std::size_t defined = 0;
    for (std::size_t i = 0; i < v.vertices(); ++i) {
        const float f = ld.as<float>()[i];
        if (std::isnan(f)) continue;
        CHECK(f == 2.0f);
        ++defined;
    }
    CHECK(defined == 32 * 32 * 8);  // x = 8..15: floor((x - 4) / 2) in 2..5 puts column 5 in W'
    check_field(ld, ref::local_dimension_brute(v, 10.5, 8));
}

TEST_CASE("clean analytic surfaces read as clean: under 1% of defined vertices above 2.5") {
    // A sphere (distance from the centre) and a tilted plane (a x + b y + c z), float32 and
    // quantised to uint8, at several isovalues.
    const std::size_t n = 64;
    Volume sphere({n, n, n}, ValueType::float32), plane({n, n, n}, ValueType::float32);
    Volume sphere8({n, n, n}, ValueType::uint8);
    const double c = (n - 1) / 2.0;
    for (std::size_t z = 0; z < n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const std::size_t i = sphere.index(x, y, z);
                const double r = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                sphere.as<float>()[i] = float(r);
                sphere8.as<std::uint8_t>()[i] = std::uint8_t(std::min(255.0, std::round(4 * r)));
                plane.as<float>()[i] = float(0.31 * x + 0.52 * y + 0.79 * z);
            }
    struct Surface {
        const char* name;
        const Volume& v;
        std::vector<double> isovalues;
    };
    const Surface surfaces[] = {{"sphere float32", sphere, {8.3, 15.5, 24.1}},
                                {"sphere uint8", sphere8, {40, 70, 100}},
                                {"tilted plane", plane, {20.2, 50.5, 80.7}}};
    for (const Surface& s : surfaces)
        for (double iso : s.isovalues) {
            const LocalSummary sum = summarize_local(local_fractal_dimension(ctx(), s.v, iso, 8));
            MESSAGE(std::string(s.name) << " s=" << iso << ": " << sum.defined << " defined, share > 2.5 " << sum.above_red
                           << ", mean " << sum.mean);
            CAPTURE(std::string(s.name)); CAPTURE(iso);
            CHECK(sum.defined > 1000);
            CHECK(sum.above_red < 0.01);
        }
}

TEST_CASE("noisy-sphere: the noisy half has clearly higher LD than the clean half") {
    // synthetic:noisy-sphere: the noise grows from 0 at x = 0 to +-8 at the far side.
    const Volume v = make_synthetic("noisy-sphere", SyntheticOptions{});
    const Volume ld = local_fractal_dimension(ctx(), v, 128, 8);
    double sum[2] = {0, 0};
    std::size_t count[2] = {0, 0};
    const Dims d = v.dims();
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) {
                const float f = ld.as<float>()[v.index(x, y, z)];
                if (std::isnan(f)) continue;
                const int half = 2 * x >= d.nx;
                sum[half] += f;
                ++count[half];
            }
    REQUIRE(count[0] > 1000);
    REQUIRE(count[1] > 1000);
    const double clean = sum[0] / double(count[0]), noisy = sum[1] / double(count[1]);
    MESSAGE("noisy-sphere " << dims_string(d) << " s=128: mean LD clean half " << clean << ", noisy half " << noisy);
    CHECK(clean < ld_blue);
    CHECK(noisy - clean > 0.2);  // measured: 2.056 against 2.330
}

TEST_CASE("noise raises LD: a clean sphere is blue on average, a noisy one red") {
    double previous = 0;
    for (double mu : {0.0, 8.0, 32.0}) {
        SyntheticOptions o;
        o.size = 64;
        o.noise = mu;
        LocalSummary s = summarize_local(local_fractal_dimension(ctx(), make_synthetic("sphere", o), 128, 8));
        CAPTURE(mu);
        MESSAGE("sphere 64^3 + noise " << mu << ": mean LD " << s.mean << ", share > 2.5 " << s.above_red);
        CHECK(s.mean > previous);
        if (mu == 0) CHECK(s.mean < ld_blue);
        if (mu == 32) CHECK(s.mean > ld_red);
        previous = s.mean;
    }
}

TEST_CASE("invalid windows and isovalues are input errors") {
    Volume v = testutil::random_volume({5, 5, 5}, ValueType::float32, 0, 9, 1);
    for (int k : {0, 1, 3, -2, 7})
        CHECK_THROWS_WITH_AS(local_fractal_dimension(ctx(), v, 1.0, k), doctest::Contains("window"), InputError);
    for (double s : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()})
        CHECK_THROWS_WITH_AS(local_fractal_dimension(ctx(), v, s, 8), doctest::Contains("isovalue"), InputError);
    CHECK_THROWS_AS(local_fractal_dimension_openmp(v, 1.0, 5), InputError);
    // Any finite isovalue is valid for integer data, far outside the type's range too.
    Volume u = testutil::random_volume({4, 4, 4}, ValueType::uint8, 0, 255, 2);
    for (double s : {-1e9, 1e9, 255.5, -0.5}) {
        Volume ld = local_fractal_dimension(ctx(), u, s, 2);
        CHECK(summarize_local(ld).defined == 0);
    }
}

TEST_CASE("colour map: blue up to 2.2, red from 2.5, linear between, NaN grey") {
    CHECK(ld_colour(1.0) == Rgb{0, 0, 255});
    CHECK(ld_colour(2.2) == Rgb{0, 0, 255});
    CHECK(ld_colour(2.5) == Rgb{255, 0, 0});
    CHECK(ld_colour(3.1) == Rgb{255, 0, 0});
    CHECK(ld_colour(2.44) == Rgb{204, 0, 51});
    CHECK(ld_colour(2.26) == Rgb{51, 0, 204});
    CHECK(ld_colour(-std::numeric_limits<double>::infinity()) == Rgb{0, 0, 255});
    CHECK(ld_colour(std::numeric_limits<double>::quiet_NaN()) == Rgb{128, 128, 128});
}

TEST_CASE("summary: defined vertices, shares above 2.2 and 2.5, mean") {
    Volume ld({5, 1, 1}, ValueType::float32);
    float* p = ld.as<float>();
    p[0] = 2.0f; p[1] = 2.3f; p[2] = 2.6f; p[3] = std::numeric_limits<float>::quiet_NaN(); p[4] = 2.5f;
    LocalSummary s = summarize_local(ld);
    CHECK(s.vertices == 5);
    CHECK(s.defined == 4);
    CHECK(s.above_blue == 0.75);
    CHECK(s.above_red == 0.25);
    CHECK(s.mean == doctest::Approx((2.0 + 2.3 + 2.6 + 2.5) / 4));
    Volume none({2, 2, 1}, ValueType::float32);
    for (int i = 0; i < 4; ++i) none.as<float>()[i] = std::numeric_limits<float>::quiet_NaN();
    CHECK(summarize_local(none).defined == 0);
    CHECK(std::isnan(summarize_local(none).mean));
    CHECK_THROWS_AS(summarize_local(Volume({2, 2, 2}, ValueType::uint8)), std::logic_error);
}

TEST_CASE("real volumes: brute force on small ones, summed-area reference on larger ones") {
    const std::string dir = testutil::shared_data_or_skip("real-volume LD checks");
    if (dir.empty()) return;
    struct Real {
        const char* file;
        double iso[2];
        bool brute;
    };
    const Real volumes[] = {
        {"bucky_32x32x32_uint8.raw", {40, 128.5}, true},
        {"fuel_cropped_64x33x32_uint8.raw", {10, 100}, true},
        {"hydrogen_3d_orbital_64x64x64_float32.raw", {0.01, 0.3}, false},
        {"walnut_128x96x114_uint16.raw", {1000, 8000}, false},
        {"stent_128x128x256_int16.raw", {150, 1000}, false},
    };
    for (const Real& r : volumes) {
        Volume v = read_volume(dir + "/" + r.file);
        for (double iso : r.iso) {
            CAPTURE(std::string(r.file)); CAPTURE(iso);
            Volume ld = local_fractal_dimension(ctx(), v, iso, 8);
            std::size_t defined = check_field(ld, r.brute ? ref::local_dimension_brute(v, iso, 8)
                                                          : ref::local_dimension_sat(v, iso, 8));
            MESSAGE(std::string(r.file) << " s=" << iso << ": LD defined at " << defined << " vertices, mean "
                           << summarize_local(ld).mean);
            CHECK(defined > 0);
        }
    }
}

}  // TEST_SUITE("local")

TEST_SUITE("local") {

TEST_CASE("the LD field on 2x2x2 blocks holds the full field bit for bit: all types, awkward sizes, windows") {
    testutil::TuningGuard guard;
    ctx().tuning.local_blocks = false;  // the full-size tables
    std::uint32_t seed = 900;
    for (const char* variant : {"rows", "vertices"}) {
        ctx().tuning.local_variant = parse_variant<LocalVariant>(variant);
        ctx().tuning.row_items = variant[0] == 'r' ? 5 : 0;  // 5: rows shared unevenly
        const ValueType types[] = {ValueType::uint8, ValueType::int16, ValueType::float32, ValueType::float64,
                                   ValueType::uint32};
        for (ValueType t : types)
            for (const Dims& d : {Dims{17, 13, 11}, Dims{1, 9, 8}, Dims{2, 2, 7}, Dims{24, 23, 5}, Dims{3, 31, 2}})
                for (int window : {2, 4, 8, 10}) {
                    CAPTURE(value_type_name(t));
                    CAPTURE(dims_string(d));
                    CAPTURE(window);
                    const Volume v = testutil::random_volume(d, t, 0, 9, seed++);
                    const double iso = is_integer(t) ? 5 : 2.5;
                    const Volume full = local_fractal_dimension(ctx(), v, iso, window);
                    const Dims hb = ld_block_dims(d, window);
                    const std::size_t p = std::size_t(ld_block_phase(window));
                    std::vector<float> blocks(hb.vertices());
                    with_cl_errors([&] {
                        Buffer<unsigned char> values(ctx(), v.size_bytes(), CL_MEM_READ_ONLY);
                        values.write(ctx().queue(), static_cast<const unsigned char*>(v.data()), v.size_bytes());
                        const Buffer<float> b = block_local_dimension(ctx(), values.get(), t, d, iso, window);
                        b.read(ctx().queue(), blocks.data(), blocks.size());
                    });
                    std::size_t bad = 0;
                    const float* f = full.as<float>();
                    for (std::size_t z = 0; z < d.nz; ++z)
                        for (std::size_t y = 0; y < d.ny; ++y)
                            for (std::size_t x = 0; x < d.nx; ++x) {
                                const float a = f[v.index(x, y, z)];
                                const float b = blocks[(((z + p) / 2) * hb.ny + (y + p) / 2) * hb.nx + (x + p) / 2];
                                bad += std::memcmp(&a, &b, sizeof a) != 0;
                            }
                    CAPTURE(variant);
                    CHECK(bad == 0);
                }
    }
}

}  // TEST_SUITE("local")

TEST_SUITE("local") {

// block_indicators_rows works on vectors of 16 vertex columns (8 G' cubes) and finishes each
// row one G' cube at a time; block_dimension_rows skips the rows whose windows hold no
// intersected G' cube. Widths below, at and past one chunk, with and without a tail; every
// value type over its whole range, isovalues at and past its ends.
TEST_CASE("the block LD kernels against the reference: every type, chunks and tails, windows 2-10, outside isovalues") {
    testutil::TuningGuard guard;
    std::uint32_t seed = 1500;
    std::size_t defined = 0;
    const ValueType types[] = {ValueType::int8,  ValueType::uint8, ValueType::int16,   ValueType::uint16,
                               ValueType::int32, ValueType::uint32, ValueType::float32, ValueType::float64};
    for (const char* variant : {"rows", "vertices"}) {
        ctx().tuning.local_variant = parse_variant<LocalVariant>(variant);
        for (ValueType t : types) {
            // The type's ends (float data: -4 .. 4 in halves).
            const bool integer = is_integer(t);
            const double lo = integer ? type_min(t) : -8, hi = integer ? type_max(t) : 8;
            const double vlo = integer ? lo : -4, vhi = integer ? hi : 4;
            for (const Dims& d : {Dims{53, 7, 6}, Dims{34, 5, 5}, Dims{19, 4, 9}, Dims{16, 6, 4}}) {
                ctx().tuning.row_items = d.nx == 34 ? 64 : 3;  // more work-items than rows; rows shared unevenly
                // Small values (many cubes intersected) and values over the whole range.
                const Volume small = testutil::random_volume(d, t, 0, 9, seed++);
                const Volume wide = testutil::random_volume(d, t, long(lo), long(hi), seed++);
                const std::pair<const Volume*, double> inputs[] = {
                    {&small, is_integer(t) ? 5 : 2.5}, {&wide, vhi}, {&wide, vlo + 0.5}, {&wide, vlo}, {&wide, vhi + 0.25},
                    {&wide, -1e300}, {&wide, 1e300}};
                for (const auto& [v, iso] : inputs)
                    for (int window : {2, 4, 6, 8, 10}) {
                        CAPTURE(variant);
                        CAPTURE(value_type_name(t));
                        CAPTURE(dims_string(d));
                        CAPTURE(iso);
                        CAPTURE(window);
                        const DeviceVolume values(ctx(), *v);
                        defined += check_field(local_fractal_dimension(values, iso, window).download(),
                                               ref::local_dimension_sat(*v, iso, window));
                    }
            }
        }
    }
    CHECK(defined > 10000);
}

}  // TEST_SUITE("local")
