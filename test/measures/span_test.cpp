// Span counts on the device against the plain reference (test/reference), exactly.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <tuple>

#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"
#include "baselines.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

// Compares every level and kind of a device (or OpenMP) result with the brute reference.
void check_against_reference(const Volume& v, const IsovalueSet& iso, const SpanResult& r, int levels) {
    REQUIRE(r.curves.size() == 2);
    for (int l = 0; l < levels; ++l) {
        Volume lv = ref::level(v, l);
        CHECK(r.get(SpanKind::cubes).level_dims[l] == lv.dims());
        CHECK(r.get(SpanKind::cubes).counts[l] == ref::cubes_brute(lv, iso));
        CHECK(r.get(SpanKind::edges).counts[l] == ref::edges_brute(lv, iso));
    }
}

using testutil::Case;

const Case cases[] = {
    {{2, 2, 2}, ValueType::uint8, 0, 255},     {{1, 1, 1}, ValueType::uint8, 0, 255},
    {{1, 5, 7}, ValueType::uint8, 0, 3},       {{5, 1, 7}, ValueType::uint16, 0, 9},
    {{7, 5, 1}, ValueType::int16, -4, 4},      {{2, 3, 2}, ValueType::float32, -6, 6},
    {{13, 7, 11}, ValueType::uint8, 0, 255},   {{13, 7, 11}, ValueType::uint8, 100, 103},
    {{17, 9, 5}, ValueType::uint16, 0, 65535}, {{11, 13, 7}, ValueType::int16, -32768, 32767},
    {{9, 10, 12}, ValueType::int16, -300, 40}, {{19, 6, 9}, ValueType::float32, -20, 20},
    {{65, 3, 4}, ValueType::uint8, 0, 255},    {{3, 66, 5}, ValueType::float32, 0, 1000},
    {{31, 17, 23}, ValueType::uint16, 1000, 1100},
    // x-rows of 64 and 65 cubes and longer: the CPU kernel works in chunks of 64 cubes.
    {{66, 4, 3}, ValueType::uint8, 0, 255},    {{129, 3, 2}, ValueType::float32, -50, 50},
    // The types of revision 2: int8; int32 and uint32 with narrow ranges far from 0 (every
    // integer) and with the whole type's range (uniform float64 isovalues); float64.
    {{13, 7, 11}, ValueType::int8, -128, 127}, {{5, 1, 7}, ValueType::int8, -3, 3},
    {{11, 9, 7}, ValueType::int32, 1000000000, 1000000300},
    {{12, 7, 9}, ValueType::int32, -2147483647 - 1, 2147483647},
    {{9, 11, 6}, ValueType::uint32, 0, 4294967295}, {{10, 8, 9}, ValueType::uint32, 4294967000, 4294967295},
    {{19, 6, 9}, ValueType::float64, -20, 20}, {{67, 3, 4}, ValueType::float64, -300, 300},
};

}  // namespace

TEST_SUITE("span") {

TEST_CASE("device counts equal the reference for all types, awkward sizes, 3 levels") {
    std::uint32_t seed = 1;
    for (const Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        IsovalueSet iso = IsovalueSet::for_volume(v, 64);
        CAPTURE(c.d.nx); CAPTURE(c.d.ny); CAPTURE(c.d.nz); CAPTURE(value_type_name(c.t));
        SpanOptions opt;
        opt.kinds = {SpanKind::cubes, SpanKind::edges};
        opt.levels = 3;
        check_against_reference(v, iso, count_spans(ctx(), v, iso, opt), 3);
    }
}

TEST_CASE("the two reference forms agree (brute force and difference histogram)") {
    for (const Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, 77);
        IsovalueSet iso = IsovalueSet::for_volume(v, 40);
        CHECK(ref::cubes_brute(v, iso) == ref::cubes_histogram(v, iso));
        CHECK(ref::edges_brute(v, iso) == ref::edges_histogram(v, iso));
    }
}

