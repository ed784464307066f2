// The noise model (Theorem 1, Lemmas 1-3, the Gaussian and box models), reproducible noise
// on the device against its host definition, and the thesis' experiment at N = 64.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "clfractal/noise.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "test_util.hpp"

using namespace clfractal;

namespace {

constexpr double pi = 3.14159265358979323846;

// The three closed forms of Theorem 1, each on its own (to test the joins).
double eq32(double r) { return std::log2((32 * r * r * r + 8 * r - 1) / (32 * std::pow(r / 2, 3) + 8 * (r / 2) - 1)); }
double eq33(double r) { return std::log2((32 * r * r * r + 8 * r - 1) / (std::pow(r, 4) + 6 * r * r)); }
double eq34(double r) { return std::log2(4 * (2 * r * r + 3) / (2 * (r / 2) * (r / 2) + 3)); }

// Plain composite midpoint rule, for integrals checked against the lemmas.
template <class F> double midpoint(const F& f, double a, double b, int n) {
    double s = 0, h = (b - a) / n;
    for (int i = 0; i < n; ++i) s += f(a + (i + 0.5) * h);
    return s * h;
}

bool same_bits(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

}  // namespace

TEST_SUITE("noise") {

TEST_CASE("Theorem 1: 2 without noise, continuous at 1/2 and 1, increasing to 3") {
    CHECK(expected_edge_dimension(0.0) == doctest::Approx(2.0).epsilon(1e-15));
    // The thesis' forms (r/2 written out) against the library at the joins, from both sides.
    CHECK(eq33(0.5) == doctest::Approx(eq34(0.5)).epsilon(1e-12));
    CHECK(eq32(1.0) == doctest::Approx(eq33(1.0)).epsilon(1e-12));
    for (double r : {0.1, 0.3, 0.4999}) CHECK(expected_edge_dimension(r) == doctest::Approx(eq34(r)).epsilon(1e-12));
    for (double r : {0.5, 0.7, 0.9999}) CHECK(expected_edge_dimension(r) == doctest::Approx(eq33(r)).epsilon(1e-12));
    for (double r : {1.0, 2.0, 4.0}) CHECK(expected_edge_dimension(r) == doctest::Approx(eq32(r)).epsilon(1e-12));
    const double eps = 1e-9;
    CHECK(std::abs(expected_edge_dimension(0.5 - eps) - expected_edge_dimension(0.5)) < 1e-7);
    CHECK(std::abs(expected_edge_dimension(1 - eps) - expected_edge_dimension(1)) < 1e-7);
    double last = 0;
    for (double r = 0; r <= 20; r += 0.01) {
        const double d = expected_edge_dimension(r);
        CHECK(d > last);
        CHECK(d < 3);
        last = d;
    }
    CHECK(expected_edge_dimension(1e6) == doctest::Approx(3.0).epsilon(1e-6));
    CHECK(expected_edge_dimension(1e3) > 2.999);
    CHECK_THROWS_AS(expected_edge_dimension(-0.1), std::invalid_argument);
    CHECK_THROWS_AS(expected_edge_dimension(std::nan("")), std::invalid_argument);
}

TEST_CASE("Theorem 1 is log2(8 Lemma3(gamma) / Lemma3(2 gamma))") {
    const double lambda = 100;
    for (double r = 0; r <= 6; r += 0.125)
        CHECK(expected_edge_dimension(r) ==
              doctest::Approx(std::log2(8 * lemma3_probability(1, r, lambda) / lemma3_probability(2, r, lambda)))
                  .epsilon(1e-12));
}

TEST_CASE("Lemma 1: the thesis' three cases and Monte Carlo") {
    const double mu = 1.5, sigma = 10;
    // Case 1: both within mu of sigma; case 2: only s_b; case 3: only s_a.
    CHECK(lemma1_probability(9.2, 10.9, sigma, mu) == doctest::Approx(0.5 - (9.2 - sigma) * (10.9 - sigma) / (2 * mu * mu)));
    CHECK(lemma1_probability(7.0, 9.4, sigma, mu) == doctest::Approx(0.5 + (9.4 - sigma) / (2 * mu)));
    // Case 3: the thesis prints 1/2 + (s_a - sigma) / (2 mu), a sign slip (it would give 1 at
    // s_a = sigma + mu, where the noisy s_a can never reach sigma); its proof's own
    // P(noisy s_a <= sigma) = 1/2 - (s_a - sigma) / (2 mu) is what holds, and what Lemma 2 uses.
    CHECK(lemma1_probability(10.6, 13.0, sigma, mu) == doctest::Approx(0.5 - (10.6 - sigma) / (2 * mu)));
    CHECK(lemma1_probability(5, 20, sigma, mu) == 1.0);
    CHECK(lemma1_probability(12, 20, sigma, mu) == 0.0);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> noise(-mu, mu);
    for (auto [sa, sb] : {std::pair{9.2, 10.9}, {7.0, 9.4}, {10.6, 13.0}, {9.9, 10.1}}) {
        const int n = 200000;
        int hits = 0;
        for (int k = 0; k < n; ++k) {
            const double a = sa + noise(rng), b = sb + noise(rng);
            hits += std::min(a, b) <= sigma && sigma <= std::max(a, b);
        }
        CHECK(std::abs(double(hits) / n - lemma1_probability(sa, sb, sigma, mu)) < 0.005);
    }
}

TEST_CASE("Lemma 2: numeric integration of Lemma 1 over x, and Monte Carlo") {
    const double sigma = 0, lambda = 6;
    for (double mu : {0.4, 1.0, 2.0})
        for (double delta : {0.0, 0.3, 0.8, 1.5, 3.0}) {
            if (lambda < mu + delta) continue;
            const double integral =
                midpoint([&](double x) { return lemma1_probability(x, x + delta, sigma, mu); }, -lambda, lambda, 200000) /
                (2 * lambda);
            CHECK(lemma2_probability(delta, mu, lambda) == doctest::Approx(integral).epsilon(1e-6));
            // 2 Lambda times Lemma 2 is the edge model's E|delta + n_b - n_a|.
            CHECK(edge_span_measure(delta, NoiseKind::uniform, mu) ==
                  doctest::Approx(2 * lambda * lemma2_probability(delta, mu, lambda)).epsilon(1e-12));
        }
    std::mt19937_64 rng(12);
    const double mu = 1.0, delta = 0.7;
    std::uniform_real_distribution<double> noise(-mu, mu), start(sigma - lambda, sigma + lambda);
    const int n = 400000;
    int hits = 0;
    for (int k = 0; k < n; ++k) {
        const double x = start(rng), a = x + noise(rng), b = x + delta + noise(rng);
        hits += std::min(a, b) <= sigma && sigma <= std::max(a, b);
    }
    CHECK(double(hits) / n == doctest::Approx(lemma2_probability(delta, mu, lambda)).epsilon(0.02));
    CHECK_THROWS_AS(lemma2_probability(3, 4, 5), std::invalid_argument);
}

TEST_CASE("Lemma 3 against edge spans sampled uniformly") {
    // Psi(e) = (x, delta) uniform on [sigma - Lambda, sigma + Lambda] x [0, gamma].
    const double sigma = 3, gamma = 1, lambda = 6;
    std::mt19937_64 rng(13);
    for (double mu : {0.0, 0.3, 0.5, 0.8, 2.0, 4.0}) {
        std::uniform_real_distribution<double> start(sigma - lambda, sigma + lambda), span(0, gamma), noise(-mu, mu);
        const int n = 1000000;
        int hits = 0;
        for (int k = 0; k < n; ++k) {
            const double x = start(rng), delta = span(rng);
            const double a = x + (mu > 0 ? noise(rng) : 0), b = x + delta + (mu > 0 ? noise(rng) : 0);
            hits += std::min(a, b) <= sigma && sigma <= std::max(a, b);
        }
        const double p = lemma3_probability(gamma, mu, lambda), se = std::sqrt(p * (1 - p) / n);
        INFO("mu = " << mu << ", measured " << double(hits) / n << ", Lemma 3 " << p);
        CHECK(std::abs(double(hits) / n - p) < 5 * se);
    }
}

TEST_CASE("Edge model by numerical integration: Theorem 1 for uniform noise, Gaussian checks") {
    for (double r = 0; r <= 5; r += 0.25)
        CHECK(expected_edge_dimension(r, NoiseKind::uniform) == doctest::Approx(expected_edge_dimension(r)).epsilon(1e-6));
    // Gaussian: E|delta + N(0, 2 s^2)| is the folded normal mean.
    for (double s : {0.2, 1.0, 3.0})
        for (double delta : {0.0, 0.5, 2.0}) {
            const double tau = s * std::sqrt(2.0);
            const double folded = tau * std::sqrt(2 / pi) * std::exp(-delta * delta / (2 * tau * tau)) +
                                  delta * std::erf(delta / (tau * std::sqrt(2.0)));
            CHECK(edge_span_measure(delta, NoiseKind::gaussian, s) == doctest::Approx(folded).epsilon(1e-7));
        }
    CHECK(expected_edge_dimension(0.0, NoiseKind::gaussian) == doctest::Approx(2.0).epsilon(1e-12));
    double last = 2;
    for (double s = 0.1; s <= 4; s += 0.1) {
        const double d = expected_edge_dimension(s, NoiseKind::gaussian);
        CHECK(d > last);
        last = d;
    }
    CHECK(expected_edge_dimension(200.0, NoiseKind::gaussian) == doctest::Approx(3.0).epsilon(1e-4));
    // Monte Carlo of the same model: D = log2(8 E|d1 + w| / E|d2 + w'|), d1 ~ U[0,1], d2 ~ U[0,2].
    std::mt19937_64 rng(14);
    std::uniform_real_distribution<double> unit(0, 1);
    for (double s : {0.3, 1.0}) {
        std::normal_distribution<double> normal(0, s);
        double e1 = 0, e2 = 0;
        const int n = 1000000;
        for (int k = 0; k < n; ++k) {
            const double w = normal(rng) - normal(rng), d = unit(rng);
            e1 += std::abs(d + w);
            e2 += std::abs(2 * d + w);
        }
        CHECK(std::log2(8 * e1 / e2) == doctest::Approx(expected_edge_dimension(s, NoiseKind::gaussian)).epsilon(0.003));
    }
}

TEST_CASE("Box model: 2 without noise, below the edge model, towards 3") {
    CHECK(expected_box_dimension(0.0, NoiseKind::uniform, 10000) == doctest::Approx(2.0).epsilon(1e-12));
    CHECK(expected_box_dimension(0.0, NoiseKind::gaussian, 10000) == doctest::Approx(2.0).epsilon(1e-12));
    for (double r : {0.5, 1.0, 2.0}) {
        const double box = expected_box_dimension(r, NoiseKind::uniform, 1 << 17);
        CHECK(box > 2.05);
        CHECK(box < expected_edge_dimension(r));
    }
    CHECK(expected_box_dimension(100.0, NoiseKind::uniform, 1 << 16) == doctest::Approx(3.0).epsilon(0.002));
    // Deterministic: the same seed gives the same value whatever the thread count.
    CHECK(expected_box_dimension(1.0, NoiseKind::gaussian, 50000, 7) == expected_box_dimension(1.0, NoiseKind::gaussian, 50000, 7));
}

TEST_CASE("Counter-based draws: uniform is the top of uniform_noise, Gaussian has unit variance") {
    double sum = 0, sum2 = 0, gsum = 0, gsum2 = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const float u = uniform_noise_f32(5, std::uint64_t(i));
        CHECK_FALSE(u < -1.0f);
        CHECK(u < 1.0f);
        if (i < 1000) CHECK(double(u) == std::floor(uniform_noise(5, std::uint64_t(i)) * 0x1p23) * 0x1p-23);
        sum += u, sum2 += double(u) * u;
        const double g = gaussian_noise_f32(5, std::uint64_t(i));
        gsum += g, gsum2 += g * g;
    }
    CHECK(std::abs(sum / n) < 0.01);
    CHECK(sum2 / n == doctest::Approx(1.0 / 3).epsilon(0.01));
    CHECK(std::abs(gsum / n) < 0.01);
    CHECK(gsum2 / n == doctest::Approx(1.0).epsilon(0.01));
    CHECK(uniform_noise_f32(5, 17) != uniform_noise_f32(6, 17));
}

TEST_CASE("Device noise equals the host definition on every vertex, for every slab split") {
    const std::vector<Dims> sizes{{7, 5, 3}, {1, 1, 13}, {2, 3, 1}, {17, 2, 11}, {31, 29, 7}};
    for (const Dims& d : sizes)
        for (ValueType t : all_value_types) {
            // The integer types' extremes are reached (clamps); int32/uint32/float64 add in double.
            long lo = t == ValueType::int16 ? -300 : 0, hi = t == ValueType::uint8 ? 255 : 700;
            if (t == ValueType::int8) lo = -128, hi = 127;
            if (t == ValueType::int32) lo = -2147483647 - 1, hi = 2147483647;
            if (t == ValueType::uint32) lo = 4294967000, hi = 4294967295;
            const Volume v = testutil::random_volume(d, t, lo, hi, 21);
            for (bool keep : {false, true}) {
                NoiseOptions opt;
                opt.amplitude = t == ValueType::uint8 || t == ValueType::int8 ? 40 : 2.5;  // hits both clamps
                opt.seed = 99;
                opt.keep_type = keep;
                const Volume ref = add_noise_host(v, opt);
                CHECK(ref.type() == (keep ? t : ValueType::float32));
                for (std::size_t slab : {std::size_t(0), std::size_t(1), std::size_t(2), d.nz}) {
                    opt.slab_slices = slab;
                    INFO(dims_string(d) << " " << value_type_name(t) << " keep " << keep << " slab " << slab);
                    CHECK(same_bits(add_noise(testutil::ctx(), v, opt), ref));
                }
            }
        }
}

TEST_CASE("Gaussian draws: within 3e-6 of double-precision Box-Muller") {
    // The generator's bits, written out here (splitmix64, as synthetic.hpp documents).
    const auto mix = [](std::uint64_t z) {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    };
    const std::uint64_t seed = 3, mixed = mix(seed);
    const auto bits = [&](std::uint64_t c) { return mix(mixed + (c + 1) * 0x9E3779B97F4A7C15ull); };
    double worst = 0;
    for (std::uint64_t i = 0; i < 300000; ++i) {
        const std::uint64_t c = (std::uint64_t(1) << 62) + 2 * i;
        const double u1 = double((bits(c) >> 40) + 1) * 0x1p-24, u2 = double(bits(c + 1) >> 40) * 0x1p-24;
        const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * pi * u2);
        worst = std::max(worst, std::abs(double(gaussian_noise_f32(seed, i)) - z));
    }
    MESSAGE("largest |float32 - double| Box-Muller difference: " << worst);
    CHECK(worst < 3e-6);
    // 300000 draws exercise every quadrant of the cosine and both branches of the reduction of m.
}

