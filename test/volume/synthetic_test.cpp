// Synthetic volumes: specs, the catalog, each shape's values, noise and uniform_noise.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "clfractal/synthetic.hpp"
#include "clfractal/volume.hpp"
#include "clfractal/volume_io.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::check_same;
using testutil::contains;
using testutil::input_error;

namespace {

SyntheticOptions sized(std::size_t n) {
    SyntheticOptions opt;
    opt.size = n;
    return opt;
}

}  // namespace

TEST_SUITE("volume") {

TEST_CASE("synthetic specs in read_volume") {
    const Volume v = read_volume("synthetic:sphere:9");
    CHECK(v.dims() == Dims{9, 9, 9});
    CHECK(v.name == "synthetic:sphere:9");
    CHECK(read_volume("synthetic:torus").dims() == Dims{128, 128, 128});

    std::string m = input_error([] { read_volume("synthetic:blob:8"); });
    CHECK(contains(m, "synthetic:blob"));
    CHECK(contains(m, "sphere, noisy-sphere, torus, points, marschner-lobb"));
    CHECK(contains(input_error([] { read_volume("synthetic:"); }), "unknown synthetic volume"));
    for (const std::string bad : {"synthetic:sphere:1", "synthetic:sphere:2049", "synthetic:sphere:",
                                  "synthetic:sphere:abc", "synthetic:sphere:-4", "synthetic:sphere:12x",
                                  "synthetic:sphere:+8", "synthetic:sphere: 8", "synthetic:sphere:8:8",
                                  "synthetic:sphere:99999999999999999999999"}) {
        CAPTURE(bad);
        m = input_error([&] { read_volume(bad); });
        CHECK(contains(m, bad + ": size"));
        CHECK(contains(m, "from 2 to 2048"));
    }
    CHECK(read_volume("synthetic:sphere:2").dims() == Dims{2, 2, 2});
}

TEST_CASE("synthetic catalog: dims, types, names, options") {
    const auto catalog = synthetic_catalog();
    REQUIRE(catalog.size() == 5);
    for (const SyntheticInfo& s : catalog) {
        CAPTURE(s.name);
        CHECK_FALSE(s.description.empty());
        SyntheticOptions opt;
        opt.size = 9;
        const Volume v = make_synthetic(s.name, opt);
        CHECK(v.dims() == Dims{9, 9, 9});
        const bool sphere = s.name == "sphere" || s.name == "noisy-sphere";
        CHECK(v.type() == (sphere ? ValueType::uint8 : ValueType::float32));
        CHECK(v.name == "synthetic:" + s.name + ":9");
        CHECK(v.spacing == std::array<double, 3>{1.0, 1.0, 1.0});
        CHECK_NOTHROW(check_finite(v, s.name));
        opt.type = ValueType::int16;
        CHECK(make_synthetic(s.name, opt).type() == ValueType::int16);
    }
    SyntheticOptions opt;
    opt.size = 1;
    CHECK(contains(input_error([&] { make_synthetic("sphere", opt); }), "at least 2"));
    opt.size = 8;
    opt.noise = -1;
    CHECK(contains(input_error([&] { make_synthetic("sphere", opt); }), "noise"));
    opt.noise = 0;
    opt.points = 0;
    CHECK(contains(input_error([&] { make_synthetic("points", opt); }), "points"));
}

TEST_CASE("sphere: the formula, radially monotone") {
    SyntheticOptions opt;
    opt.size = 17;
    const Volume v = make_synthetic("sphere", opt);
    const double c = 8;
    std::vector<std::pair<double, double>> by_distance;
    for (std::size_t z = 0; z < 17; ++z)
        for (std::size_t y = 0; y < 17; ++y)
            for (std::size_t x = 0; x < 17; ++x) {
                const double d = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                const double value = v.value(v.index(x, y, z));
                CHECK(value == std::round(255 * std::clamp(1 - d / 8.5, 0.0, 1.0)));
                by_distance.emplace_back(d, value);
            }
    std::sort(by_distance.begin(), by_distance.end());
    for (std::size_t i = 1; i < by_distance.size(); ++i)
        CHECK(by_distance[i].second <= by_distance[i - 1].second);
    CHECK(v.value(v.index(8, 8, 8)) == 255);
    CHECK(v.value(0) == 0);
}

TEST_CASE("noisy-sphere: clean at x = 0, noisy towards x = N-1") {
    for (double mu : {0.0, 10.0}) {
        CAPTURE(mu);
        SyntheticOptions opt;
        opt.size = 32;
        opt.noise = mu;
        const double amplitude = mu > 0 ? mu : 8;  // the generator's default amplitude
        const Volume noisy = make_synthetic("noisy-sphere", opt);
        opt.noise = 0;
        const Volume clean = make_synthetic("sphere", opt);
        std::size_t differ_far = 0;
        double largest = 0;
        for (std::size_t z = 0; z < 32; ++z)
            for (std::size_t y = 0; y < 32; ++y) {
                CHECK(noisy.value(noisy.index(0, y, z)) == clean.value(clean.index(0, y, z)));
                differ_far += noisy.value(noisy.index(31, y, z)) != clean.value(clean.index(31, y, z));
                for (std::size_t x = 0; x < 32; ++x) {
                    const std::size_t i = noisy.index(x, y, z);
                    const double diff = std::fabs(noisy.value(i) - clean.value(i));
                    CHECK(diff <= amplitude * x / 31.0 + 1);
                    largest = std::max(largest, diff);
                }
            }
        CHECK(differ_far > 32 * 32 / 4);  // outside the sphere half the noise clamps to 0
        CHECK(largest >= amplitude * 0.8);
    }
}

TEST_CASE("torus, points, marschner-lobb: values") {
    SyntheticOptions opt;
    opt.size = 33;
    const Volume torus = make_synthetic("torus", opt);
    CHECK(torus.value(torus.index(16, 16, 16)) == doctest::Approx(33 / 4.0));
    CHECK(torus.value(torus.index(24, 16, 16)) == doctest::Approx(0.25));
    CHECK(torus.value(torus.index(16, 8, 18)) == doctest::Approx(std::hypot(0.25, 2.0)));

    const Volume ml = make_synthetic("marschner-lobb", sized(3));
    CHECK(ml.value(ml.index(1, 1, 1)) == doctest::Approx(0.6));  // rho(0) = cos(12 pi) = 1
    CHECK(ml.value(ml.index(1, 1, 2)) == doctest::Approx(0.2));  // sin(pi/2) = 1
    const ValueRange r = value_range(make_synthetic("marschner-lobb", sized(40)));
    CHECK(r.min >= 0);
    CHECK(r.max <= 1);

    opt.size = 24;
    opt.points = 3;
    const Volume points = make_synthetic("points", opt);
    const ValueRange pr = value_range(points);
    CHECK(pr.min >= 0);
    CHECK(pr.min <= std::sqrt(3.0) / 2);  // every point lies inside the grid
    for (std::size_t i = 0; i + 1 < points.vertices(); ++i)  // gradient magnitude at most 1
        if ((i + 1) % 24 != 0) CHECK(std::fabs(points.value(i + 1) - points.value(i)) <= 1 + 1e-5);
    check_same(make_synthetic("points", opt), points);
    opt.seed = 2;
    const Volume other = make_synthetic("points", opt);
    CHECK(std::memcmp(other.data(), points.data(), points.size_bytes()) != 0);
}

TEST_CASE("synthetic noise and type conversion") {
    SyntheticOptions opt;
    opt.size = 12;
    const Volume clean = make_synthetic("torus", opt);
    opt.noise = 2;
    opt.seed = 7;
    const Volume noisy = make_synthetic("torus", opt);
    for (std::size_t i = 0; i < clean.vertices(); ++i)
        CHECK(noisy.value(i) == doctest::Approx(clean.value(i) + 2 * uniform_noise(7, i)).epsilon(1e-6));

    opt.noise = 0;
    opt.type = ValueType::uint8;
    const Volume rounded = make_synthetic("torus", opt);
    for (std::size_t i = 0; i < clean.vertices(); ++i)
        CHECK(rounded.value(i) == std::round(clean.value(i)));

    // Clamping: a sphere with large noise saturates at both ends of uint8 and int16 keeps it.
    opt.size = 16;
    opt.type.reset();
    opt.noise = 1000;
    const ValueRange u8 = value_range(make_synthetic("sphere", opt));
    CHECK(u8.min == 0);
    CHECK(u8.max == 255);
    opt.type = ValueType::int16;
    const ValueRange i16 = value_range(make_synthetic("sphere", opt));
    CHECK(i16.min < -500);
    CHECK(i16.max > 500);
}

TEST_CASE("uniform_noise: the documented formula, deterministic, uniform on [-1, 1)") {
    // Reference values computed in Python from the formula in synthetic.cpp.
    CHECK(uniform_noise(1, 0) == 0.4994964827160602);
    CHECK(uniform_noise(1, 1) == -0.25521315424166846);
    CHECK(uniform_noise(42, 123456789) == -0.09004530672211808);
    CHECK(uniform_noise(0, ~std::uint64_t(0)) == -1.0);

    const std::size_t n = 1000000;
    double sum = 0, sum_squares = 0, lo = 1, hi = -1, cross = 0;
    bool deterministic = true;
    for (std::size_t i = 0; i < n; ++i) {
        const double u = uniform_noise(1, i);
        deterministic = deterministic && u == uniform_noise(1, i);
        sum += u;
        sum_squares += u * u;
        cross += u * uniform_noise(2, i);
        lo = std::min(lo, u);
        hi = std::max(hi, u);
    }
    CHECK(deterministic);
    CHECK(lo >= -1);
    CHECK(hi < 1);
    CHECK(lo < -0.999);
    CHECK(hi > 0.999);
    CHECK(std::fabs(sum / n) < 0.005);
    CHECK(sum_squares / n == doctest::Approx(1.0 / 3).epsilon(0.01));
    CHECK(std::fabs(cross / n) < 0.005);  // seeds 1 and 2 are uncorrelated
}

}  // TEST_SUITE("volume")