TEST_CASE("float isovalues at exact vertex values follow a < s <= b") {
    // Values are multiples of 0.5 and so are the isovalues: every isovalue hits vertices.
    Volume v = testutil::random_volume({9, 8, 7}, ValueType::float32, -8, 8, 5);
    std::vector<float> s;
    for (int k = -9; k <= 9; ++k) s.push_back(0.5f * float(k));
    IsovalueSet iso = IsovalueSet::floats(s);
    SpanOptions opt;
    opt.kinds = {SpanKind::cubes, SpanKind::edges};
    opt.levels = 2;
    check_against_reference(v, iso, count_spans(ctx(), v, iso, opt), 2);

    // A single cube with span [1, 2]: s = 1 does not intersect it, s = 2 does.
    Volume one({2, 2, 2}, ValueType::float32);
    float* p = one.as<float>();
    for (int i = 0; i < 8; ++i) p[i] = 1.5f;
    p[0] = 1.0f;
    p[7] = 2.0f;
    IsovalueSet three = IsovalueSet::floats({1.0f, 1.5f, 2.0f});
    auto r = count_spans(ctx(), one, three, SpanOptions{{SpanKind::cubes}, 1, 0});
    CHECK(r.get(SpanKind::cubes).counts[0] == std::vector<std::uint64_t>{0, 1, 1});
}

TEST_CASE("integer isovalues cover every integer of the value range") {
    Volume v = testutil::random_volume({6, 6, 6}, ValueType::int16, -7, 5, 9);
    IsovalueSet iso = IsovalueSet::for_volume(v);
    REQUIRE(iso.integer());
    CHECK(iso.value(0) == -7);
    CHECK(iso.size() == 13);
    auto r = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes}, 1, 0});
    CHECK(r.get(SpanKind::cubes).counts[0][0] == 0);  // nothing lies below the minimum
}

TEST_CASE("an integer isovalue range narrower than the data counts exactly") {
    // Values outside [first, last] clamp to the ends of the histogram.
    Volume v = testutil::random_volume({14, 11, 9}, ValueType::uint16, 0, 900, 21);
    IsovalueSet iso = IsovalueSet::parse_range("300:420:1", ValueType::uint16);
    SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 2, 0};
    check_against_reference(v, iso, count_spans(ctx(), v, iso, opt), 2);
    check_against_reference(v, iso, count_spans_openmp(v, iso, opt), 2);
}

TEST_CASE("integer isovalue ranges cut by the type or beyond it count exactly (bins in int and in long)") {
    // 8/16-bit data bins in int when the first isovalue is within 2^20 of 0, else in long; the
    // OpenMP baseline has the same two binners.
    SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 2, 0};
    for (const auto& [type, lo, hi, first, last] :
         {std::tuple{ValueType::int8, -128, 127, -200, 10}, std::tuple{ValueType::uint8, 20, 90, -5, 300},
          std::tuple{ValueType::int16, -300, 200, -40000, -100}, std::tuple{ValueType::uint16, 0, 5000, 4990, 70000},
          std::tuple{ValueType::uint16, 0, 5000, -2000000, -1999990}, std::tuple{ValueType::int16, -50, 50, 2000000, 2000003}}) {
        CAPTURE(value_type_name(type));
        CAPTURE(first);
        const Volume v = testutil::random_volume({13, 9, 7}, type, lo, hi, 5);
        const IsovalueSet iso = IsovalueSet::integers(first, last);
        check_against_reference(v, iso, count_spans(ctx(), v, iso, opt), 2);
        check_against_reference(v, iso, count_spans_openmp(v, iso, opt), 2);
    }
}