TEST_CASE("Gaussian device noise equals the host bit for bit, for every slab split and run") {
    for (const Dims& d : {Dims{19, 6, 9}, Dims{1, 1, 13}, Dims{64, 33, 5}})
        for (ValueType t : {ValueType::uint8, ValueType::int16, ValueType::float32})
            for (bool keep : {false, true}) {
                const Volume v = testutil::random_volume(d, t, 0, 200, 22);
                NoiseOptions opt;
                opt.kind = NoiseKind::gaussian;
                opt.amplitude = 30;
                opt.seed = 5;
                opt.keep_type = keep;
                const Volume host = add_noise_host(v, opt);
                for (std::size_t slab : {std::size_t(0), std::size_t(1), std::size_t(2), std::size_t(4)}) {
                    opt.slab_slices = slab;
                    INFO(dims_string(d) << " " << value_type_name(t) << " keep " << keep << " slab " << slab);
                    CHECK(same_bits(add_noise(testutil::ctx(), v, opt), host));
                }
                opt.slab_slices = 0;
                CHECK(same_bits(add_noise(testutil::ctx(), v, opt), host));  // a second run
            }
}

TEST_CASE("Noise arguments") {
    const Volume v = testutil::random_volume({4, 4, 4}, ValueType::float32, 0, 10, 1);
    NoiseOptions opt;
    opt.amplitude = -1;
    CHECK_THROWS_AS(add_noise(testutil::ctx(), v, opt), InputError);
    opt.amplitude = std::nan("");
    CHECK_THROWS_AS(add_noise_host(v, opt), InputError);
    CHECK_THROWS_AS(parse_noise_kind("pink"), InputError);
    CHECK_THROWS_AS(noise_experiment_volume("cube", 16, 1, 1), InputError);
    CHECK_THROWS_AS(estimate_gamma(v, 1000.0), InputError);
    opt.amplitude = 0;  // no noise: the values, converted to float32
    const Volume same = add_noise(testutil::ctx(), v, opt);
    CHECK(std::memcmp(same.data(), v.data(), v.size_bytes()) == 0);
}

