// Filters against test/reference/filter_reference: the median exactly; the Gaussian and the
// bilateral filter within a stated tolerance of the exact (double) result; the targeted and
// LD-guided filters change exactly the selected vertices; slabs equal the in-core run.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/filter_reference.hpp"
#include "test_util.hpp"
#include "measures/local_queries.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

// Tolerances against the exact result x (double), with e the accumulation's relative error:
// 1e-5 for float32 accumulation (at most a few hundred terms), 1e-12 for double (int32,
// uint32, float64: include/clfractal/filter.hpp):
//  - float data: |got - x| <= e (1 + |x|);
//  - integer data: |got - clamp(x)| <= 0.5 + e (1 + |x|), i.e. correctly rounded except
//    where x is within accumulation error of a tie, where it may round the other way
//    (at most 1 level off).
bool within(ValueType t, double got, double x) {
    const double e = is_wide(t) ? 1e-12 : 1e-5;
    if (!is_integer(t)) return std::fabs(got - x) <= e * (1 + std::fabs(x));
    return std::fabs(got - std::clamp(x, type_min(t), type_max(t))) <= 0.5 + e * (1 + std::fabs(x));
}

void check_close(const Volume& got, const std::vector<double>& want) {
    REQUIRE(got.vertices() == want.size());
    std::size_t bad = 0, first = want.size();
    for (std::size_t i = 0; i < want.size(); ++i)
        if (!within(got.type(), got.value(i), want[i])) {
            ++bad;
            first = std::min(first, i);
        }
    if (bad) MESSAGE("first difference at vertex " << first << ": " << got.value(first) << " vs " << want[first]);
    CHECK(bad == 0);
}

bool same_bytes(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

void check_equal(const Volume& got, const Volume& want) {
    REQUIRE(got.dims() == want.dims());
    REQUIRE(got.type() == want.type());
    std::size_t first = got.vertices(), bad = 0;
    for (std::size_t i = 0; i < got.vertices(); ++i)
        if (got.value(i) != want.value(i)) {
            ++bad;
            first = std::min(first, i);
        }
    if (bad) MESSAGE(bad << " differences, first at vertex " << first << ": " << got.value(first) << " vs "
                         << want.value(first));
    CHECK(bad == 0);
}

using testutil::Case;

const ValueType types[] = {ValueType::uint8, ValueType::uint16, ValueType::int16, ValueType::float32};

// 1- and 2-thick axes, primes, sizes that are no multiple of anything.
const Dims sizes[] = {{1, 1, 1}, {2, 2, 2}, {1, 5, 7}, {5, 1, 7}, {7, 5, 1}, {2, 3, 2},
                      {3, 3, 3}, {13, 7, 11}, {17, 9, 5}, {19, 6, 9}, {16, 16, 16}, {31, 2, 3}};

// Values spanning the whole type (saturation, negative values) for integer data.
Volume test_volume(const Dims& d, ValueType t, std::uint32_t seed) {
    switch (t) {
    case ValueType::uint8: return testutil::random_volume(d, t, 0, 255, seed);
    case ValueType::uint16: return testutil::random_volume(d, t, 0, 65535, seed);
    case ValueType::int16: return testutil::random_volume(d, t, -32768, 32767, seed);
    case ValueType::int8:
    case ValueType::int32:
    case ValueType::uint32: return testutil::random_volume(d, t, long(type_min(t)), long(type_max(t)), seed);
    default: return testutil::random_volume(d, t, -200, 200, seed);
    }
}

const char* variants[] = {"rows", "vertices", "tiled"};

}  // namespace

TEST_SUITE("filter") {

TEST_CASE("median equals the reference exactly: every type, awkward sizes, every variant") {
    testutil::TuningGuard guard;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        std::uint32_t seed = 1;
        for (const Dims& d : sizes)
            for (ValueType t : types) {
                CAPTURE(variant);
                CAPTURE(dims_string(d));
                CAPTURE(value_type_name(t));
                // Wide values and narrow ones (many ties).
                for (int narrow = 0; narrow < 2; ++narrow) {
                    Volume v = narrow ? testutil::random_volume(d, t, 0, 3, seed++) : test_volume(d, t, seed++);
                    check_equal(median_filter(ctx(), v), reference::median_filter(v));
                }
            }
    }
}