TEST_CASE("the default isovalue set comes with the counts (8-bit data cropped from every value of its type)") {
    // count_spans(ctx, v, opt, bins) against for_volume(v, bins) counted: the same set, value
    // for value, and the same counts of every kind and level. Volumes: every case above; 8-bit
    // ones of one value (the type's ends too), of two values at the type's ends, of values
    // that miss the type's ends; grids too thin for a cube (the range read from the values);
    // a z-part; each kind alone and both.
    std::vector<Volume> volumes;
    std::uint32_t seed = 40;
    for (const Case& c : cases) volumes.push_back(testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++));
    for (const auto& [type, lo, hi] : {std::tuple{ValueType::uint8, 0, 0}, std::tuple{ValueType::uint8, 255, 255},
                                       std::tuple{ValueType::uint8, 37, 37}, std::tuple{ValueType::int8, -128, -128},
                                       std::tuple{ValueType::int8, 127, 127}, std::tuple{ValueType::int8, -3, 3},
                                       std::tuple{ValueType::uint8, 90, 91}, std::tuple{ValueType::int8, -128, 127}})
        for (const Dims& d : {Dims{9, 8, 7}, Dims{2, 2, 2}, Dims{1, 6, 5}, Dims{6, 1, 1}, Dims{1, 1, 1}})
            volumes.push_back(testutil::random_volume(d, type, lo, hi, seed++));
    for (ValueType type : {ValueType::uint8, ValueType::int8}) {  // the type's two ends only
        Volume v = testutil::random_volume({7, 6, 5}, type, 0, 1, seed++);
        auto* b = static_cast<std::uint8_t*>(v.data());
        for (std::size_t i = 0; i < v.vertices(); ++i)
            b[i] = b[i] ? (type == ValueType::uint8 ? 255 : 127) : (type == ValueType::uint8 ? 0 : 128);
        volumes.push_back(std::move(v));
    }
    for (const Volume& v : volumes) {
        CAPTURE(v.dims().nx); CAPTURE(v.dims().ny); CAPTURE(v.dims().nz); CAPTURE(value_type_name(v.type()));
        for (const std::vector<SpanKind>& kinds : {std::vector<SpanKind>{SpanKind::cubes}, std::vector<SpanKind>{SpanKind::edges},
                                                  std::vector<SpanKind>{SpanKind::edges, SpanKind::cubes}}) {
            for (const SpanOptions& opt : {SpanOptions{kinds, 3, 0}, SpanOptions{kinds, 2, 0, 2, v.dims().nz}}) {
                if (opt.z_begin >= v.dims().nz) continue;
                CAPTURE(kinds.size()); CAPTURE(opt.z_begin);
                const IsovalueSet want = IsovalueSet::for_volume(v, 64);
                const SpanResult expected = count_spans(ctx(), v, want, opt);
                const DeviceVolume device(ctx(), v);
                for (const SpanResult& got : {count_spans(ctx(), v, opt, 64), count_spans(device, v, opt, 64)}) {
                    REQUIRE(got.isovalues.size() == want.size());
                    CHECK(got.isovalues.integer() == want.integer());
                    for (std::size_t j = 0; j < want.size(); ++j) CHECK(got.isovalues.value(j) == want.value(j));
                    REQUIRE(got.curves.size() == expected.curves.size());
                    for (std::size_t k = 0; k < kinds.size(); ++k) {
                        CHECK(got.curves[k].kind == expected.curves[k].kind);
                        CHECK(got.curves[k].level_dims == expected.curves[k].level_dims);
                        CHECK(got.curves[k].counts == expected.curves[k].counts);
                    }
                }
            }
        }
    }
    Volume other({9, 8, 7}, ValueType::uint8);
    CHECK_THROWS_AS(count_spans(DeviceVolume(ctx(), other), testutil::random_volume({9, 8, 6}, ValueType::uint8, 0, 9, 1),
                                SpanOptions{}, 256),
                    std::invalid_argument);
}

TEST_CASE("a constant volume has no intersected cube or edge") {
    Volume v({8, 9, 10}, ValueType::uint8);
    IsovalueSet iso = IsovalueSet::for_volume(v);
    auto r = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 2, 0});
    for (auto& c : r.curves)
        for (auto& lvl : c.counts)
            for (auto n : lvl) CHECK(n == 0);
}

