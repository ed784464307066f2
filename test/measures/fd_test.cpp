// Fractal-dimension curves and their summary against plain computations.
#include <doctest/doctest.h>

#include <cmath>

#include "clfractal/fd.hpp"
#include "clfractal/synthetic.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

TEST_SUITE("fd") {

TEST_CASE("eq. 2.5 and eq. 3.1 per isovalue, NaN where a count is 0") {
    Volume v = testutil::random_volume({21, 18, 15}, ValueType::uint8, 0, 60, 3);
    IsovalueSet iso = IsovalueSet::for_volume(v);
    SpanResult spans = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 2, 0});
    for (SpanKind kind : {SpanKind::cubes, SpanKind::edges}) {
        FdCurve f = fd_curve(ctx(), spans, kind);
        CHECK(f.fd_fit.empty());
        auto n0 = kind == SpanKind::cubes ? ref::cubes_brute(v, iso) : ref::edges_brute(v, iso);
        auto n1 = kind == SpanKind::cubes ? ref::cubes_brute(ref::level(v, 1), iso) : ref::edges_brute(ref::level(v, 1), iso);
        int undefined = 0;
        for (std::size_t j = 0; j < iso.size(); ++j) {
            if (n0[j] == 0 || n1[j] == 0) {
                CHECK(std::isnan(f.fd[j]));
                ++undefined;
            } else {
                CHECK(f.fd[j] == std::log2(double(n0[j]) / double(n1[j])));
            }
        }
        CHECK(undefined >= 1);  // s = vmin is never intersected
    }
}

TEST_CASE("multi-level least squares (CLBlast) equals a plain fit; L = 2 equals eq. 2.5") {
    Volume v = testutil::random_volume({40, 37, 33}, ValueType::int16, -50, 50, 8);
    IsovalueSet iso = IsovalueSet::for_volume(v);
    const int L = 4;
    SpanResult spans = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::cubes}, L, 0});
    FdCurve f = fd_curve(ctx(), spans, SpanKind::cubes);
    REQUIRE(f.fd_fit.size() == iso.size());
    int defined = 0;
    for (std::size_t j = 0; j < iso.size(); ++j) {
        bool any_zero = false;
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (int l = 0; l < L; ++l) {
            std::uint64_t n = f.counts[l][j];
            any_zero |= n == 0;
            double y = n ? std::log2(double(n)) : 0;
            sx += l; sy += y; sxx += double(l) * l; sxy += l * y;
        }
        if (any_zero) {
            CHECK(std::isnan(f.fd_fit[j]));
            continue;
        }
        ++defined;
        double slope = (L * sxy - sx * sy) / (L * sxx - sx * sx);
        // float32 GEMV on devices without fp64
        CHECK(f.fd_fit[j] == doctest::Approx(-slope).epsilon(ctx().has_fp64() ? 1e-9 : 1e-5));
    }
    CHECK(defined > 10);

    std::vector<std::vector<std::uint64_t>> two{f.counts[0], f.counts[1]};
    std::vector<double> d2 = least_squares_dimension(ctx(), two);
    for (std::size_t j = 0; j < iso.size(); ++j) {
        if (std::isnan(f.fd[j])) CHECK(std::isnan(d2[j]));
        else CHECK(d2[j] == doctest::Approx(f.fd[j]).epsilon(ctx().has_fp64() ? 1e-12 : 1e-5));
    }
}

TEST_CASE("summary: mean, population std, count-weighted mean, kappa, min_count") {
    std::vector<double> fd{NAN, 2.0, 2.5, 3.0, NAN};
    std::vector<std::uint64_t> n{0, 10, 30, 60, 5}, sub{0, 2, 8, 1, 0};
    FdSummary s = summarize(fd, n, sub);
    CHECK(s.defined == 3);
    CHECK(s.mean == doctest::Approx(2.5));
    CHECK(s.std == doctest::Approx(std::sqrt((0.25 + 0 + 0.25) / 3)));
    CHECK(s.weighted_mean == doctest::Approx((20 + 75 + 180) / 100.0));
    CHECK(s.kappa == doctest::Approx(2.5 / 3));
    FdSummary m = summarize(fd, n, sub, 2);
    CHECK(m.defined == 2);
    CHECK(m.mean == doctest::Approx(2.25));
    FdSummary none = summarize({NAN}, {0}, {0});
    CHECK(none.defined == 0);
    CHECK(std::isnan(none.mean));
}

TEST_CASE("smooth surfaces have dimension near 2, noisy ones higher") {
    SyntheticOptions o;
    o.size = 96;
    Volume sphere = make_synthetic("sphere", o);
    Volume noisy = make_synthetic("noisy-sphere", o);
    for (auto* v : {&sphere, &noisy}) {
        IsovalueSet iso = IsovalueSet::for_volume(*v);
        SpanResult spans = count_spans(ctx(), *v, iso, SpanOptions{{SpanKind::cubes}, 2, 0});
        FdCurve f = fd_curve(ctx(), spans, SpanKind::cubes);
        FdSummary s = summarize(f.fd, f.counts[0], f.counts[1], 50);
        MESSAGE(v->name << ": mean FD " << s.mean << " over " << s.defined << " isovalues");
        if (v == &sphere) CHECK(s.mean == doctest::Approx(2.0).epsilon(0.05));
        else CHECK(s.mean > 2.1);
    }
}

}  // TEST_SUITE("fd")
