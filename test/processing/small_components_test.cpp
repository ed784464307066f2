// The small-components filter against test/reference/small_components_reference (breadth-
// first search straight from the definition): every output value, every count, on random
// grids of every type and awkward sizes, K from 0 to beyond the grid, both connectivities;
// the guarantee on the result; the component counts against count_components_at; real
// volumes of four types; the errors.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>

#include "clfractal/components.hpp"
#include "clfractal/small_components.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/small_components_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

int positive_adjacency(SmallComponentsConnectivity mode) { return mode == SmallComponentsConnectivity::cube ? 26 : 6; }

// The filter's output and counts equal the reference's.
void check_against_reference(const Volume& v, double s, std::size_t k, SmallComponentsConnectivity mode) {
    const SmallComponentsResult got = small_components_filter(v, s, k, mode);
    const reference::SmallComponents want = reference::small_components_filter(v, s, k, positive_adjacency(mode));
    REQUIRE(got.volume.dims() == v.dims());
    REQUIRE(got.volume.type() == v.type());
    CHECK(std::memcmp(got.volume.data(), want.volume.data(), v.size_bytes()) == 0);
    const std::array<std::size_t, 6> counts{got.positive_before,  got.negative_before, got.positive_removed,
                                            got.negative_removed, got.positive_after,  got.negative_after};
    CHECK(counts == want.counts());
    CHECK(got.changed == want.changed);
    CHECK(got.changed_share == doctest::Approx(double(want.changed) / double(v.vertices())));
    CHECK(got.lowered + got.raised >= got.changed);
}

// The guarantee: more than k vertices, no component of either set of the result with k or
// fewer; else every vertex at the raised value.
void check_guarantee(const Volume& v, double s, std::size_t k, SmallComponentsConnectivity mode) {
    const SmallComponentsResult r = small_components_filter(v, s, k, mode);
    const std::size_t n = v.vertices();
    std::vector<bool> positive(n), negative(n);
    for (std::size_t i = 0; i < n; ++i) {
        positive[i] = r.volume.value(i) >= r.isovalue;
        negative[i] = !positive[i];
    }
    if (n > k) {
        for (std::size_t size : reference::label_components(v.dims(), positive, positive_adjacency(mode)).sizes)
            CHECK(size > k);
        for (std::size_t size : reference::label_components(v.dims(), negative, 6).sizes) CHECK(size > k);
    } else {
        for (std::size_t i = 0; i < n; ++i) CHECK(r.volume.value(i) == r.raised_value);
    }
}

const Dims awkward[] = {{1, 1, 1}, {1, 1, 7}, {2, 1, 13}, {1, 2, 2}, {5, 3, 2},
                        {7, 11, 13}, {17, 2, 19}, {23, 29, 3}};

}  // namespace