TEST_CASE("slabs whose last one is short at coarse levels") {
    // nz - 1 not a multiple of 2^(levels-1): the last slab has a single slice at level 2.
    for (std::size_t nz : {35, 38, 34}) {
        Volume v = testutil::random_volume({9, 7, nz}, ValueType::uint8, 0, 255, unsigned(nz));
        IsovalueSet iso = IsovalueSet::for_volume(v);
        SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 3, 0};
        const SpanResult whole = count_spans(ctx(), v, iso, opt);
        for (std::size_t slices : {5, 9}) {
            CAPTURE(nz); CAPTURE(slices);
            opt.slab_slices = slices;
            SpanResult r = count_spans(ctx(), v, iso, opt);
            for (std::size_t k = 0; k < 2; ++k) CHECK(r.curves[k].counts == whole.curves[k].counts);
        }
        check_against_reference(v, iso, whole, 3);
    }
}

TEST_CASE("tiny slabs give identical counts at every level") {
    Volume v = testutil::random_volume({23, 19, 37}, ValueType::uint16, 0, 3000, 11);
    IsovalueSet iso = IsovalueSet::for_volume(v);
    SpanOptions opt;
    opt.kinds = {SpanKind::cubes, SpanKind::edges};
    opt.levels = 3;
    const SpanResult whole = count_spans(ctx(), v, iso, opt);
    CHECK(whole.slabs == 1);
    for (std::size_t slices : {5, 6, 9, 13, 36}) {
        CAPTURE(slices);
        opt.slab_slices = slices;
        SpanResult r = count_spans(ctx(), v, iso, opt);
        CHECK(r.slabs > 1);
        for (std::size_t k = 0; k < 2; ++k) CHECK(r.curves[k].counts == whole.curves[k].counts);
    }
    // One level: slabs of 2 slices (one cube layer each).
    opt.levels = 1;
    opt.slab_slices = 2;
    SpanResult r = count_spans(ctx(), v, iso, opt);
    CHECK(r.slabs == 36);
    for (std::size_t k = 0; k < 2; ++k) CHECK(r.curves[k].counts[0] == whole.curves[k].counts[0]);
    // Copied slabs (the path of GPUs) give the same counts as slabs read in place.
    testutil::TuningGuard guard;
    ctx().tuning.zero_copy = !ctx().tuning.zero_copy;
    opt.slab_slices = 3;
    r = count_spans(ctx(), v, iso, opt);
    for (std::size_t k = 0; k < 2; ++k) CHECK(r.curves[k].counts[0] == whole.curves[k].counts[0]);
    ctx().tuning = guard.saved;
    // A slab budget in bytes (Tuning::slab_bytes) splits the volume the same way.
    ctx().tuning.slab_bytes = 23 * 19 * 2 * 7;
    opt.slab_slices = 0;
    r = count_spans(ctx(), v, iso, opt);
    CHECK(r.slabs == 6);
    for (std::size_t k = 0; k < 2; ++k) CHECK(r.curves[k].counts[0] == whole.curves[k].counts[0]);
}