TEST_CASE("gamma estimated from the edge spans of the distance field is about 1") {
    const Volume points = noise_experiment_volume("points", 48, 10, 1);
    CHECK(estimate_gamma(points, 8.0) == doctest::Approx(1.0).epsilon(0.05));
    // Scaling the values scales gamma.
    Volume scaled = points;
    for (std::size_t i = 0; i < scaled.vertices(); ++i) scaled.as<float>()[i] *= 25;
    CHECK(estimate_gamma(scaled, 200.0) == doctest::Approx(25 * estimate_gamma(points, 8.0)).epsilon(0.01));
}

TEST_CASE("The thesis' experiment at N = 64 matches Theorem 1 within 0.05") {
    // Distance to 10 random points, uniform noise mu = 0, 0.5, ..., 4 (Fig. 3.5 at half the
    // size). At N = 128 the default run is within 0.016 (docs/guide/theorem.md); at N = 64 the isosurfaces
    // are smaller and more of them touch the border, and the measured values are within 0.033.
    const Volume clean = noise_experiment_volume("points", 64, 10, 1);
    std::vector<double> mu;
    for (int k = 0; k <= 8; ++k) mu.push_back(0.5 * k);
    const auto pts = noise_experiment(testutil::ctx(), clean, default_noise_isovalues("points", 64), mu,
                                      NoiseKind::uniform, 1.0, 1, 4096);
    REQUIRE(pts.size() == mu.size());
    for (const NoisePoint& p : pts) {
        INFO("mu " << p.amplitude << ": measured " << p.measured_edge_fd << ", formula " << p.formula);
        CHECK(p.r == p.amplitude);
        CHECK(p.formula == expected_edge_dimension(p.r));
        CHECK(std::abs(p.measured_edge_fd - p.formula) < 0.05);
        CHECK(std::abs(p.measured_box_fd - p.model_box) < 0.1);
    }
}

}  // TEST_SUITE