TEST_CASE("Gaussian within tolerance of the exact result") {
    testutil::TuningGuard guard;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        std::uint32_t seed = 100;
        for (const Dims& d : sizes)
            for (ValueType t : types)
                for (double sigma : {0.4, 1.0, 1.7}) {
                    CAPTURE(variant);
                    CAPTURE(dims_string(d));
                    CAPTURE(value_type_name(t));
                    CAPTURE(sigma);
                    Volume v = test_volume(d, t, seed++);
                    Volume g = gaussian_filter(ctx(), v, sigma);
                    CHECK(g.type() == t);
                    check_close(g, reference::gaussian_filter(v, sigma));
                }
    }
}

TEST_CASE("bilateral within tolerance of the exact result") {
    testutil::TuningGuard guard;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        std::uint32_t seed = 200;
        for (const Dims& d : sizes)
            for (ValueType t : types) {
                CAPTURE(variant);
                CAPTURE(dims_string(d));
                CAPTURE(value_type_name(t));
                Volume v = testutil::random_volume(d, t, 0, 40, seed++);
                for (auto [ss, sr] : {std::pair{0.5, 5.0}, std::pair{1.0, 12.0}}) {
                    CAPTURE(ss);
                    check_close(bilateral_filter(ctx(), v, ss, sr), reference::bilateral_filter(v, ss, sr));
                }
            }
    }
}

TEST_CASE("slabs with a halo equal the in-core run") {
    testutil::TuningGuard guard;
    const Dims d{9, 7, 23};
    for (const char* variant : variants)
        for (ValueType t : types) {
            ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
            CAPTURE(variant);
            CAPTURE(value_type_name(t));
            Volume v = testutil::random_volume(d, t, 0, 30, 7);
            const FilterSpec specs[] = {FilterSpec::median(), FilterSpec::gaussian(1.2), FilterSpec::bilateral(1, 8)};
            for (const FilterSpec& s : specs) {
                CAPTURE(s.describe());
                ctx().tuning.slab_bytes = 0;
                Volume whole = apply_filter(ctx(), v, s);
                const Volume ld = local_fractal_dimension(ctx(), v, 15, 4);
                Volume masked_whole = masked_filter(ctx(), v, s, ld, 2.3);
                // Slabs of 1, 2 and 5 output slices (input slabs = these plus the halos).
                for (std::size_t out_slices : {1, 2, 5}) {
                    ctx().tuning.slab_bytes = (out_slices + 2 * s.radius()) * d.nx * d.ny * value_size(t);
                    CAPTURE(out_slices);
                    CHECK(same_bytes(apply_filter(ctx(), v, s), whole));
                    CHECK(same_bytes(masked_filter(ctx(), v, s, ld, 2.3), masked_whole));
                    // The targeted call takes the slab path too (LD in-core).
                    CHECK(same_bytes(targeted_filter(ctx(), v, s, 15, 2.3, 4).volume, masked_whole));
                }
            }
        }
}

