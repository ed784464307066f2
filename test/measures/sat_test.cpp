// 3D summed-area tables on the device against the plain recurrence (test/reference), exactly.
#include <doctest/doctest.h>

#include <numeric>
#include <random>

#include "clfractal/sat.hpp"
#include "reference/local_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

// 1-thick axes, primes, lines longer than a work-group (257), y and z lines longer than
// the column blocks, and an x-y plane larger than a row stretch of the sequential kernel.
const Dims sizes[] = {{1, 1, 1},  {1, 1, 7},   {1, 7, 1},   {7, 1, 1},  {2, 3, 5},   {13, 1, 11}, {1, 17, 19},
                      {31, 29, 23}, {64, 3, 2}, {257, 5, 3}, {3, 300, 2}, {5, 4, 301}, {50, 50, 3}};

// Uniform values over the whole type: sums wrap, and the table must wrap identically.
template <class C> std::vector<C> random_counts(const Dims& d, std::uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<C> v(d.vertices());
    for (auto& x : v) x = C(rng());
    return v;
}

// Every size against the reference, in both widths, with the current tuning.
void check_all_sizes(std::uint32_t seed) {
    for (const Dims& d : sizes) {
        CAPTURE(dims_string(d));
        auto u = random_counts<cl_uint>(d, seed);
        CHECK(summed_area_table(ctx(), u, d) == ref::summed_area_table(u, d));
        auto l = random_counts<cl_ulong>(d, seed + 1);
        CHECK(summed_area_table(ctx(), l, d) == ref::summed_area_table(l, d));
        ++seed;
    }
}

}  // namespace

TEST_SUITE("sat") {

TEST_CASE("the eq. 2.8 recurrence equals the direct box sums") {
    for (const Dims& d : {Dims{1, 1, 1}, Dims{4, 1, 3}, Dims{5, 6, 7}, Dims{2, 9, 1}}) {
        auto u = random_counts<cl_uint>(d, 3);
        CHECK(ref::summed_area_table(u, d) == ref::summed_area_table_direct(u, d));
        auto l = random_counts<cl_ulong>(d, 4);
        CHECK(ref::summed_area_table(l, d) == ref::summed_area_table_direct(l, d));
    }
}

TEST_CASE("device tables equal the reference for every size, 32 and 64 bits, default variant") {
    MESSAGE("variant: " << variant_name(ctx().tuning.sat_variant));
    check_all_sizes(10);
}

TEST_CASE("every variant and work shape gives the reference tables") {
    testutil::TuningGuard guard;
    ctx().tuning.sat_variant = parse_variant<SatVariant>("sequential");
    for (std::size_t items : {1, 3, 64}) {
        CAPTURE(items);
        ctx().tuning.row_items = items;
        check_all_sizes(100);
    }
    ctx().tuning.sat_variant = parse_variant<SatVariant>("workgroup");
    // 1: one line per work-item; 7, 96: work-groups that are no power of two (96 = 32
    // columns x 3 along the axis); 256: 32 x 8.
    for (std::size_t wg : {1, 7, 64, 96, 256}) {
        CAPTURE(wg);
        ctx().tuning.sat_work_group = wg;
        check_all_sizes(200);
    }
}

TEST_CASE("counts of 0/1 indicators and 64-bit totals are exact") {
    testutil::TuningGuard guard;
    const Dims d{40, 33, 27};
    std::mt19937 rng(5);
    std::vector<cl_uint> bits(d.vertices());
    for (auto& b : bits) b = rng() & 1;
    // Values near 2^40: the totals need 64 bits.
    std::vector<cl_ulong> big(d.vertices());
    for (auto& b : big) b = (cl_ulong(1) << 40) + (rng() & 0xffff);
    for (const char* variant : {"sequential", "workgroup"}) {
        CAPTURE(variant);
        ctx().tuning.sat_variant = parse_variant<SatVariant>(variant);
        auto s = summed_area_table(ctx(), bits, d);
        CHECK(s == ref::summed_area_table(bits, d));
        CHECK(s.back() == std::accumulate(bits.begin(), bits.end(), cl_uint(0)));
        auto t = summed_area_table(ctx(), big, d);
        CHECK(t == ref::summed_area_table(big, d));
        CHECK(t.back() > (cl_ulong(1) << 32));
    }
}

TEST_CASE("a device buffer is transformed in place") {
    const Dims d{9, 8, 7};
    auto u = random_counts<cl_uint>(d, 77);
    Buffer<cl_uint> buf(ctx(), u.size());
    buf.write(ctx().queue(), u.data(), u.size());
    summed_area_table(ctx(), buf, d);
    CHECK(buf.to_host(ctx().queue()) == ref::summed_area_table(u, d));
    // A buffer of the wrong size is a programming error, reported before any launch.
    CHECK_THROWS_AS(summed_area_table(ctx(), buf, Dims{9, 8, 6}), std::logic_error);
    CHECK_THROWS_AS(summed_area_table(ctx(), u, Dims{9, 8, 8}), std::logic_error);
    testutil::TuningGuard guard;
    CHECK_THROWS_AS(parse_variant<SatVariant>("no-such-variant"), InputError);
}

TEST_CASE("the table of a uint32 DeviceVolume: a new device volume, no upload, the input kept") {
    for (const Dims& d : sizes) {
        CAPTURE(dims_string(d));
        const auto u = random_counts<cl_uint>(d, 91);
        Volume v(d, ValueType::uint32);
        std::copy(u.begin(), u.end(), v.as<cl_uint>());
        v.spacing = {1.0, 2.0, 3.0};
        const DeviceVolume dv(ctx(), v);
        const std::uint64_t before = ctx().uploads();
        const DeviceVolume table = summed_area_table(dv);
        CHECK(ctx().uploads() == before);
        const Volume t = table.download();
        CHECK(std::vector<cl_uint>(t.as<cl_uint>(), t.as<cl_uint>() + t.vertices()) == ref::summed_area_table(u, d));
        CHECK(t.spacing == v.spacing);
        const Volume kept = dv.download();
        CHECK(std::vector<cl_uint>(kept.as<cl_uint>(), kept.as<cl_uint>() + kept.vertices()) == u);
    }
    const Volume bytes(Dims{2, 2, 2}, ValueType::uint8);
    CHECK_THROWS_AS(summed_area_table(DeviceVolume(ctx(), bytes)), InputError);
}

}  // TEST_SUITE("sat")