TEST_CASE("counts of z-parts (as MPI ranks split a volume) add up to the whole") {
    for (const Dims d : {Dims{9, 7, 37}, Dims{5, 6, 2}, Dims{4, 3, 1}, Dims{6, 5, 9}}) {
        Volume v = testutil::random_volume(d, ValueType::int16, -50, 50, unsigned(d.nz));
        IsovalueSet iso = IsovalueSet::for_volume(v);
        for (int levels : {1, 2, 3}) {
            SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, levels, 0};
            const SpanResult whole = count_spans(ctx(), v, iso, opt);
            for (std::size_t parts : {1, 2, 3, 5}) {
                CAPTURE(d.nz); CAPTURE(levels); CAPTURE(parts);
                auto ranges = split_slices(d.nz, levels, parts);
                REQUIRE(!ranges.empty());
                CHECK(ranges.size() <= parts);
                CHECK(ranges.front().first == 0);
                CHECK(ranges.back().second == d.nz);
                std::vector<std::vector<std::vector<std::uint64_t>>> sum(2);
                for (std::size_t i = 0; i < ranges.size(); ++i) {
                    if (i > 0) CHECK(ranges[i].first + 1 == ranges[i - 1].second);
                    opt.z_begin = ranges[i].first;
                    opt.z_end = ranges[i].second;
                    opt.slab_slices = (i % 2) ? 2 * (std::size_t(1) << (levels - 1)) + 1 : 0;  // slabs inside a part
                    SpanResult r = count_spans(ctx(), v, iso, opt);
                    for (std::size_t k = 0; k < 2; ++k) {
                        if (sum[k].empty()) sum[k] = r.curves[k].counts;
                        else
                            for (int l = 0; l < levels; ++l)
                                for (std::size_t j = 0; j < iso.size(); ++j) sum[k][l][j] += r.curves[k].counts[l][j];
                    }
                }
                opt.z_begin = opt.z_end = opt.slab_slices = 0;
                for (std::size_t k = 0; k < 2; ++k) CHECK(sum[k] == whole.curves[k].counts);
            }
        }
    }
    CHECK(split_slices(37, 3, 4) == std::vector<std::pair<std::size_t, std::size_t>>{{0, 9}, {8, 17}, {16, 25}, {24, 37}});
}

TEST_CASE("every kernel variant gives the reference counts") {
    testutil::TuningGuard guard;
    struct Variant {
        const char* name;
        std::size_t work_group, items, local_hist_bytes;
        bool zero_copy;
    };
    const Variant variants[] = {
        {"private", 1, 1, 0, true},        {"private", 1, 3, 0, false},      {"private", 1, 64, 0, true},
        {"atomic", 1, 1, 1 << 20, false},  {"atomic", 7, 5, 1 << 20, true},  {"atomic", 64, 16, 1 << 20, false},
        {"atomic", 32, 4, 0 /* global-memory histograms */, true},
    };
    std::uint32_t seed = 100;
    for (const Variant& var : variants) {
        ctx().tuning.span_variant = parse_variant<SpanVariant>(var.name);
        ctx().tuning.work_group = var.work_group;
        ctx().tuning.private_items = var.items;
        ctx().tuning.local_hist_bytes = var.local_hist_bytes;
        ctx().tuning.zero_copy = var.zero_copy;
        for (const Case& c : {cases[6], cases[8], cases[9], cases[11], cases[1], cases[4], cases[17], cases[19],
                              cases[20], cases[21], cases[23]}) {
            CAPTURE(var.name); CAPTURE(var.work_group); CAPTURE(var.items); CAPTURE(var.local_hist_bytes);
            CAPTURE(var.zero_copy);
            Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
            IsovalueSet iso = IsovalueSet::for_volume(v, 50);
            SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 2, 0};
            check_against_reference(v, iso, count_spans(ctx(), v, iso, opt), 2);
        }
    }
}

TEST_CASE("the OpenMP baseline gives the reference counts") {
    for (const Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, 500);
        IsovalueSet iso = IsovalueSet::for_volume(v, 33);
        SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 3, 0};
        check_against_reference(v, iso, count_spans_openmp(v, iso, opt), 3);
    }
}