TEST_CASE("targeted filter changes exactly the vertices with LD > h") {
    testutil::TuningGuard guard;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        std::uint32_t seed = 300;
        for (ValueType t : types)
            for (const Dims& d : {Dims{17, 13, 11}, Dims{2, 9, 8}, Dims{24, 24, 24}}) {
                CAPTURE(variant);
                CAPTURE(value_type_name(t));
                CAPTURE(dims_string(d));
                Volume v = testutil::random_volume(d, t, 0, 12, seed++);
                const double iso = is_integer(t) ? 6 : 3;
                for (int window : {2, 8}) {
                    const Volume ld = local_fractal_dimension(ctx(), v, iso, window);
                    const float* p = ld.as<float>();
                    const FilterSpec specs[] = {FilterSpec::median(), FilterSpec::gaussian(0.8),
                                                FilterSpec::bilateral(1, 4)};
                    for (const FilterSpec& s : specs)
                        for (double h : {2.3, 2.0, -10.0}) {
                            CAPTURE(s.describe());
                            CAPTURE(window);
                            CAPTURE(h);
                            const Volume full = apply_filter(ctx(), v, s);
                            const TargetedResult r = targeted_filter(ctx(), v, s, iso, h, window);
                            REQUIRE(r.volume.type() == t);
                            std::size_t selected = 0, changed = 0, bad = 0;
                            for (std::size_t i = 0; i < v.vertices(); ++i) {
                                const bool sel = double(p[i]) > h;
                                selected += sel;
                                const double want = sel ? full.value(i) : v.value(i);
                                bad += r.volume.value(i) != want;
                                changed += r.volume.value(i) != v.value(i);
                            }
                            CHECK(bad == 0);
                            CHECK(r.selected == selected);
                            CHECK(r.changed == changed);
                            CHECK(r.selected_share == doctest::Approx(double(selected) / v.vertices()));
                            if (s.kind == FilterKind::median && selected == v.vertices()) {
                                check_equal(r.volume, reference::median_filter(v));
                            }
                        }
                }
            }
    }
}

TEST_CASE("revision 2 types: median exact, Gaussian and bilateral within tolerance, targeted and LD-guided") {
    testutil::TuningGuard guard;
    std::uint32_t seed = 400;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        for (ValueType t : {ValueType::int8, ValueType::int32, ValueType::uint32, ValueType::float64})
            for (const Dims& d : {Dims{2, 2, 2}, Dims{1, 5, 7}, Dims{19, 6, 9}, Dims{33, 4, 3}}) {
                CAPTURE(variant);
                CAPTURE(value_type_name(t));
                CAPTURE(dims_string(d));
                const Volume v = test_volume(d, t, seed++);
                check_equal(median_filter(ctx(), v), reference::median_filter(v));
                const Volume g = gaussian_filter(ctx(), v, 1.0);
                CHECK(g.type() == t);
                check_close(g, reference::gaussian_filter(v, 1.0));
                // int8 and uint32 differ from int32 only in their conversions (checked above):
                // the masked and bilateral kernels, costly to compile, run for int32 and float64.
                if (t == ValueType::int8 || t == ValueType::uint32) continue;
                const Volume small = testutil::random_volume(d, t, 0, 40, seed++);
                check_close(bilateral_filter(ctx(), small, 1.0, 12.0), reference::bilateral_filter(small, 1.0, 12.0));
                // Targeted (h = 2: a mixed selection) and LD-guided, against the full filters.
                const double iso = 20;
                const Volume ld = local_fractal_dimension(ctx(), small, iso, 4);
                for (const FilterSpec& s : {FilterSpec::median(), FilterSpec::gaussian(0.8), FilterSpec::bilateral(1, 4)}) {
                    CAPTURE(s.describe());
                    const Volume full = apply_filter(ctx(), small, s);
                    const TargetedResult r = targeted_filter(ctx(), small, s, iso, 2.0, 4);
                    std::size_t bad = 0;
                    for (std::size_t i = 0; i < small.vertices(); ++i)
                        bad += r.volume.value(i) != (ld.as<float>()[i] > 2.0f ? full.value(i) : small.value(i));
                    CHECK(bad == 0);
                }
                const TargetedResult lb = ld_bilateral_filter(ctx(), small, 1, 6, iso, 4);
                check_close(lb.volume, reference::bilateral_filter(small, 1, 6, ld.as<float>()));
            }
    }
}

TEST_CASE("threshold above every LD changes nothing") {
    Volume v = testutil::random_volume({20, 17, 9}, ValueType::uint8, 0, 255, 5);
    // LD is not bounded by 3 (windows clipped at the border can hold more than 8 times the
    // coarse count): h = the largest LD of the field.
    const Volume ld = local_fractal_dimension(ctx(), v, 128, 8);
    double h = -1e9;
    for (std::size_t i = 0; i < ld.vertices(); ++i)
        if (!std::isnan(ld.as<float>()[i])) h = std::max(h, double(ld.as<float>()[i]));
    MESSAGE("largest LD " << h);
    for (const FilterSpec& s : {FilterSpec::median(), FilterSpec::gaussian(1), FilterSpec::bilateral(1, 30)}) {
        const TargetedResult r = targeted_filter(ctx(), v, s, 128, h, 8);
        CHECK(same_bytes(r.volume, v));
        CHECK(r.selected == 0);
        CHECK(r.changed == 0);
        // An isovalue below every value: LD undefined everywhere, nothing selected at any h.
        CHECK(same_bytes(targeted_filter(ctx(), v, s, -1, -100, 8).volume, v));
    }
}

