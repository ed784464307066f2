// Clean bands on curves with known answers, Theorem 1 inverted, and the noise estimate on
// synthetic data of known noise.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "clfractal/advice.hpp"
#include "clfractal/noise.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

using testutil::curve;

TEST_SUITE("advice") {

TEST_CASE("clean bands: runs of defined D <= 2.2 with enough surface, widest first") {
    const double n = std::numeric_limits<double>::quiet_NaN();
    //                  0    1    2    3    4    5    6    7    8    9    10   11   12
    const FdCurve f = curve({2.5, 2.1, 2.0, 2.15, 2.3, 2.1, 2.05, 2.2, 2.1, n, 2.0, 1.9, 2.1},
                            {100, 900, 1000, 800, 900, 50, 400, 400, 300, 0, 5, 200, 9});
    const std::vector<CleanBand> b = clean_bands(f);
    // Floor: 1% of 1000 = 10. Runs: 1..3 (width 3, max 1000), 5..8 (width 4, max 400), 11 (width 1);
    // 10 and 12 lack surface, 9 is undefined, 0 and 4 are above 2.2.
    REQUIRE(b.size() == 3);
    CHECK(b[0].first == 5);
    CHECK(b[0].last == 8);
    CHECK(b[0].representative == 6);
    CHECK(b[0].max_count == 400);
    CHECK(b[0].max_fd == 2.2);
    CHECK(b[0].mean_fd == doctest::Approx((2.1 + 2.05 + 2.2 + 2.1) / 4));
    CHECK(b[1].first == 1);
    CHECK(b[1].last == 3);
    CHECK(b[1].representative == 2);
    CHECK(b[2].first == 11);
    CHECK(b[2].width() == 1);
    // Equal widths: the larger surface first.
    const std::vector<CleanBand> t = clean_bands(curve({2.0, 2.0, 3.0, 2.0, 2.0}, {10, 10, 10, 20, 5}));
    REQUIRE(t.size() == 2);
    CHECK(t[0].first == 3);
    CHECK(t[1].first == 0);
    // A stricter threshold and share.
    CHECK(clean_bands(f, BandOptions{2.0, 0.01}).size() == 2);  // isovalues 2 and 11
    CHECK(clean_bands(f, BandOptions{2.2, 0.5}).size() == 1);   // 1..3: the only counts >= 500
    CHECK(clean_bands(curve({2.5, 2.6}, {10, 10})).empty());
    CHECK_THROWS_AS(clean_bands(f, BandOptions{2.2, 1.5}), InputError);
}

TEST_CASE("Theorem 1 inverted: r from the edge dimension, round trip") {
    for (double r : {0.05, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 10.0}) {
        CAPTURE(r);
        CHECK(noise_ratio_from_edge_dimension(expected_edge_dimension(r)) == doctest::Approx(r).epsilon(1e-9));
    }
    CHECK(noise_ratio_from_edge_dimension(2.0) == 0);
    CHECK(noise_ratio_from_edge_dimension(1.7) == 0);
    CHECK(std::isinf(noise_ratio_from_edge_dimension(3.0)));
    CHECK(std::isnan(noise_ratio_from_edge_dimension(std::nan(""))));
    // The trusted range's ends, as documented.
    CHECK(noise_ratio_from_edge_dimension(noise_fd_min) == doctest::Approx(0.17).epsilon(0.05));
    CHECK(noise_ratio_from_edge_dimension(noise_fd_max) == doctest::Approx(4.3).epsilon(0.05));
}

TEST_CASE("mean edge span of the noise model against Monte Carlo") {
    CHECK(mean_edge_span(0) == doctest::Approx(0.5).epsilon(1e-6));
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1), w(-1, 1);
    for (double r : {0.3, 1.0, 2.5}) {
        double sum = 0;
        const int samples = 400000;
        for (int i = 0; i < samples; ++i) sum += std::abs(u(rng) + r * (w(rng) - w(rng)));
        CAPTURE(r);
        CHECK(mean_edge_span(r) == doctest::Approx(sum / samples).epsilon(0.005));
    }
}

TEST_CASE("Gaussian edge model: the closed form against the numerical integral, inverted, mean span") {
    CHECK(gaussian_edge_dimension(0) == 2);
    for (double r : {0.05, 0.2, 0.5, 1.0, 2.0, 5.0}) {
        CAPTURE(r);
        const double d = gaussian_edge_dimension(r);
        CHECK(d == doctest::Approx(expected_edge_dimension(r, NoiseKind::gaussian)).epsilon(2e-6));
        CHECK(gaussian_noise_ratio_from_edge_dimension(d) == doctest::Approx(r).epsilon(1e-9));
    }
    CHECK(gaussian_noise_ratio_from_edge_dimension(2.0) == 0);
    CHECK(std::isinf(gaussian_noise_ratio_from_edge_dimension(3.0)));
    CHECK(std::isnan(gaussian_noise_ratio_from_edge_dimension(std::nan(""))));
    CHECK(mean_edge_span_gaussian(0) == 0.5);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> n(0, 1);
    for (double r : {0.3, 1.0, 2.5}) {
        double sum = 0;
        const int samples = 400000;
        for (int i = 0; i < samples; ++i) sum += std::abs(u(rng) + r * (n(rng) - n(rng)));
        CAPTURE(r);
        CHECK(mean_edge_span_gaussian(r) == doctest::Approx(sum / samples).epsilon(0.005));
    }
}