TEST_CASE("float64 and wide int32/uint32 data: isovalues in the data's own type, compared exactly") {
    testutil::TuningGuard guard;
    SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 2, 0};
    const auto counted = [](const SpanResult& r) {
        std::uint64_t n = 0;
        for (auto& c : r.curves) n += *std::max_element(c.counts[0].begin(), c.counts[0].end());
        return n;
    };
    // float64 values 1 + k 2^-40: all of them are 1.0f in float32, so a float32 shortcut
    // counts nothing. Isovalues on the values (ties) and between them.
    Volume f(Dims{15, 12, 11}, ValueType::float64);
    Volume k = testutil::random_volume(f.dims(), ValueType::int16, 0, 40, 3);
    for (std::size_t i = 0; i < f.vertices(); ++i) f.as<double>()[i] = 1 + std::ldexp(k.value(i), -40);
    std::vector<double> s;
    for (int j = 0; j <= 80; ++j) s.push_back(1 + std::ldexp(0.5 * j, -40));
    const IsovalueSet fs = IsovalueSet::doubles(s);
    // The same comparisons in float32 find nothing: the check below can fail.
    const Volume f32 = convert_volume(f, ValueType::float32);
    const IsovalueSet fs32 = IsovalueSet::floats({float(s[41])});
    CHECK(fs32.value(0) == 1.0);
    CHECK(ref::cubes_brute(f32, fs32) == std::vector<std::uint64_t>{0});
    const IsovalueSet fdef = IsovalueSet::for_volume(f, 64);
    CHECK(fdef.float64());
    for (const IsovalueSet& iso : {fs, fdef})
        for (const char* variant : {"private", "atomic"}) {
            CAPTURE(variant);
            ctx().tuning.span_variant = parse_variant<SpanVariant>(variant);
            const SpanResult r = count_spans(ctx(), f, iso, opt);
            check_against_reference(f, iso, r, 2);
            CHECK(counted(r) > 100);
            check_against_reference(f, iso, count_spans_openmp(f, iso, opt), 2);
        }
    ctx().tuning = guard.saved;

    // int32 values just below 2^31 and uint32 values just below 2^32, 0..300 apart, with the
    // type's extremes present (a wide range: uniform float64 isovalues by default).
    // Isovalues on every value and halfway: float32 would merge 64 neighbours into one.
    for (ValueType t : {ValueType::int32, ValueType::uint32}) {
        CAPTURE(value_type_name(t));
        const double top = type_max(t);
        Volume v = testutil::random_volume(Dims{13, 9, 10}, t, long(top) - 300, long(top), 8);
        visit(v, [&](auto* p) { p[0] = decltype(p[0] + 0)(type_min(t)); });
        const IsovalueSet def = IsovalueSet::for_volume(v, 256);
        CHECK(def.float64());
        CHECK(def.size() == 256);
        CHECK(def.value(255) == top);
        const IsovalueSet fine =
            IsovalueSet::parse_range(std::to_string(long(top) - 301) + ".5:" + std::to_string(long(top)) + ":0.5", t);
        REQUIRE(fine.float64());
        CHECK(fine.size() == 602);
        for (const IsovalueSet& iso : {def, fine}) {
            const SpanResult r = count_spans(ctx(), v, iso, opt);
            check_against_reference(v, iso, r, 2);
            check_against_reference(v, iso, count_spans_openmp(v, iso, opt), 2);
            CHECK(counted(r) > 0);
        }
        // The narrow part alone: every integer, 2^31 - 1 and 2^32 - 1 included.
        const IsovalueSet ints = IsovalueSet::parse_range(std::to_string(long(top) - 300) + ":" +
                                                              std::to_string(long(top)) + ":1", t);
        REQUIRE(ints.integer());
        check_against_reference(v, ints, count_spans(ctx(), v, ints, opt), 2);
    }
}