TEST_SUITE("small_components") {

TEST_CASE("equals the breadth-first reference on random grids of every type, K from 0 to beyond the grid") {
    std::uint32_t seed = 1;
    for (const ValueType t : all_value_types)
        for (const Dims& d : awkward) {
            const bool is_signed = type_min(t) < 0 || !is_integer(t);
            const long lo = is_signed ? -3 : 0, hi = is_signed ? 3 : 6;
            const Volume v = testutil::random_volume(d, t, lo, hi, seed++);
            const std::size_t n = d.vertices();
            // Integer data: s on a value and between two; float data (values / 2): likewise.
            const double mid = is_integer(t) ? double(lo + hi) / 2 : double(lo + hi) / 4;
            for (const double s : {mid, mid + 0.25, double(hi) / (is_integer(t) ? 1 : 2)})
                for (const std::size_t k : {std::size_t(0), std::size_t(1), std::size_t(2), std::size_t(5),
                                            std::size_t(20), std::size_t(100), n - 1, n, n + 1, std::size_t(1) << 40})
                    for (const auto mode : {SmallComponentsConnectivity::cube, SmallComponentsConnectivity::six}) {
                        CAPTURE(value_type_name(t));
                        CAPTURE(dims_string(d));
                        CAPTURE(s);
                        CAPTURE(k);
                        CAPTURE(small_components_connectivity_name(mode));
                        check_against_reference(v, s, k, mode);
                        check_guarantee(v, s, k, mode);
                    }
        }
}

TEST_CASE("K = 0 changes nothing; the counts before are the isosurface components of the cube convention") {
    std::uint32_t seed = 100;
    for (const ValueType t : all_value_types) {
        const Volume v = testutil::random_volume({19, 7, 11}, t, 0, 5, seed++);
        const double s = is_integer(t) ? 3 : 1.5;
        const SmallComponentsResult r = small_components_filter(v, s, 0);
        testutil::check_same(r.volume, v);
        CHECK(r.changed == 0);
        CHECK(r.positive_after == r.positive_before);
        CHECK(r.negative_after == r.negative_before);
        CHECK(std::int64_t(r.positive_before + r.negative_before) - 1 == count_components_at(ctx(), v, s));
        // The result of a larger K: its components at s by the all-isovalue sweeps.
        const SmallComponentsResult f = small_components_filter(v, s, 10);
        CHECK(f.changed > 0);
        CHECK(std::int64_t(f.positive_after + f.negative_after) - 1 == count_components_at(ctx(), f.volume, s));
    }
}

TEST_CASE("new values sit just across the isovalue in the data's type") {
    // A lone positive vertex and a lone negative vertex in a 5^3 grid split in two halves.
    for (const ValueType t : all_value_types) {
        Volume v({5, 5, 6}, t);
        visit(v, [&](auto* p) {
            using T = std::remove_pointer_t<decltype(p)>;
            for (std::size_t i = 0; i < v.vertices(); ++i) p[i] = i < 75 ? T(1) : T(9);
            p[v.index(2, 2, 1)] = T(9);  // positive island in the low half
            p[v.index(2, 2, 4)] = T(1);  // negative hole in the high half
        });
        const double s = is_integer(t) ? 4.5 : 4.3;
        const SmallComponentsResult r = small_components_filter(v, s, 1);
        CAPTURE(value_type_name(t));
        CHECK(r.positive_removed == 1);
        CHECK(r.negative_removed == 1);
        CHECK(r.changed == 2);
        if (t == ValueType::float32) {
            CHECK(r.volume.value(v.index(2, 2, 1)) == double(std::nextafter(4.3f, 0.0f)));
            CHECK(r.volume.value(v.index(2, 2, 4)) == double(4.3f));
        } else if (t == ValueType::float64) {
            CHECK(r.volume.value(v.index(2, 2, 1)) == std::nextafter(4.3, 0.0));
            CHECK(r.volume.value(v.index(2, 2, 4)) == 4.3);
        } else {
            CHECK(r.volume.value(v.index(2, 2, 1)) == 4);
            CHECK(r.volume.value(v.index(2, 2, 4)) == 5);
        }
        CHECK(r.positive_after == 1);
        CHECK(r.negative_after == 1);
    }
}

TEST_CASE("real volumes of four types equal the reference and keep the guarantee") {
    // Isovalues at which each volume has small components of both or one set.
    const std::map<std::string, double> isovalues{
        {"mni_avg152t1", 40.5}, {"walnut", 20000}, {"stent", 500}, {"m4_totaldensity", 0.3}};
    for (const auto& rv : testutil::real_volumes("small components on real volumes")) {
        const std::string name = rv.columns.at("name");
        if (!isovalues.count(name)) continue;
        const Volume v = read_volume(rv.path);
        const double s = isovalues.at(name);
        // K = 100 too where the breadth-first reference is quick (below 2 M vertices).
        for (const std::size_t k : {std::size_t(5), std::size_t(100)}) {
            if (k == 100 && v.vertices() > 2000000) continue;
            CAPTURE(name);
            CAPTURE(k);
            check_against_reference(v, s, k, SmallComponentsConnectivity::cube);
            check_guarantee(v, s, k, SmallComponentsConnectivity::cube);
            const SmallComponentsResult r = small_components_filter(v, s, k);
            CHECK(r.positive_removed + r.negative_removed > 0);
        }
    }
}

TEST_CASE("errors: isovalues with no value of the type on one side, NaN, bad connectivity names") {
    const Volume u8 = testutil::random_volume({4, 4, 4}, ValueType::uint8, 0, 9, 7);
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(u8, 0, 5); }),
                             "no uint8 value below"));
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(u8, 255.5, 5); }),
                             "no uint8 value at or above"));
    CHECK_NOTHROW(small_components_filter(u8, 255, 5));
    CHECK_NOTHROW(small_components_filter(u8, 0.5, 5));
    const Volume i8 = testutil::random_volume({4, 4, 4}, ValueType::int8, -9, 9, 7);
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(i8, -128, 5); }),
                             "no int8 value below"));
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(u8, NAN, 5); }), "finite"));
    const Volume f32 = testutil::random_volume({4, 4, 4}, ValueType::float32, -9, 9, 7);
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(f32, 1e39, 5); }),
                             "outside the float32 range"));
    CHECK(testutil::contains(
        testutil::input_error([&] { small_components_filter(f32, -double(std::numeric_limits<float>::max()), 5); }),
        "no finite float32 value below"));
    Volume nan = f32;
    nan.as<float>()[5] = NAN;
    CHECK(testutil::contains(testutil::input_error([&] { small_components_filter(nan, 0, 5); }), "NaN"));
    CHECK(testutil::contains(testutil::input_error([] { parse_small_components_connectivity("26"); }),
                             "expected one of cube, six"));
    CHECK(parse_small_components_connectivity("six") == SmallComponentsConnectivity::six);
}

}  // TEST_SUITE
