// Every kernel family and every kernel variant on tiny volumes, against the plain references:
// the bounded subset that also runs on slow and strict devices (the Oclgrind stage of CI, a
// simulated GPU with 1 compute unit, small local memory, race and bounds checks), so that
// each kernel has run on a second OpenCL implementation. Variants a device cannot run
// (work-group sizes above its limits) are shrunk by the library and named here.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "clfractal/components.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/pyramid.hpp"
#include "clfractal/sat.hpp"
#include "clfractal/smooth.hpp"
#include "clfractal/span.hpp"
#include "reference/fd4_reference.hpp"
#include "reference/filter_reference.hpp"
#include "reference/local_reference.hpp"
#include "reference/smooth_reference.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

const Dims tiny{9, 7, 6};

void check_spans(const Volume& v, int levels) {
    const IsovalueSet iso = IsovalueSet::for_volume(v, 20);
    const SpanResult r = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, levels, 0});
    for (int l = 0; l < levels; ++l) {
        const Volume lv = ref::level(v, l);
        CHECK(r.get(SpanKind::cubes).counts[l] == ref::cubes_brute(lv, iso));
        CHECK(r.get(SpanKind::edges).counts[l] == ref::edges_brute(lv, iso));
    }
}

// Largest |device - reference| over the defined values; NaN patterns must agree.
double field_error(const Volume& got, const std::vector<double>& want) {
    REQUIRE(got.vertices() == want.size());
    const float* p = got.as<float>();
    double worst = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
        REQUIRE(std::isnan(p[i]) == std::isnan(want[i]));
        if (!std::isnan(want[i])) worst = std::max(worst, std::fabs(double(p[i]) - want[i]));
    }
    return worst;
}

}  // namespace