TEST_CASE("isovalue sets: parsing and validation") {
    // The default set: every integer up to 65,536 of them, else uniform float64 values.
    CHECK(IsovalueSet::for_range(ValueType::int32, -5, 65530).integer());
    CHECK(IsovalueSet::for_range(ValueType::int32, -5, 65531).float64());
    CHECK(IsovalueSet::for_range(ValueType::uint32, 0, 4294967295.0, 10).size() == 10);
    CHECK(IsovalueSet::for_range(ValueType::int8, -128, 127).size() == 256);
    CHECK(IsovalueSet::for_range(ValueType::float64, 0, 1, 3).float64());
    CHECK_FALSE(IsovalueSet::for_range(ValueType::float32, 0, 1, 3).float64());
    CHECK(IsovalueSet::uniform(0, 1, 3, ValueType::float64).value(0) == 1.0 / 3);
    CHECK(IsovalueSet::uniform(0, 1, 3, ValueType::float32).value(0) == double(float(1.0 / 3)));
    // Round-trip text: 9 significant digits for float32, 17 for float64.
    CHECK(IsovalueSet::doubles({0.1}).text(0) == "0.10000000000000001");
    CHECK(IsovalueSet::floats({0.1f}).text(0) == "0.100000001");
    CHECK(IsovalueSet::integers(-3, 4).text(1) == "-2");
    CHECK(IsovalueSet::single(ValueType::int32, 2147483000.5).value(0) == 2147483001.0);
    CHECK(IsovalueSet::single(ValueType::float64, 0.1).value(0) == 0.1);
    CHECK(IsovalueSet::single(ValueType::float32, 0.1).value(0) == double(0.1f));
    CHECK(IsovalueSet::parse_range("0:10:2", ValueType::int32).float64());
    CHECK(IsovalueSet::parse_range("0:10:1", ValueType::uint32).integer());
    CHECK_THROWS_AS(IsovalueSet::parse_range("0:10:2", ValueType::int8), InputError);
    CHECK_THROWS_AS(IsovalueSet::integers(0, std::int64_t(1) << 24), InputError);
    CHECK(IsovalueSet::doubles({1, 2}).matches(ValueType::int32));
    CHECK_FALSE(IsovalueSet::doubles({1, 2}).matches(ValueType::int16));
    CHECK_FALSE(IsovalueSet::floats({1, 2}).matches(ValueType::float64));
    CHECK_THROWS_AS(count_spans(ctx(), Volume(Dims{2, 2, 2}, ValueType::float64), IsovalueSet::floats({1})),
                    std::logic_error);
    IsovalueSet r = IsovalueSet::parse_range("0.5:2:0.5", ValueType::float32);
    CHECK(r.size() == 4);
    CHECK(r.value(3) == 2.0);
    CHECK(IsovalueSet::parse_range("3:10:1", ValueType::uint8).size() == 8);
    CHECK_THROWS_AS(IsovalueSet::parse_range("3:1:1", ValueType::float32), InputError);
    CHECK_THROWS_AS(IsovalueSet::parse_range("1:3", ValueType::float32), InputError);
    CHECK_THROWS_AS(IsovalueSet::parse_range("1:3:0", ValueType::float32), InputError);
    CHECK_THROWS_AS(IsovalueSet::parse_range("1.5:3:1", ValueType::uint8), InputError);
    CHECK_THROWS_AS(IsovalueSet::floats({1.0f, 1.0f}), InputError);
    CHECK_THROWS_AS(IsovalueSet::floats({}), InputError);
    IsovalueSet u = IsovalueSet::uniform(0, 1, 4);
    CHECK(u.size() == 4);
    CHECK(u.value(0) == doctest::Approx(0.25));
    CHECK(u.value(3) == 1.0);
}

}  // TEST_SUITE("span")

TEST_SUITE("realdata") {

TEST_CASE("device counts equal the reference on every volume in shared/data") {
    const auto volumes = testutil::real_volumes("real-volume checks");
    if (volumes.empty()) return;
    int checked = 0;
    for (const testutil::RealVolume& real : volumes) {
        const std::string& file = real.file();
        Volume v = read_volume(real.path);
        IsovalueSet iso = IsovalueSet::for_volume(v);
        SpanResult r = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 2, 0});
        CAPTURE(file);
        for (int l = 0; l < 2; ++l) {
            Volume lv = ref::level(v, l);
            CHECK(r.get(SpanKind::cubes).counts[l] == ref::cubes_histogram(lv, iso));
            CHECK(r.get(SpanKind::edges).counts[l] == ref::edges_histogram(lv, iso));
        }
        ++checked;
    }
    MESSAGE("real volumes checked: " << checked);
    CHECK(checked >= 16);
}

}  // TEST_SUITE("realdata")