TEST_CASE("the noise estimate's Gaussian inversion recovers Gaussian noise within 10%") {
    const std::size_t n = 128;
    const Volume clean = noise_experiment_volume("points", n, 10, 1);
    const IsovalueSet iso = IsovalueSet::floats(default_noise_isovalues("points", n));
    for (double sd : {0.5, 1.0, 2.0}) {
        NoiseOptions o;
        o.kind = NoiseKind::gaussian;
        o.amplitude = sd;
        o.seed = 12;
        const NoiseEstimate e = estimate_noise(ctx(), add_noise(ctx(), clean, o), iso);
        MESSAGE("Gaussian noise sd = " << sd << ": estimated " << e.median_sigma_gaussian << " (r "
                                       << e.median_ratio_gaussian << ") from " << e.used << " isovalues");
        CAPTURE(sd);
        CHECK(e.used >= 4);
        CHECK(std::abs(e.median_sigma_gaussian - sd) <= 0.1 * sd);
    }
}

TEST_CASE("intersected edge spans: counts equal the device's E(s), sums the brute force") {
    std::uint32_t seed = 3;
    for (auto [d, t, lo, hi] : {std::tuple{Dims{9, 7, 5}, ValueType::uint8, 0L, 20L},
                                std::tuple{Dims{6, 11, 4}, ValueType::int16, -9L, 9L},
                                std::tuple{Dims{8, 5, 7}, ValueType::float32, -6L, 6L},
                                std::tuple{Dims{10, 9, 6}, ValueType::uint16, 0L, 30L},
                                std::tuple{Dims{7, 8, 9}, ValueType::int8, -128L, 127L},
                                std::tuple{Dims{9, 6, 8}, ValueType::uint16, 0L, 60000L},
                                std::tuple{Dims{5, 6, 7}, ValueType::int32, -70000L, 70000L}}) {
        const Volume v = testutil::random_volume(d, t, lo, hi, seed++);
        const IsovalueSet iso = IsovalueSet::for_volume(v, 37);
        const std::string type = value_type_name(t);
        CAPTURE(type);
        const EdgeSpanSums s = intersected_edge_spans(v, iso);
        const SpanResult spans = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::edges}, 1, 0});
        CHECK(s.count == spans.curves[0].counts[0]);
        for (std::size_t j = 0; j < iso.size(); ++j) {
            const double sv = iso.value(j);
            double want = 0;
            for (std::size_t z = 0; z < d.nz; ++z)
                for (std::size_t y = 0; y < d.ny; ++y)
                    for (std::size_t x = 0; x < d.nx; ++x) {
                        const double f = v.value(v.index(x, y, z));
                        auto edge = [&](double g) {
                            const double a = std::min(f, g), b = std::max(f, g);
                            if (a < sv && sv <= b) want += b - a;
                        };
                        if (x + 1 < d.nx) edge(v.value(v.index(x + 1, y, z)));
                        if (y + 1 < d.ny) edge(v.value(v.index(x, y + 1, z)));
                        if (z + 1 < d.nz) edge(v.value(v.index(x, y, z + 1)));
                    }
            CAPTURE(j);
            CHECK(s.sum[j] == doctest::Approx(want).epsilon(1e-12));
        }
    }
}

TEST_CASE("the noise estimate recovers a known uniform noise level within 10%") {
    // Thesis §3.2.1: the distance to random points (gradient 1, directions spread over the
    // sphere, so edge spans are uniform on [0, 1]) plus uniform noise [-mu, mu].
    const std::size_t n = 128;
    const Volume clean = noise_experiment_volume("points", n, 10, 1);
    const IsovalueSet iso = IsovalueSet::floats(default_noise_isovalues("points", n));
    for (double mu : {0.5, 1.0, 2.0, 3.0}) {
        NoiseOptions o;
        o.amplitude = mu;
        o.seed = 11;
        const Volume noisy = add_noise(ctx(), clean, o);
        const NoiseEstimate e = estimate_noise(ctx(), noisy, iso);
        MESSAGE("uniform noise mu = " << mu << ": estimated mu " << e.median_amplitude << " (r " << e.median_ratio
                                      << ", gamma " << e.median_amplitude / e.median_ratio << ") from " << e.used
                                      << " isovalues");
        CAPTURE(mu);
        CHECK(e.used >= 4);
        CHECK(std::abs(e.median_amplitude - mu) <= 0.1 * mu);
    }
    // A clean field: no isovalue in the trusted range, so no estimate.
    const NoiseEstimate e = estimate_noise(ctx(), clean, iso);
    CHECK(e.used == 0);
    CHECK(std::isnan(e.median_amplitude));
}

}  // TEST_SUITE