TEST_CASE("the threshold is compared exactly as a double") {
    for (double h : {2.3, 2.0, -1.0, 2.5000000001, 1e-40, 0.0}) {
        const float f = float_threshold(h);
        CHECK(double(f) <= h);
        CHECK(double(std::nextafter(f, std::numeric_limits<float>::infinity())) > h);
    }
    CHECK(float_threshold(1e300) == std::numeric_limits<float>::infinity());
    CHECK_THROWS_AS(float_threshold(std::nan("")), InputError);
}

TEST_CASE("LD-guided bilateral filter against the reference") {
    testutil::TuningGuard guard;
    for (const char* variant : variants) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        for (ValueType t : types) {
            CAPTURE(variant);
            CAPTURE(value_type_name(t));
            Volume v = testutil::random_volume({37, 12, 10}, t, 0, 20, 11);
            const double iso = is_integer(t) ? 10 : 5;
            const Volume ld = local_fractal_dimension(ctx(), v, iso, 4);
            const TargetedResult r = ld_bilateral_filter(ctx(), v, 1, 6, iso, 4);
            check_close(r.volume, reference::bilateral_filter(v, 1, 6, ld.as<float>()));
            std::size_t kept_wrong = 0, selected = 0;
            for (std::size_t i = 0; i < v.vertices(); ++i) {
                const bool on = ld.as<float>()[i] > 2.0f;
                selected += on;
                if (!on) kept_wrong += r.volume.value(i) != v.value(i);
            }
            CHECK(kept_wrong == 0);
            CHECK(r.selected == selected);
            CHECK(same_bytes(masked_filter(ctx(), v, FilterSpec::bilateral(1, 6), ld, 0, true), r.volume));
        }
    }
}

TEST_CASE("bad parameters are input errors") {
    Volume v = testutil::random_volume({4, 4, 4}, ValueType::uint8, 0, 9, 1);
    CHECK_THROWS_AS(gaussian_filter(ctx(), v, 0), InputError);
    CHECK_THROWS_AS(gaussian_filter(ctx(), v, -1), InputError);
    CHECK_THROWS_AS(gaussian_filter(ctx(), v, std::nan("")), InputError);
    CHECK_THROWS_AS(gaussian_filter(ctx(), v, 20), InputError);
    CHECK_THROWS_AS(bilateral_filter(ctx(), v, 1, 0), InputError);
    CHECK_THROWS_AS(bilateral_filter(ctx(), v, 6, 1), InputError);
    CHECK_THROWS_AS(targeted_filter(ctx(), v, FilterSpec::median(), 5, std::nan(""), 8), InputError);
    CHECK_THROWS_AS(targeted_filter(ctx(), v, FilterSpec::median(), 5, 2.3, 3), InputError);
    const Volume wrong(Dims{4, 4, 3}, ValueType::float32);
    CHECK_THROWS_AS(masked_filter(ctx(), v, FilterSpec::median(), wrong, 2.3), InputError);
}

}  // TEST_SUITE("filter")

TEST_SUITE("realdata") {

// The real volumes up to 6 M vertices (all but engine, bonsai and the teapot: their
// reference medians take seconds), every type present there.
TEST_CASE("median equals the reference exactly on the real volumes") {
    const auto volumes = testutil::real_volumes("real-volume median checks");
    if (volumes.empty()) return;
    int checked = 0;
    for (const testutil::RealVolume& real : volumes) {
        const std::string& file = real.file();
        Volume v = read_volume(real.path);
        if (v.vertices() > 6000000) continue;
        CAPTURE(file);
        check_equal(median_filter(ctx(), v), reference::median_filter(v));
        ++checked;
    }
    MESSAGE("real volumes median-checked: " << checked);
    CHECK(checked >= 13);
}

}  // TEST_SUITE("realdata")