TEST_SUITE("portable") {

TEST_CASE("span counting: private, local-memory and global-memory histograms") {
    testutil::TuningGuard guard;
    const std::size_t limit = ctx().max_work_group();
    for (const char* variant : {"private", "atomic"})
        for (std::size_t local_hist : {std::size_t(1) << 16, std::size_t(0)})
            for (std::size_t wg : {std::size_t(1), std::size_t(7), std::size_t(64)}) {
                if (wg > limit) MESSAGE("work-group " << wg << " above the device's " << limit << ": shrunk");
                ctx().tuning.span_variant = parse_variant<SpanVariant>(variant);
                ctx().tuning.local_hist_bytes = local_hist;
                ctx().tuning.work_group = wg;
                ctx().tuning.private_items = 3;
                CAPTURE(variant); CAPTURE(local_hist); CAPTURE(wg);
                check_spans(testutil::random_volume(tiny, ValueType::uint8, 0, 255, 3), 2);
                check_spans(testutil::random_volume({7, 5, 5}, ValueType::int16, -300, 300, 4), 2);
                check_spans(testutil::random_volume({6, 5, 4}, ValueType::float32, -9, 9, 5), 2);
            }
}

TEST_CASE("summed-area tables: sequential and work-group scans") {
    testutil::TuningGuard guard;
    std::vector<cl_uint> values(tiny.vertices());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = cl_uint(i * 7 % 5);
    for (const char* variant : {"sequential", "workgroup"}) {
        ctx().tuning.sat_variant = parse_variant<SatVariant>(variant);
        CAPTURE(variant);
        CHECK(summed_area_table(ctx(), values, tiny) == ref::summed_area_table(values, tiny));
    }
}

TEST_CASE("local fractal dimension: rows and vertices") {
    testutil::TuningGuard guard;
    const Volume v = testutil::random_volume({11, 9, 8}, ValueType::uint8, 0, 40, 6);
    for (const char* variant : {"rows", "vertices"}) {
        ctx().tuning.local_variant = parse_variant<LocalVariant>(variant);
        CAPTURE(variant);
        CHECK(field_error(local_fractal_dimension(ctx(), v, 20.5, 4), ref::local_dimension_brute(v, 20.5, 4)) < 1e-5);
    }
}

TEST_CASE("filters: median and Gaussian in rows, vertices and tiles; the targeted median") {
    testutil::TuningGuard guard;
    const Volume v = testutil::random_volume(tiny, ValueType::uint8, 0, 255, 7);
    const std::vector<double> gauss = reference::gaussian_filter(v, 1.0);
    for (const char* variant : {"rows", "vertices", "tiled"}) {
        ctx().tuning.filter_variant = parse_variant<FilterVariant>(variant);
        CAPTURE(variant);
        const Volume med = median_filter(ctx(), v), want = reference::median_filter(v);
        CHECK(std::equal(med.as<std::uint8_t>(), med.as<std::uint8_t>() + med.vertices(), want.as<std::uint8_t>()));
        const Volume g = gaussian_filter(ctx(), v, 1.0);
        for (std::size_t i = 0; i < g.vertices(); ++i)
            CHECK(std::fabs(double(g.as<std::uint8_t>()[i]) - reference::store_as(ValueType::uint8, gauss[i])) <= 1);
    }
    // The targeted median: the median where LD > h, the input elsewhere.
    const Volume smooth_v = testutil::random_volume(tiny, ValueType::uint8, 0, 40, 9);
    const std::vector<double> ld = ref::local_dimension_brute(smooth_v, 20.5, 4);
    const Volume full = reference::median_filter(smooth_v);
    const TargetedResult t = targeted_filter(ctx(), smooth_v, FilterSpec::median(), 20.5, 2.0, 4);
    std::size_t selected = 0;
    for (std::size_t i = 0; i < ld.size(); ++i) {
        const bool high = ld[i] > 2.0;
        selected += high;
        CHECK(t.volume.as<std::uint8_t>()[i] == (high ? full : smooth_v).as<std::uint8_t>()[i]);
    }
    CHECK(t.selected == selected);
}

TEST_CASE("components, D4, LD4, subsampling and smoothing on a simulated device") {
    const Volume v = testutil::random_volume(tiny, ValueType::uint8, 0, 9, 8);
    for (double s : {3.0, 5.0})
        CHECK(std::uint64_t(count_components_at(ctx(), v, s)) == ref::components_bfs(v, s));
    {
        // The device labelling (kernels label_runs, join_runs, count_roots), both modes.
        testutil::TuningGuard guard;
        ctx().tuning.labelling = LabellingPath::device;
        const std::vector<std::int64_t> cube = count_components_at(ctx(), v, {3.0, 5.0}, Connectivity::cube);
        const std::vector<std::int64_t> freudenthal = count_components_at(ctx(), v, {3.0, 5.0}, Connectivity::freudenthal);
        CHECK(std::uint64_t(cube[0]) == ref::components_bfs(v, 3.0));
        CHECK(std::uint64_t(cube[1]) == ref::components_bfs(v, 5.0));
        CHECK(freudenthal == count_components_at(v, {3.0, 5.0}, Connectivity::freudenthal));
    }
    const ComponentCurve curve = count_components(ctx(), v, IsovalueSet::for_volume(v));
    for (std::size_t j = 0; j < curve.isovalues.size(); ++j)
        CHECK(std::uint64_t(curve.components[j]) == ref::components_bfs(v, curve.isovalues.value(j)));
    const ref::Fd4 want = ref::fd4(v, 1.0);
    const Fd4Result got = fractal_dimension_4d(ctx(), v, 1.0);
    CHECK(got.i4 == want.i4);
    CHECK(got.i4_sub == want.i4_sub);
    CHECK(field_error(local_fractal_dimension_4d(ctx(), v, 1.0, 4), ref::local_dimension_4d_brute(v, 1.0, 4)) < 1e-5);
    const Volume sub = subsample(v), want_sub = ref::level(v, 1);
    CHECK(std::equal(sub.as<std::uint8_t>(), sub.as<std::uint8_t>() + sub.vertices(), want_sub.as<std::uint8_t>()));
    const SmoothResult sm = smooth_isosurface(ctx(), v, 4.5, 2.0, 4, SmoothVariant::plain, 1.0, true);
    const ref::SmoothOutcome want_sm = ref::smooth(v, ref::field_values(sm.ld), 4.5, 2.0, SmoothVariant::plain, 1.0);
    CHECK(std::equal(sm.volume.as<std::uint8_t>(), sm.volume.as<std::uint8_t>() + v.vertices(),
                     want_sm.volume.as<std::uint8_t>()));
    CHECK(field_error(sm.ld, ref::local_dimension_brute(v, 4.5, 4)) < 1e-5);
}

}  // TEST_SUITE