TEST_SUITE("noise") {

TEST_CASE("Boston Teapot at isovalue 65 (thesis Fig. 3.7): gamma about 25, formula up to r = 2") {
    const std::string dir = testutil::shared_data_or_skip("the teapot noise check");
    if (dir.empty()) return;
    const std::string path = dir + "/boston_teapot_256x256x178_uint8.raw";
    if (!std::filesystem::exists(path)) {
        MESSAGE("skipped: " << path << " absent");
        return;
    }
    const Volume v = read_volume(path);
    // The thesis reads gamma = 25 off the spans around 65 (+/- 15); the estimator gives 23.0.
    const double gamma = estimate_gamma(v, 65);
    CHECK(gamma > 21);
    CHECK(gamma < 27);
    // With the thesis' gamma the measurement follows Theorem 1 until the noise reaches the
    // empty background (mu near 65), which the model does not have.
    const auto pts = noise_experiment(testutil::ctx(), v, {65.0f}, {0, 25, 50}, NoiseKind::uniform, 25, 1, 1024);
    for (const NoisePoint& p : pts) {
        INFO("mu " << p.amplitude << ": measured " << p.measured_edge_fd << ", formula " << p.formula);
        CHECK(std::abs(p.measured_edge_fd - p.formula) < 0.03);
    }
}

}  // TEST_SUITE