TEST_SUITE("filter") {

TEST_CASE("the targeted median (LD on blocks) equals the masked median with the full LD field") {
    testutil::TuningGuard guard;
    std::uint32_t seed = 700;
    for (const char* variant : {"rows", "vertices"}) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        for (ValueType t : {ValueType::uint8, ValueType::float32, ValueType::int32})
            for (const Dims& d : {Dims{37, 19, 13}, Dims{1, 17, 9}, Dims{18, 2, 3}, Dims{33, 33, 33}})
                for (int window : {2, 6, 8})
                    for (double h : {2.0, 2.45}) {
                        CAPTURE(variant);
                        CAPTURE(value_type_name(t));
                        CAPTURE(dims_string(d));
                        CAPTURE(window);
                        CAPTURE(h);
                        const Volume v = testutil::random_volume(d, t, 0, 10, seed++);
                        const double iso = is_integer(t) ? 5 : 2.5;
                        const Volume ld = local_fractal_dimension(ctx(), v, iso, window);
                        const TargetedResult r = targeted_filter(ctx(), v, FilterSpec::median(), iso, h, window);
                        CHECK(same_bytes(r.volume, masked_filter(ctx(), v, FilterSpec::median(), ld, h)));
                        std::size_t selected = 0, changed = 0;
                        for (std::size_t i = 0; i < v.vertices(); ++i) {
                            selected += double(ld.as<float>()[i]) > h;
                            changed += r.volume.value(i) != v.value(i);
                        }
                        CHECK(r.selected == selected);
                        CHECK(r.changed == changed);
                    }
    }
}

// The CPU path (rows): the block selection (block_selection, after the G' tables of either
// local variant) read by median_rows, which counts the selected and changed vertices itself.
// Selection from the full LD field, medians from the reference.
TEST_CASE("the targeted median on blocks against the reference median: every type, windows 2-10") {
    testutil::TuningGuard guard;
    ctx().tuning.filter_variant = FilterVariant::rows;
    ctx().tuning.row_items = 3;
    std::uint32_t seed = 1700;
    const ValueType types[] = {ValueType::int8,  ValueType::uint8, ValueType::int16,   ValueType::uint16,
                               ValueType::int32, ValueType::uint32, ValueType::float32, ValueType::float64};
    std::size_t selected_total = 0;
    for (ValueType t : types)
        for (const Dims& d : {Dims{37, 19, 13}, Dims{18, 2, 3}, Dims{35, 6, 5}}) {
            // The G' tables from the rows kernels for the first sizes, the vertices ones for the last.
            ctx().tuning.local_variant = d.nx == 35 ? LocalVariant::vertices : LocalVariant::rows;
            const Volume v = testutil::random_volume(d, t, 0, 10, seed++);
            const Volume median = reference::median_filter(v);
            const double iso = is_integer(t) ? 5 : 2.5;
            for (int window : {2, 4, 6, 8, 10}) {
                CAPTURE(value_type_name(t));
                CAPTURE(dims_string(d));
                CAPTURE(window);
                const Volume ld = local_fractal_dimension(ctx(), v, iso, window);
                const TargetedResult r = targeted_filter(ctx(), v, FilterSpec::median(), iso, 2.0, window);
                std::size_t selected = 0, changed = 0, bad = 0;
                for (std::size_t i = 0; i < v.vertices(); ++i) {
                    const bool sel = ld.as<float>()[i] > 2.0f;
                    selected += sel;
                    changed += sel && median.value(i) != v.value(i);
                    bad += r.volume.value(i) != (sel ? median.value(i) : v.value(i));
                }
                CHECK(bad == 0);
                CHECK(r.selected == selected);
                CHECK(r.changed == changed);
                selected_total += selected;
            }
        }
    CHECK(selected_total > 1000);  // not an empty selection throughout
}

}  // TEST_SUITE("filter")
