// The 4D fractal dimension and its local field (include/clfractal/fd4.hpp) against
// test/reference/fd4_reference (the definition, cube by cube): I4 counts exactly, on every
// value type, awkward sizes, default and odd bin widths, with bins computed in double on the
// device and by the host (the path for devices without cl_khr_fp64); the integer identity
// I4(G, 1) = sum_s I(s) + cubes against the span counts; LD4 against brute-force window sums;
// the filter targeted by LD4 against the reference mask and median.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "clfractal/fd4.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/fd4_reference.hpp"
#include "reference/filter_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

// Every type of the ValueType enum: its values are 0, 1, ... up to the first that
// value_type_name refuses, so types added to the enum are tested here without an edit.
std::vector<ValueType> every_type() {
    std::vector<ValueType> types;
    for (int i = 0;; ++i) {
        try {
            value_type_name(ValueType(i));
        } catch (const std::logic_error&) {
            break;
        }
        types.push_back(ValueType(i));
    }
    return types;
}

const Dims awkward[] = {Dims{1, 1, 1}, Dims{1, 6, 7}, Dims{2, 2, 2}, Dims{3, 3, 3}, Dims{2, 3, 5},
                        Dims{7, 11, 13}, Dims{17, 4, 9}, Dims{31, 2, 6}, Dims{20, 19, 3}};

// Random values in [7, 120] (float data: halves), so vmin is rarely 0 and every type holds them.
Volume sample(const Dims& d, ValueType t, std::uint32_t seed) { return testutil::random_volume(d, t, 7, 120, seed); }

// LD4 within 1e-5 of the reference (float32 ratio and log2), NaN exactly where the reference
// is NaN; returns the number of defined vertices compared.
std::size_t compare_field(const Volume& got, const std::vector<double>& want) {
    REQUIRE(got.type() == ValueType::float32);
    REQUIRE(got.vertices() == want.size());
    const float* p = got.as<float>();
    std::size_t defined = 0, bad = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
        const bool ok = std::isnan(want[i]) ? std::isnan(p[i]) : std::fabs(double(p[i]) - want[i]) <= 1e-5;
        if (!ok && bad++ == 0) {
            CAPTURE(i);
            CHECK(double(p[i]) == doctest::Approx(want[i]));
        }
        defined += !std::isnan(want[i]);
    }
    CHECK(bad == 0);
    return defined;
}

}  // namespace

