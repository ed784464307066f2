// The C ABI (include/clfractal/clfractal.h) against the C++ library and the reference:
// same curves, same LD field, status codes and last-error messages on bad input.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "clfractal/clfractal.h"
#include "clfractal/fd.hpp"
#include "clfractal/local.hpp"
#include "clfractal/version.hpp"
#include "reference/fd4_reference.hpp"
#include "reference/mesh_reference.hpp"
#include "reference/small_components_reference.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;

namespace {

clf_type c_type(ValueType t) {
    switch (t) {
    case ValueType::uint8: return CLF_UINT8;
    case ValueType::uint16: return CLF_UINT16;
    case ValueType::int16: return CLF_INT16;
    case ValueType::float32: return CLF_FLOAT32;
    case ValueType::int8: return CLF_INT8;
    case ValueType::int32: return CLF_INT32;
    case ValueType::uint32: return CLF_UINT32;
    case ValueType::float64: return CLF_FLOAT64;
    }
    return clf_type(-1);
}

struct CContext {
    clf_context* c = nullptr;
    CContext() { REQUIRE(clf_context_create("", &c) == CLF_OK); }
    ~CContext() { clf_context_destroy(c); }
};

bool same_double(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace

TEST_SUITE("capi") {

TEST_CASE("curves through the C ABI equal the C++ library's and the reference counts") {
    CContext cc;
    CHECK(std::string(clf_context_description(cc.c)) == testutil::ctx().description());
    std::uint32_t seed = 7;
    for (ValueType t : all_value_types) {
        for (Dims d : {Dims{13, 7, 11}, Dims{2, 2, 2}, Dims{1, 5, 9}}) {
            const bool unsigned_type = type_min(t) == 0;
            // int32 over most of its range: uniform float64 isovalues.
            Volume v = t == ValueType::int32 ? testutil::random_volume(d, t, -2000000000, 2000000000, seed++)
                                             : testutil::random_volume(d, t, unsigned_type ? 0 : -40, 100, seed++);
            clf_volume* cv = nullptr;
            REQUIRE(clf_volume_create(v.data(), d.nx, d.ny, d.nz, c_type(t), &cv) == CLF_OK);
            size_t dims[3];
            clf_volume_dims(cv, dims);
            CHECK((dims[0] == d.nx && dims[1] == d.ny && dims[2] == d.nz));
            CHECK(clf_volume_type(cv) == c_type(t));
            for (clf_kind kind : {CLF_BOX, CLF_EDGE})
                for (int levels : {2, 3}) {
                    CAPTURE(value_type_name(t)); CAPTURE(d.nx); CAPTURE(int(kind)); CAPTURE(levels);
                    clf_curve_options o;
                    clf_curve_options_default(&o);
                    o.kind = kind;
                    o.levels = levels;
                    o.bins = is_integer(t) && !is_wide(t) ? 0 : 40;
                    clf_curve* curve = nullptr;
                    REQUIRE(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_OK);
                    const SpanKind k = kind == CLF_EDGE ? SpanKind::edges : SpanKind::cubes;
                    IsovalueSet iso = IsovalueSet::for_volume(v, 40);
                    FdCurve f = fd_curve(testutil::ctx(), count_spans(testutil::ctx(), v, iso, {{k}, levels, 0}), k);
                    REQUIRE(clf_curve_size(curve) == iso.size());
                    CHECK(clf_curve_levels(curve) == levels);
                    bool all_equal = true;
                    for (int l = 0; l < levels; ++l) {
                        Volume lv = ref::level(v, l);
                        auto expected = k == SpanKind::cubes ? ref::cubes_brute(lv, iso) : ref::edges_brute(lv, iso);
                        for (std::size_t j = 0; j < iso.size(); ++j)
                            all_equal &= clf_curve_count(curve, l, j) == expected[j];
                    }
                    for (std::size_t j = 0; j < iso.size(); ++j) {
                        all_equal &= clf_curve_isovalue(curve, j) == iso.value(j);
                        all_equal &= same_double(clf_curve_dimension(curve, j), f.fd[j]);
                        all_equal &= same_double(clf_curve_dimension_fit(curve, j), levels > 2 ? f.fd_fit[j] : f.fd[j]);
                    }
                    CHECK(all_equal);
                    clf_summary s;
                    clf_curve_summary(curve, 3, &s);
                    FdSummary e = summarize(f.fd, f.counts[0], f.counts[1], 3);
                    CHECK(s.defined == e.defined);
                    CHECK(same_double(s.mean, e.mean));
                    CHECK(same_double(s.std, e.std));
                    // Out-of-range queries are harmless.
                    CHECK(std::isnan(clf_curve_dimension(curve, iso.size())));
                    CHECK(clf_curve_count(curve, levels, 0) == 0);
                    clf_curve_destroy(curve);
                }
            clf_volume_destroy(cv);
        }
    }
}

TEST_CASE("an explicit float isovalue list and the LD field through the C ABI") {
    CContext cc;
    Volume v = testutil::random_volume({12, 10, 9}, ValueType::float32, -20, 20, 3);
    clf_volume* cv = nullptr;
    REQUIRE(clf_volume_create(v.data(), 12, 10, 9, CLF_FLOAT32, &cv) == CLF_OK);
    const std::vector<float> list{-5.f, -0.5f, 0.f, 2.5f, 7.f};
    clf_curve_options o;
    clf_curve_options_default(&o);
    o.isovalues = list.data();
    o.isovalue_count = list.size();
    clf_curve* curve = nullptr;
    REQUIRE(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_OK);
    IsovalueSet iso = IsovalueSet::floats(list);
    auto expected = ref::cubes_brute(v, iso);
    REQUIRE(clf_curve_size(curve) == list.size());
    for (std::size_t j = 0; j < list.size(); ++j) CHECK(clf_curve_count(curve, 0, j) == expected[j]);
    clf_curve_destroy(curve);

    std::vector<float> ld(v.vertices());
    REQUIRE(clf_local_dimension(cc.c, cv, 0.25, 4, ld.data()) == CLF_OK);
    Volume expect = local_fractal_dimension(testutil::ctx(), v, 0.25, 4);
    CHECK(std::memcmp(ld.data(), expect.data(), expect.size_bytes()) == 0);
    clf_volume_destroy(cv);

    // The same list on float64 and int32 data: float64 isovalues of those float values;
    // an 8/16-bit integer volume takes no list.
    for (ValueType t : {ValueType::float64, ValueType::int32}) {
        CAPTURE(value_type_name(t));
        const Volume w = convert_volume(v, t);
        REQUIRE(clf_volume_create(w.data(), 12, 10, 9, c_type(t), &cv) == CLF_OK);
        CHECK(clf_volume_type(cv) == c_type(t));
        REQUIRE(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_OK);
        const auto want = ref::cubes_brute(w, IsovalueSet::doubles(std::vector<double>(list.begin(), list.end())));
        for (std::size_t j = 0; j < list.size(); ++j) CHECK(clf_curve_count(curve, 0, j) == want[j]);
        clf_curve_destroy(curve);
        REQUIRE(clf_local_dimension(cc.c, cv, 0.25, 4, ld.data()) == CLF_OK);
        expect = local_fractal_dimension(testutil::ctx(), w, 0.25, 4);
        CHECK(std::memcmp(ld.data(), expect.data(), expect.size_bytes()) == 0);
        clf_volume_destroy(cv);
    }
    const Volume u = convert_volume(v, ValueType::int16);
    REQUIRE(clf_volume_create(u.data(), 12, 10, 9, CLF_INT16, &cv) == CLF_OK);
    CHECK(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_ERROR_INPUT);
    clf_volume_destroy(cv);
    const double d64[8] = {0, 1, 2, std::numeric_limits<double>::infinity(), 4, 5, 6, 7};
    CHECK(clf_volume_create(d64, 2, 2, 2, CLF_FLOAT64, &cv) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("Inf") != std::string::npos);
    CHECK(clf_volume_create(d64, 2, 2, 2, clf_type(8), &cv) == CLF_ERROR_INPUT);
}

TEST_CASE("a stream through the C ABI gives the whole-volume curve after every slice") {
    CContext cc;
    for (ValueType t : {ValueType::uint8, ValueType::int16, ValueType::float32, ValueType::int32, ValueType::float64}) {
        CAPTURE(value_type_name(t));
        Volume v = testutil::random_volume({9, 7, 13}, t, t == ValueType::uint8 ? 0 : -30, 60, 17);
        const ValueRange r = value_range(v);
        const double range[2] = {r.min, r.max};
        clf_curve_options o;
        clf_curve_options_default(&o);
        o.levels = 3;
        o.bins = is_integer(t) ? 0 : 50;
        clf_stream* st = nullptr;
        REQUIRE(clf_stream_create(cc.c, 9, 7, c_type(t), &o, range, &st) == CLF_OK);
        const std::size_t slice = 9 * 7 * value_size(t);
        for (std::size_t z = 0; z < 13; ++z) {
            REQUIRE(clf_stream_push_slice(st, static_cast<const unsigned char*>(v.data()) + z * slice) == CLF_OK);
            CHECK(clf_stream_slices(st) == z + 1);
            if (z < 1 || z % 4 != 0) continue;
            Volume part(Dims{9, 7, z + 1}, t);
            std::memcpy(part.data(), v.data(), (z + 1) * slice);
            const IsovalueSet iso = IsovalueSet::for_range(t, r.min, r.max, 50);
            for (clf_kind kind : {CLF_BOX, CLF_EDGE}) {
                const SpanKind k = kind == CLF_EDGE ? SpanKind::edges : SpanKind::cubes;
                clf_curve* curve = nullptr;
                REQUIRE(clf_stream_curve(st, kind, &curve) == CLF_OK);
                REQUIRE(clf_curve_size(curve) == iso.size());
                bool equal = true;
                for (int l = 0; l < 3; ++l) {
                    Volume lv = ref::level(part, l);
                    auto expected = k == SpanKind::cubes ? ref::cubes_brute(lv, iso) : ref::edges_brute(lv, iso);
                    for (std::size_t j = 0; j < iso.size(); ++j) equal &= clf_curve_count(curve, l, j) == expected[j];
                }
                CHECK(equal);
                clf_curve_destroy(curve);
            }
        }
        clf_stream_destroy(st);
    }
    // Float data without a range or list, NaN slices, bad levels: input errors.
    clf_stream* st = reinterpret_cast<clf_stream*>(1);
    CHECK(clf_stream_create(cc.c, 4, 4, CLF_FLOAT32, nullptr, nullptr, &st) == CLF_ERROR_INPUT);
    CHECK(st == nullptr);
    const double bad[2] = {5, 1};
    CHECK(clf_stream_create(cc.c, 4, 4, CLF_UINT8, nullptr, bad, &st) == CLF_ERROR_INPUT);
    const double ok[2] = {0, 1};
    REQUIRE(clf_stream_create(cc.c, 2, 2, CLF_FLOAT32, nullptr, ok, &st) == CLF_OK);
    const float nan_slice[4] = {0, 1, std::numeric_limits<float>::quiet_NaN(), 0};
    CHECK(clf_stream_push_slice(st, nan_slice) == CLF_ERROR_INPUT);
    CHECK(clf_stream_slices(st) == 0);
    CHECK(clf_stream_push_slice(st, nullptr) == CLF_ERROR_INPUT);
    clf_stream_destroy(st);
}

TEST_CASE("bad input through the C ABI: a status, a message, NULL handles, no exception") {
    CContext cc;
    clf_volume* cv = reinterpret_cast<clf_volume*>(1);
    CHECK(clf_volume_read("/nonexistent/volume.nrrd", &cv) == CLF_ERROR_INPUT);
    CHECK(cv == nullptr);
    CHECK(std::string(clf_last_error()).find("/nonexistent/volume.nrrd") != std::string::npos);

    float nan_data[8] = {0, 1, 2, 3, 4, 5, 6, std::numeric_limits<float>::quiet_NaN()};
    CHECK(clf_volume_create(nan_data, 2, 2, 2, CLF_FLOAT32, &cv) == CLF_ERROR_INPUT);
    CHECK(cv == nullptr);
    CHECK(std::string(clf_last_error()).find("NaN") != std::string::npos);
    CHECK(clf_volume_create(nan_data, 2, 2, 2, 9, &cv) == CLF_ERROR_INPUT);
    CHECK(clf_volume_create(nullptr, 2, 2, 2, CLF_UINT8, &cv) == CLF_ERROR_INPUT);
    CHECK(clf_volume_create(nan_data, 0, 2, 2, CLF_UINT8, &cv) == CLF_ERROR_INPUT);
    CHECK(clf_volume_create(nan_data, std::size_t(1) << 30, std::size_t(1) << 30, 4, CLF_UINT8, &cv) ==
          CLF_ERROR_INPUT);
    CHECK(cv == nullptr);

    unsigned char bytes[8] = {0, 10, 20, 30, 40, 50, 60, 70};
    REQUIRE(clf_volume_create(bytes, 2, 2, 2, CLF_UINT8, &cv) == CLF_OK);
    clf_curve_options o;
    clf_curve_options_default(&o);
    clf_curve* curve = reinterpret_cast<clf_curve*>(1);
    o.levels = 1;
    CHECK(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_ERROR_INPUT);
    CHECK(curve == nullptr);
    CHECK(std::string(clf_last_error()).find("levels") != std::string::npos);
    o.levels = 2;
    o.bins = 16;
    CHECK(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_ERROR_INPUT);
    CHECK(clf_curve_compute(nullptr, cv, nullptr, &curve) == CLF_ERROR_INPUT);
    CHECK(clf_curve_compute(cc.c, cv, nullptr, nullptr) == CLF_ERROR_INPUT);
    float ld[8];
    CHECK(clf_local_dimension(cc.c, cv, 35, 3, ld) == CLF_ERROR_INPUT);  // odd window
    CHECK(clf_context_create("no such device anywhere", nullptr) == CLF_ERROR_INPUT);
    clf_context* none = reinterpret_cast<clf_context*>(1);
    CHECK(clf_context_create("no such device anywhere", &none) == CLF_ERROR_DEVICE);
    CHECK(none == nullptr);
    CHECK(std::string(clf_last_error()).find("no such device anywhere") != std::string::npos);
    clf_volume_destroy(cv);
    // Destroying NULL is allowed.
    clf_volume_destroy(nullptr);
    clf_curve_destroy(nullptr);
    clf_context_destroy(nullptr);
    // One version number: the C ABI, the C++ library and the generated header agree.
    CHECK(std::string(clf_version()) == clfractal::version());
    CHECK(std::string(clf_version()) == CLFRACTAL_VERSION_STRING);
}

TEST_CASE("every C entry point checks handles, enums and ranges; clf_last_error follows every call") {
    CContext cc;
    unsigned char bytes[8] = {0, 10, 20, 30, 40, 50, 60, 70};
    clf_volume* cv = nullptr;
    // Types and kinds are ints, checked before any conversion: any int is safe.
    for (int bad : {-1, 8, 9, 1 << 30, std::numeric_limits<int>::min()}) {
        CAPTURE(bad);
        CHECK(clf_volume_create(bytes, 2, 2, 2, bad, &cv) == CLF_ERROR_INPUT);
        CHECK(std::string(clf_last_error()).find("unknown clf_type") != std::string::npos);
        clf_stream* st = reinterpret_cast<clf_stream*>(1);
        CHECK(clf_stream_create(cc.c, 2, 2, bad, nullptr, nullptr, &st) == CLF_ERROR_INPUT);
        CHECK(st == nullptr);
    }
    REQUIRE(clf_volume_create(bytes, 2, 2, 2, CLF_UINT8, &cv) == CLF_OK);
    CHECK(std::string(clf_last_error()).empty());
    clf_curve_options o;
    clf_curve_options_default(&o);
    clf_curve* curve = nullptr;
    for (int bad : {-1, 2, 77}) {
        o.kind = bad;
        CHECK(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_ERROR_INPUT);
        CHECK(std::string(clf_last_error()).find("CLF_BOX or CLF_EDGE") != std::string::npos);
        CHECK(curve == nullptr);
    }
    o.kind = CLF_EDGE;
    REQUIRE(clf_curve_compute(cc.c, cv, &o, &curve) == CLF_OK);
    CHECK(std::string(clf_last_error()).empty());

    // Getters: a fallback value on NULL or out of range, with the reason; "" when fine.
    CHECK(clf_volume_type(nullptr) == CLF_TYPE_NONE);
    CHECK(std::string(clf_last_error()).find("NULL") != std::string::npos);
    CHECK(clf_volume_type(cv) == CLF_UINT8);
    CHECK(std::string(clf_last_error()).empty());
    size_t dims[3] = {7, 7, 7};
    clf_volume_dims(nullptr, dims);
    CHECK(dims[0] == 7);
    CHECK(!std::string(clf_last_error()).empty());
    clf_volume_dims(cv, nullptr);
    CHECK(!std::string(clf_last_error()).empty());
    clf_volume_dims(cv, dims);
    CHECK((dims[0] == 2 && dims[1] == 2 && dims[2] == 2));
    CHECK(std::string(clf_last_error()).empty());
    CHECK(clf_curve_size(nullptr) == 0);
    CHECK(clf_curve_levels(nullptr) == 0);
    CHECK(std::isnan(clf_curve_isovalue(curve, clf_curve_size(curve))));
    CHECK(std::string(clf_last_error()).find("out of range") != std::string::npos);
    CHECK(std::isnan(clf_curve_dimension(nullptr, 0)));
    CHECK(std::isnan(clf_curve_dimension_fit(curve, 1u << 30)));
    CHECK(clf_curve_count(curve, -1, 0) == 0);
    CHECK(clf_curve_count(curve, 2, 0) == 0);
    CHECK(clf_curve_isovalue(curve, 0) == 0);
    CHECK(std::string(clf_last_error()).empty());
    clf_summary summary{};
    clf_curve_summary(nullptr, 0, &summary);
    CHECK(!std::string(clf_last_error()).empty());
    clf_curve_summary(curve, 0, nullptr);
    CHECK(!std::string(clf_last_error()).empty());
    CHECK(clf_stream_slices(nullptr) == 0);
    CHECK(std::string(clf_context_description(nullptr)).empty());
    CHECK(!std::string(clf_last_error()).empty());
    CHECK(!std::string(clf_context_description(cc.c)).empty());
    CHECK(std::string(clf_last_error()).empty());
    clf_curve_options_default(nullptr);
    CHECK(!std::string(clf_last_error()).empty());

    // Streams: NULL handles and kinds; an int16 range far outside the type is clipped
    // before any conversion to an integer ({-1e19, 10}: every int16 from -32768 to 10).
    CHECK(clf_stream_push_slice(nullptr, bytes) == CLF_ERROR_INPUT);
    clf_curve* sc = nullptr;
    CHECK(clf_stream_curve(nullptr, CLF_BOX, &sc) == CLF_ERROR_INPUT);
    clf_stream* st = nullptr;
    const double wide[2] = {-1e19, 10};
    REQUIRE(clf_stream_create(cc.c, 2, 2, CLF_INT16, nullptr, wide, &st) == CLF_OK);
    const std::int16_t slice[4] = {-5, 3, 10, -32768};
    REQUIRE(clf_stream_push_slice(st, slice) == CLF_OK);
    REQUIRE(clf_stream_push_slice(st, slice) == CLF_OK);
    CHECK(clf_stream_curve(st, 5, &sc) == CLF_ERROR_INPUT);
    CHECK(sc == nullptr);
    REQUIRE(clf_stream_curve(st, CLF_BOX, &sc) == CLF_OK);
    CHECK(clf_curve_size(sc) == 32768 + 10 + 1);
    CHECK(clf_curve_isovalue(sc, 0) == -32768);
    CHECK(clf_curve_isovalue(sc, clf_curve_size(sc) - 1) == 10);
    clf_curve_destroy(sc);
    clf_stream_destroy(st);
    st = reinterpret_cast<clf_stream*>(1);
    const double beyond[2] = {1e19, 1e30};
    CHECK(clf_stream_create(cc.c, 2, 2, CLF_INT16, nullptr, beyond, &st) == CLF_ERROR_INPUT);
    CHECK(st == nullptr);
    const double nan_range[2] = {std::numeric_limits<double>::quiet_NaN(), 1};
    CHECK(clf_stream_create(cc.c, 2, 2, CLF_UINT16, nullptr, nan_range, &st) == CLF_ERROR_INPUT);

    // A host allocation that fails (4 TiB) is out of memory, not bad input. (ASan's operator
    // new aborts on such a request instead of throwing, so not under ASan.)
#ifndef __SANITIZE_ADDRESS__
    clf_volume* huge = reinterpret_cast<clf_volume*>(1);
    CHECK(clf_volume_create(bytes, std::size_t(1) << 14, std::size_t(1) << 14, std::size_t(1) << 12, CLF_FLOAT32,
                            &huge) == CLF_ERROR_OUT_OF_MEMORY);
    CHECK(huge == nullptr);
    CHECK(std::string(clf_last_error()).find("cannot allocate") != std::string::npos);
#endif
    CHECK(clf_local_dimension(cc.c, nullptr, 1, 8, nullptr) == CLF_ERROR_INPUT);
    clf_curve_destroy(curve);
    clf_volume_destroy(cv);
    CHECK(std::string(clf_last_error()).empty());
}

TEST_CASE("D4 through the C ABI equals the definition count for count, every type; bad q is refused") {
    CContext cc;
    const ValueType types[] = {ValueType::uint8, ValueType::int8,  ValueType::uint16,  ValueType::int16,
                               ValueType::int32, ValueType::uint32, ValueType::float32, ValueType::float64};
    std::uint32_t seed = 40;
    for (ValueType t : types) {
        for (const Dims& d : {Dims{9, 7, 5}, Dims{2, 2, 2}, Dims{17, 3, 11}}) {
            CAPTURE(value_type_name(t));
            CAPTURE(d.nx);
            const Volume v = testutil::random_volume(d, t, 0, 90, ++seed);
            clf_volume* cv = nullptr;
            REQUIRE(clf_volume_create(v.data(), d.nx, d.ny, d.nz, c_type(t), &cv) == CLF_OK);
            for (double q : {0.0, 3.0, 0.75}) {
                CAPTURE(q);
                clf_fd4 r{};
                REQUIRE(clf_fd4_compute(cc.c, cv, q, &r) == CLF_OK);
                CHECK(std::string(clf_last_error()).empty());
                const double want_q = q ? q : ref::default_q(v);
                const ref::Fd4 want = ref::fd4(v, want_q);
                CHECK(r.q == want_q);
                CHECK(r.i4_l0 == want.i4);
                CHECK(r.i4_l1 == want.i4_sub);
                CHECK(same_double(r.d4, want.d4));
            }
            clf_volume_destroy(cv);
        }
    }
    const Volume v = testutil::random_volume(Dims{5, 5, 5}, ValueType::uint8, 0, 200, 3);
    clf_volume* cv = nullptr;
    REQUIRE(clf_volume_create(v.data(), 5, 5, 5, CLF_UINT8, &cv) == CLF_OK);
    clf_fd4 r{};
    for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        CAPTURE(bad);
        CHECK(clf_fd4_compute(cc.c, cv, bad, &r) == CLF_ERROR_INPUT);
        CHECK(std::string(clf_last_error()).find("q") != std::string::npos);
    }
    CHECK(clf_fd4_compute(cc.c, cv, 1e-300, &r) == CLF_ERROR_INPUT);  // the bins would overflow
    CHECK(!std::string(clf_last_error()).empty());
    CHECK(clf_fd4_compute(nullptr, cv, 0, &r) == CLF_ERROR_INPUT);
    CHECK(clf_fd4_compute(cc.c, nullptr, 0, &r) == CLF_ERROR_INPUT);
    CHECK(clf_fd4_compute(cc.c, cv, 0, nullptr) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("NULL") != std::string::npos);
    clf_volume_destroy(cv);
}

TEST_CASE("the small-components filter through the C ABI equals the reference, every type; bad input is refused") {
    std::uint32_t seed = 70;
    for (const ValueType t : all_value_types)
        for (const int connectivity : {int(CLF_SMALL_CUBE), int(CLF_SMALL_SIX)}) {
            CAPTURE(value_type_name(t));
            CAPTURE(connectivity);
            const Dims d{13, 6, 9};
            const Volume v = testutil::random_volume(d, t, 0, 6, ++seed);
            const double s = is_integer(t) ? 3.5 : 1.75;
            clf_volume* cv = nullptr;
            REQUIRE(clf_volume_create(v.data(), d.nx, d.ny, d.nz, c_type(t), &cv) == CLF_OK);
            std::vector<unsigned char> out(v.size_bytes());
            clf_small_components st{};
            REQUIRE(clf_small_components_filter(cv, s, 4, connectivity, out.data(), &st) == CLF_OK);
            CHECK(std::string(clf_last_error()).empty());
            const reference::SmallComponents want =
                reference::small_components_filter(v, s, 4, connectivity == int(CLF_SMALL_CUBE) ? 26 : 6);
            CHECK(std::memcmp(out.data(), want.volume.data(), out.size()) == 0);
            const std::array<std::size_t, 6> counts{st.positive_before,  st.negative_before, st.positive_removed,
                                                    st.negative_removed, st.positive_after,  st.negative_after};
            CHECK(counts == want.counts());
            CHECK(st.changed == want.changed);
            CHECK(st.isovalue == (is_integer(t) ? 4.0 : s));
            REQUIRE(clf_small_components_filter(cv, s, 4, connectivity, out.data(), nullptr) == CLF_OK);
            clf_volume_destroy(cv);
        }
    const Volume v = testutil::random_volume(Dims{5, 5, 5}, ValueType::uint8, 0, 200, 3);
    clf_volume* cv = nullptr;
    REQUIRE(clf_volume_create(v.data(), 5, 5, 5, CLF_UINT8, &cv) == CLF_OK);
    std::vector<unsigned char> out(v.size_bytes());
    CHECK(clf_small_components_filter(cv, 100, 4, 2, out.data(), nullptr) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("CLF_SMALL_CUBE") != std::string::npos);
    CHECK(clf_small_components_filter(cv, 300, 4, CLF_SMALL_CUBE, out.data(), nullptr) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("no uint8 value at or above") != std::string::npos);
    CHECK(clf_small_components_filter(cv, std::nan(""), 4, CLF_SMALL_CUBE, out.data(), nullptr) == CLF_ERROR_INPUT);
    CHECK(clf_small_components_filter(nullptr, 100, 4, CLF_SMALL_CUBE, out.data(), nullptr) == CLF_ERROR_INPUT);
    CHECK(clf_small_components_filter(cv, 100, 4, CLF_SMALL_CUBE, nullptr, nullptr) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("NULL") != std::string::npos);
    clf_volume_destroy(cv);
}

TEST_CASE("component counts streamed through the C ABI equal breadth-first search after every batch, every type") {
    std::uint32_t seed = 90;
    for (const ValueType t : all_value_types)
        for (const int connectivity : {int(CLF_COMPONENTS_CUBE), int(CLF_COMPONENTS_FREUDENTHAL)}) {
            CAPTURE(value_type_name(t));
            CAPTURE(connectivity);
            const Dims d{11, 8, 10};
            const Volume v = testutil::random_volume(d, t, 0, 7, ++seed);
            const std::vector<double> at = {-1, 0.5, 1.75, 3, 4.5, 100};
            clf_components_stream* st = nullptr;
            REQUIRE(clf_components_stream_create(d.nx, d.ny, c_type(t), at.data(), at.size(), connectivity, &st) ==
                    CLF_OK);
            const auto a = connectivity == CLF_COMPONENTS_CUBE ? ref::Adjacency::six : ref::Adjacency::fourteen;
            const auto c = connectivity == CLF_COMPONENTS_CUBE ? ref::Adjacency::twenty_six : ref::Adjacency::fourteen;
            const std::size_t slice = d.nx * d.ny * value_size(t);
            for (std::size_t z = 0; z < d.nz; z += 3) {
                const std::size_t n = std::min<std::size_t>(3, d.nz - z);
                REQUIRE(clf_components_stream_push(st, static_cast<const unsigned char*>(v.data()) + z * slice, n) ==
                        CLF_OK);
                CHECK(clf_components_stream_slices(st) == z + n);
                Volume part(Dims{d.nx, d.ny, z + n}, t);
                std::memcpy(part.data(), v.data(), part.size_bytes());
                std::vector<std::int64_t> got(at.size(), -7);
                REQUIRE(clf_components_stream_counts(st, got.data()) == CLF_OK);
                for (std::size_t j = 0; j < at.size(); ++j) {
                    // Compared as the stream compares: at the isovalue the data's type holds.
                    const double s = is_integer(t) ? std::ceil(at[j]) : t == ValueType::float32 ? double(float(at[j])) : at[j];
                    const std::size_t na = ref::components(part, s, false, a), nc = ref::components(part, s, true, c);
                    CHECK(got[j] == (na && nc ? std::int64_t(na + nc) - 1 : 0));
                }
            }
            clf_components_stream_destroy(st);
        }
    // NaN slices add nothing; bad arguments are input errors.
    clf_components_stream* st = nullptr;
    const double s[1] = {0.5};
    REQUIRE(clf_components_stream_create(2, 2, CLF_FLOAT32, s, 1, CLF_COMPONENTS_CUBE, &st) == CLF_OK);
    const float bad[4] = {0, 1, std::nanf(""), 1};
    CHECK(clf_components_stream_push(st, bad, 1) == CLF_ERROR_INPUT);
    CHECK(std::string(clf_last_error()).find("NaN") != std::string::npos);
    CHECK(clf_components_stream_slices(st) == 0);
    // An isovalue beyond float32's range: every value below it, so no surface there.
    {
        clf_components_stream* far = nullptr;
        const double at[2] = {0.5, 1e39};
        REQUIRE(clf_components_stream_create(2, 2, CLF_FLOAT32, at, 2, CLF_COMPONENTS_CUBE, &far) == CLF_OK);
        const float two[8] = {0, 1, 0, 1, 1, 0, 1, 0};
        REQUIRE(clf_components_stream_push(far, two, 2) == CLF_OK);
        std::int64_t got[2] = {-1, -1};
        REQUIRE(clf_components_stream_counts(far, got) == CLF_OK);
        CHECK(got[0] > 0);
        CHECK(got[1] == 0);
        clf_components_stream_destroy(far);
    }
    CHECK(clf_components_stream_push(st, nullptr, 1) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_counts(st, nullptr) == CLF_ERROR_INPUT);
    clf_components_stream_destroy(st);
    clf_components_stream* none = reinterpret_cast<clf_components_stream*>(1);
    CHECK(clf_components_stream_create(2, 2, CLF_UINT8, s, 1, 2, &none) == CLF_ERROR_INPUT);
    CHECK(none == nullptr);
    CHECK(std::string(clf_last_error()).find("CLF_COMPONENTS_CUBE") != std::string::npos);
    const double inf[1] = {std::numeric_limits<double>::infinity()};
    CHECK(clf_components_stream_create(2, 2, CLF_UINT8, inf, 1, CLF_COMPONENTS_CUBE, &none) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_create(0, 2, CLF_UINT8, s, 1, CLF_COMPONENTS_CUBE, &none) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_create(2, 2, 9, s, 1, CLF_COMPONENTS_CUBE, &none) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_create(2, 2, CLF_UINT8, nullptr, 1, CLF_COMPONENTS_CUBE, &none) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_create(2, 2, CLF_UINT8, s, 1, CLF_COMPONENTS_CUBE, nullptr) == CLF_ERROR_INPUT);
    CHECK(clf_components_stream_slices(nullptr) == 0);
}

}  // TEST_SUITE