TEST_SUITE("fd4") {

TEST_CASE("fd4 equals the definition count for count: every type, awkward sizes, bin widths, both bin paths") {
    testutil::TuningGuard guard;
    const std::vector<ValueType> types = every_type();
    REQUIRE(types.size() >= 4);
    std::uint32_t seed = 11;
    std::size_t nonzero = 0;
    for (bool fp64 : {true, false}) {
        ctx().tuning.use_fp64 = fp64;
        for (ValueType t : types)
            for (const Dims& d : awkward) {
                const Volume v = sample(d, t, seed++);
                for (double q : {0.0, 0.7, 2.5, 3.0, 1000.0}) {
                    CAPTURE(fp64); const std::string type = value_type_name(t);
                    CAPTURE(type); CAPTURE(dims_string(d)); CAPTURE(q);
                    const Fd4Result got = fractal_dimension_4d(ctx(), v, q);
                    const double want_q = q ? q : ref::default_q(v);
                    const ref::Fd4 want = ref::fd4(v, want_q);
                    CHECK(got.q == want_q);
                    CHECK(got.i4 == want.i4);
                    CHECK(got.i4_sub == want.i4_sub);
                    if (std::isnan(want.d4)) CHECK(std::isnan(got.d4));
                    else CHECK(got.d4 == doctest::Approx(want.d4).epsilon(1e-12));
                    nonzero += want.i4_sub > 0;
                }
            }
    }
    CHECK(nonzero > 100);  // not only grids without cubes
}

TEST_CASE("integer data: I4(G, 1) = sum over isovalues of I(s) + cubes(G), from the span counts") {
    std::uint32_t seed = 70;
    for (ValueType t : every_type()) {
        if (!is_integer(t)) continue;
        for (const Dims& d : {Dims{17, 13, 11}, Dims{2, 9, 8}, Dims{33, 5, 4}}) {
            const std::string type = value_type_name(t);
                    CAPTURE(type); CAPTURE(dims_string(d));
            const Volume v = sample(d, t, seed++);
            const SpanResult spans = count_spans(ctx(), v, IsovalueSet::for_volume(v));
            std::uint64_t sum = 0;
            for (std::uint64_t c : spans.get(SpanKind::cubes).counts[0]) sum += c;
            const Fd4Result r = fractal_dimension_4d(ctx(), v);
            CHECK(r.q == 1);
            CHECK(r.i4 == sum + d.cubes());
        }
    }
}

TEST_CASE("D4 reads 3 for a smooth field and rises towards 4 with noise") {
    // 49 vertices: 48 cubes per axis in G, 24 in G', so the cube count alone gives 3.
    Volume smooth(Dims{49, 49, 49}, ValueType::float32);
    float* p = smooth.as<float>();
    for (std::size_t z = 0; z < 49; ++z)
        for (std::size_t y = 0; y < 49; ++y)
            for (std::size_t x = 0; x < 49; ++x) p[smooth.index(x, y, z)] = float(x + 2 * y + 3 * z);
    CHECK(fractal_dimension_4d(ctx(), smooth).d4 == doctest::Approx(3).epsilon(0.01));
    // Independent values: a cube of G' spans as many values as one of G, in bins twice as wide.
    const Volume noise = testutil::random_volume(Dims{49, 49, 49}, ValueType::uint8, 0, 255, 5);
    CHECK(fractal_dimension_4d(ctx(), noise).d4 == doctest::Approx(4).epsilon(0.01));
}

TEST_CASE("LD4 equals brute-force window sums: every type, windows 2..40, both table widths, both variants") {
    testutil::TuningGuard guard;
    std::uint32_t seed = 200;
    std::size_t defined = 0;
    const Dims dims[] = {Dims{9, 7, 5}, Dims{2, 3, 6}, Dims{1, 5, 4}};
    for (ValueType t : every_type())
        for (const Dims& d : dims) {
            const Volume v = sample(d, t, seed++);
            for (int k : {2, 4, 6, 8, 12, 40}) {
                const double q = k == 6 ? 2.5 : 0;
                const std::vector<double> want = ref::local_dimension_4d_brute(v, q ? q : ref::default_q(v), k);
                const std::string type = value_type_name(t);
                    CAPTURE(type); CAPTURE(dims_string(d)); CAPTURE(k);
                defined += compare_field(local_fractal_dimension_4d(ctx(), v, q, k), want);
                if (k != 6 && k != 40) continue;
                // 64-bit tables, the other query variant, host bins: the same field.
                ctx().tuning.sat_max_32bit = 0;
                ctx().tuning.local_variant = guard.saved.local_variant == LocalVariant::rows ? LocalVariant::vertices : LocalVariant::rows;
                ctx().tuning.use_fp64 = false;
                compare_field(local_fractal_dimension_4d(ctx(), v, q, k), want);
                ctx().tuning = guard.saved;
            }
        }
    CHECK(defined > 1000);
}

TEST_CASE("filter targeted by LD4: the reference median exactly where LD4 > h, the input elsewhere") {
    std::uint32_t seed = 400;
    for (ValueType t : every_type()) {
        // A smooth ramp, with noise added in the slices z >= 5 only.
        Volume v = sample(Dims{19, 14, 11}, t, seed++);
        visit(v, [&](auto* p) {
            for (std::size_t z = 0; z < 11; ++z)
                for (std::size_t y = 0; y < 14; ++y)
                    for (std::size_t x = 0; x < 19; ++x) {
                        auto& f = p[v.index(x, y, z)];
                        f = decltype(+f)(10 + 2 * x + 2 * y + (z >= 5 ? double(f) / 2 : 0));
                    }
        });
        const std::vector<double> ld4 = ref::local_dimension_4d_brute(v, ref::default_q(v), 4);
        const Volume median = reference::median_filter(v);
        const Volume field = local_fractal_dimension_4d(ctx(), v, 0, 4);
        // The fixture: LD4 is 3 on the smooth slices (a ramp of slope 2: B_1 = 5 = B_2 of G').
        CHECK(ld4[v.index(9, 7, 0)] == doctest::Approx(3).epsilon(0.02));
        std::size_t some = 0;
        for (double h : {3.2, 3.5, 3.8}) {
            const std::string type = value_type_name(t);
            CAPTURE(type);
            CAPTURE(h);
            const TargetedResult r = targeted_filter(ctx(), v, FilterSpec::median(), field, h);
            // The expected volume: the median where the reference LD4 > h (NaN never
            // qualifies), the input elsewhere.
            Volume want = v;
            std::size_t selected = 0;
            visit(want, [&](auto* w) {
                using T = std::remove_pointer_t<decltype(w)>;
                for (std::size_t i = 0; i < want.vertices(); ++i)
                    if (ld4[i] > h) w[i] = median.as<T>()[i], ++selected;
            });
            REQUIRE(r.volume.type() == t);
            CHECK(std::memcmp(r.volume.data(), want.data(), want.size_bytes()) == 0);
            CHECK(r.selected == selected);
            std::size_t changed = 0;
            for (std::size_t i = 0; i < v.vertices(); ++i) changed += want.value(i) != v.value(i);
            CHECK(r.changed == changed);
            CHECK(selected < v.vertices());
            some += selected;
        }
        CHECK(some > 0);
    }
}

TEST_CASE("bad bin widths, windows and inputs are refused with one clear error") {
    const Volume v = sample(Dims{8, 8, 8}, ValueType::uint8, 3);
    for (double q : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1e-300}) {
        CAPTURE(q);
        CHECK_THROWS_AS(fractal_dimension_4d(ctx(), v, q), InputError);
        CHECK_THROWS_AS(local_fractal_dimension_4d(ctx(), v, q, 8), InputError);
        CHECK_THROWS_AS(check_bin_width(v, q), InputError);
    }
    CHECK_THROWS_WITH_AS(check_bin_width(v, 0), doctest::Contains("--q"), InputError);
    CHECK_THROWS_AS(local_fractal_dimension_4d(ctx(), v, 0, 3), InputError);
    CHECK_THROWS_AS(local_fractal_dimension_4d(ctx(), v, 0, 0), InputError);
    Volume nan(Dims{4, 4, 4}, ValueType::float32);
    nan.as<float>()[5] = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_AS(fractal_dimension_4d(ctx(), nan), InputError);
    const Volume wrong_dims(Dims{8, 8, 7}, ValueType::float32);
    CHECK_THROWS_AS(targeted_filter(ctx(), v, FilterSpec::median(), wrong_dims, 3.5), InputError);
    // A constant float volume: every cube touches one bin, D4 = log2(cubes / cubes').
    Volume flat(Dims{9, 9, 9}, ValueType::float32);
    const Fd4Result r = fractal_dimension_4d(ctx(), flat);
    CHECK(r.i4 == 512);
    CHECK(r.i4_sub == 64);
    CHECK(r.d4 == doctest::Approx(3));
}

}  // TEST_SUITE
