// The noise level (noise_level.hpp): the device's block statistics against the plain
// reference on awkward sizes, every value type and every slab split; the estimate against
// the reference's; accuracy on fields of known noise.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "clfractal/device_volume.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/noise.hpp"
#include "clfractal/noise_level.hpp"
#include "clfractal/synthetic.hpp"
#include "reference/noise_level_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

// A smooth field plus Gaussian noise of `sigma`, rounded and clamped to t's range for
// integer types (the field reaches past both limits of the 8-bit types, so some blocks are
// clipped), offset far from 0 for the wide types.
Volume field_volume(Dims d, ValueType t, double sigma, std::uint32_t seed) {
    Volume v(d, t);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    const bool narrow = value_size(t) == 1;
    const double centre = narrow ? (is_integer(t) && type_min(t) < 0 ? 0.0 : 128.0)
                          : t == ValueType::uint32 ? 3.0e9 : t == ValueType::int32 ? -2.0e9
                          : t == ValueType::float64 ? 1.0e7 : t == ValueType::uint16 ? 30000.0 : 0.0;
    const double amplitude = narrow ? 150.0 : 400.0;
    visit(v, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t z = 0; z < d.nz; ++z)
            for (std::size_t y = 0; y < d.ny; ++y)
                for (std::size_t x = 0; x < d.nx; ++x) {
                    double f = centre + amplitude * std::sin(0.21 * double(x)) * std::cos(0.17 * double(y)) +
                               3.0 * double(z) + noise(rng);
                    if constexpr (std::is_integral_v<T>)
                        f = std::clamp(std::round(f), double(std::numeric_limits<T>::min()),
                                       double(std::numeric_limits<T>::max()));
                    p[x + d.nx * (y + d.ny * z)] = T(f);
                }
    });
    return v;
}

// Exact for 8- and 16-bit integer data (integer sums), float sums within 2e-5 otherwise.
void check_blocks(const NoiseBlocks& got, const NoiseBlocks& want, ValueType t) {
    REQUIRE(got.grid == want.grid);
    REQUIRE(got.count.size() == want.count.size());
    const bool exact = is_integer(t) && value_size(t) <= 2;
    const double tolerance = t == ValueType::float64 ? 1e-12 : 2e-5;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < got.count.size(); ++i) {
        if (got.count[i] != want.count[i] || got.low[i] != want.low[i] || got.high[i] != want.high[i]) ++bad;
        const double a = got.sum_squares[i], b = want.sum_squares[i];
        if (exact ? a != b : std::abs(a - b) > tolerance * std::max(1.0, std::abs(b))) ++bad;
    }
    CHECK(bad == 0);
    // The strided residuals, every stride.
    REQUIRE(got.strides == want.strides);
    std::size_t strided_bad = 0;
    for (std::size_t m = 0; m < want.strides.size(); ++m)
        for (std::size_t i = 0; i < want.count.size(); ++i) {
            const double a = got.strided_sums[m][i], b = want.strided_sums[m][i];
            if (got.strided_counts[m][i] != want.strided_counts[m][i]) ++strided_bad;
            if (exact ? a != b : std::abs(a - b) > tolerance * std::max(1.0, std::abs(b))) ++strided_bad;
        }
    CHECK(strided_bad == 0);
}

void check_level(const NoiseLevel& got, const NoiseLevel& want, ValueType t) {
    const bool exact = is_integer(t) && value_size(t) <= 2;
    CHECK(got.blocks == want.blocks);
    CHECK(got.usable_blocks == want.usable_blocks);
    CHECK(got.flat_blocks == want.flat_blocks);
    CHECK(got.map_dims == want.map_dims);
    REQUIRE(got.map.size() == want.map.size());
    if (std::isnan(want.sigma_white)) {
        CHECK(std::isnan(got.sigma_white));
        CHECK(std::isnan(got.sigma));
    } else if (exact) {
        CHECK(got.sigma_white == want.sigma_white);
        CHECK(got.flat_share == want.flat_share);
    } else {
        CHECK(got.sigma_white == doctest::Approx(want.sigma_white).epsilon(2e-5));
        CHECK(got.flat_share == doctest::Approx(want.flat_share).epsilon(1e-12));
    }
    // The reference's map is the residual's RMS: at strides (1, 1, 1) the map is that in sigma
    // units; at other strides a cell without a usable block has no value either.
    const bool unit = got.sigma_strides == NoiseStride{1, 1, 1};
    const double scale = unit && got.sigma_white > 0 ? got.sigma / got.sigma_white : 1.0;
    std::size_t bad = 0;
    for (std::size_t c = 0; c < got.map.size(); ++c) {
        const double a = got.map[c], b = scale * double(want.map[c]);
        if (unit ? std::isnan(a) != std::isnan(b) || (!std::isnan(b) && std::abs(a - b) > 2e-5 * std::max(1.0, b))
                 : std::isnan(b) && !std::isnan(a))
            ++bad;
    }
    CHECK(bad == 0);
}

// The standard deviation of a - b over every vertex.
double std_of_difference(const Volume& a, const Volume& b) {
    const Volume fa = convert_volume(a, ValueType::float64), fb = convert_volume(b, ValueType::float64);
    const double* p = fa.as<double>();
    const double* q = fb.as<double>();
    double s = 0, s2 = 0;
    const std::size_t n = a.vertices();
    for (std::size_t i = 0; i < n; ++i) s += p[i] - q[i], s2 += (p[i] - q[i]) * (p[i] - q[i]);
    return std::sqrt(s2 / double(n) - (s / double(n)) * (s / double(n)));
}

}  // namespace

TEST_SUITE("noise") {

TEST_CASE("Noise level: device block statistics equal the reference on awkward sizes and every type") {
    testutil::TuningGuard guard;
    const Dims sizes[] = {{37, 23, 19}, {5, 40, 3}, {18, 3, 33}, {64, 17, 9}};
    for (ValueType t : all_value_types)
        for (const Dims& d : sizes)
            for (std::size_t block : {std::size_t(4), std::size_t(7), std::size_t(16)}) {
                CAPTURE(value_type_name(t));
                CAPTURE(dims_string(d));
                CAPTURE(block);
                const Volume v = field_volume(d, t, 6.0, std::uint32_t(d.nx * 131 + block));
                const NoiseBlocks want = ref::noise_blocks(v, block);
                const DeviceVolume dv(ctx(), v);
                for (bool tiles : {true, false}) {
                ctx().tuning.noise_tiles = tiles;
                CAPTURE(tiles);
                check_blocks(noise_blocks(dv, block), want, t);
                // Host overload, whole and in slabs of one and two block rows.
                for (std::size_t slab : {std::size_t(0), block, 2 * block + 1})
                    check_blocks(noise_blocks(ctx(), v, block, slab), want, t);
                const std::size_t map_block = 2 * block;
                NoiseLevelOptions o;
                o.block = block;
                o.map_block = map_block;
                check_level(estimate_noise_level(dv, o), ref::noise_level(want, map_block, 3.0), t);
                }
            }
}

TEST_CASE("Noise level: the estimate equals the reference's on a clipped uint8 volume, and slab splits agree") {
    // 128 + 60 sin(0.21 x) cos(0.17 y) + 2 z + Gaussian noise of 4, rounded: the top slices
    // pass 255 and are clipped.
    const Dims d{96, 80, 64};
    Volume v(d, ValueType::uint8);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 4.0);
    for (std::size_t i = 0; i < d.vertices(); ++i) {
        const double x = double(i % d.nx), y = double(i / d.nx % d.ny), z = double(i / (d.nx * d.ny));
        const double f = 128 + 60 * std::sin(0.21 * x) * std::cos(0.17 * y) + 2 * z + noise(rng);
        v.as<std::uint8_t>()[i] = std::uint8_t(std::clamp(std::round(f), 0.0, 255.0));
    }
    REQUIRE(noise_block_side(d) == 8);
    const NoiseBlocks want = ref::noise_blocks(v, 8);
    const NoiseLevel r = ref::noise_level(want, 32, 3.0);
    const DeviceVolume dv(ctx(), v);
    const NoiseLevel got = estimate_noise_level(dv);
    CHECK(got.block == 8);
    check_level(got, r, ValueType::uint8);
    // The clipped blocks (reading 255) are left out, the rest give the added noise and its rounding.
    CHECK(got.usable_blocks < got.blocks);
    CHECK(got.usable_blocks > got.blocks / 3);
    CHECK(got.sigma == doctest::Approx(std::sqrt(16.0 + 1.0 / 12)).epsilon(0.03));
    for (std::size_t slab : {std::size_t(8), std::size_t(33)}) {
        NoiseLevelOptions o;
        o.slab_slices = slab;
        const NoiseLevel s = estimate_noise_level(ctx(), v, o);
        CHECK(s.sigma == got.sigma);
        CHECK(s.flat_share == got.flat_share);
    }
}

TEST_CASE("Noise level: Gaussian and uniform noise of known standard deviation on smooth fields") {
    SyntheticOptions so;
    so.size = 96;
    so.type = ValueType::float32;
    const Volume sphere = make_synthetic("sphere", so);
    for (NoiseKind kind : {NoiseKind::gaussian, NoiseKind::uniform})
        for (double sd : {0.5, 2.0, 8.0}) {
            CAPTURE(noise_kind_name(kind));
            CAPTURE(sd);
            NoiseOptions no;
            no.kind = kind;
            no.amplitude = kind == NoiseKind::uniform ? sd * std::sqrt(3.0) : sd;
            no.seed = 5;
            const Volume noisy = add_noise(ctx(), sphere, no);
            const double truth = std_of_difference(noisy, sphere);
            const NoiseLevel l = estimate_noise_level(ctx(), noisy);
            CHECK(l.sigma == doctest::Approx(truth).epsilon(0.02));
            CHECK(l.sigma_white == doctest::Approx(truth).epsilon(0.02));
            for (int k = 0; k < 3; ++k) CHECK(l.correlation[k] < 0.3);
            CHECK(l.flat_share > 0.5);
        }
}

TEST_CASE("Noise level: rounding and clipping of integer data") {
    // A ramp 20..235 in uint8 plus Gaussian noise of 3, rounded: the truth includes the
    // rounding of the noisy values (the clean ramp is exact integers).
    const Dims d{80, 80, 80};
    Volume clean(d, ValueType::uint8);
    for (std::size_t i = 0; i < d.vertices(); ++i) clean.as<std::uint8_t>()[i] = std::uint8_t(20 + (i % d.nx) * 215 / 79);
    NoiseOptions no;
    no.kind = NoiseKind::gaussian;
    no.amplitude = 3;
    no.keep_type = true;
    const Volume noisy = add_noise(ctx(), clean, no);
    CHECK(estimate_noise_level(ctx(), noisy).sigma == doctest::Approx(std_of_difference(noisy, clean)).epsilon(0.02));
    // Half the volume a background at 0: its clipped noise is left out, the other half
    // gives the noise.
    for (std::size_t i = 0; i < d.vertices(); ++i)
        if (i / (d.nx * d.ny) < d.nz / 2) clean.as<std::uint8_t>()[i] = 0;
    const Volume clipped = add_noise(ctx(), clean, no);
    const NoiseLevel l = estimate_noise_level(ctx(), clipped);
    CHECK(l.sigma == doctest::Approx(std::sqrt(9.0 + 1.0 / 12)).epsilon(0.03));
    CHECK(l.flat_share < 0.5);
    CHECK(l.flat_share > 0.3);
}

TEST_CASE("Noise level: the correlation model's fit recovers its own widths and sigma") {
    // Block statistics made from the model, V(s) = a prod f_a(s_a) / 216 + b, on 64 blocks
    // whose variances differ by a few percent (the same in every stride): the fit returns
    // the widths on its grid (0.9% apart) and sigma^2 = a + b.
    // sigma is read where the model's gain first reaches 0.3: at w = 1 the gain is 0.14 at
    // stride 2 and 0.93 at 4; at w = 1.5 (one axis) 0.20 at 2 and 0.78 at 4; at w = 0.8 (two
    // axes) 0.52 at 2.
    const double a = 100, b = 1.0 / 12;
    const std::array<double, 3> ws[] = {{1.0, 1.0, 1.0}, {0.0, 0.0, 1.5}, {0.8, 0.8, 0.0}, {0.0, 0.0, 0.0}};
    const NoiseStride read_at[] = {{4, 4, 4}, {1, 1, 4}, {2, 2, 1}, {1, 1, 1}};
    for (int c = 0; c < 4; ++c) {
        const std::array<double, 3>& w = ws[c];
        CAPTURE(w[0]);
        CAPTURE(w[2]);
        NoiseBlocks blocks;
        blocks.block = 8;
        blocks.grid = {4, 4, 4};
        blocks.volume = {32, 32, 32};
        blocks.strides = noise_strides();
        const auto model = [&](const NoiseStride& s) {
            double g = 1;
            for (int k = 0; k < 3; ++k) g *= noise_stride_factor(w[k], s[k]) / 6;
            return a * g + b;
        };
        blocks.strided_sums.assign(blocks.strides.size(), {});
        blocks.strided_counts.assign(blocks.strides.size(), {});
        for (std::size_t i = 0; i < 64; ++i) {
            const double scale = 1 + 0.002 * double(i % 7);
            blocks.count.push_back(512);
            blocks.sum_squares.push_back(512 * scale * model({1, 1, 1}));
            blocks.low.push_back(i == 0 ? 0.0 : 1.0);
            blocks.high.push_back(i == 1 ? 3.0 : 2.0);
            for (std::size_t m = 0; m < blocks.strides.size(); ++m) {
                blocks.strided_counts[m].push_back(64);
                blocks.strided_sums[m].push_back(64 * scale * model(blocks.strides[m]));
            }
        }
        const NoiseLevel l = noise_level_from_blocks(blocks);
        CHECK(l.flat_blocks == 62);  // blocks 0 and 1 read the extremes
        for (int k = 0; k < 3; ++k) CHECK(l.correlation[k] == doctest::Approx(w[k]).epsilon(0.01));
        CHECK(l.sigma == doctest::Approx(std::sqrt((a + b) * 1.006)).epsilon(0.01));
        CHECK(l.sigma_white == doctest::Approx(std::sqrt(model({1, 1, 1}) * 1.006)).epsilon(0.01));
        CHECK(l.sigma_strides == read_at[c]);
        CHECK_FALSE(l.texture);
        CHECK(l.spread[0] <= l.spread[1]);
        CHECK(l.spread[1] <= l.spread[2]);
        if (c != 2) continue;
        // Texture: V at (4, 4, 1) above 2.25 sigma^2 read at (2, 2, 1), which noise never gives
        // (the gain is at most 1): the correlation is refused, sigma is sigma_white, and said.
        const auto wide = std::find(blocks.strides.begin(), blocks.strides.end(), NoiseStride{4, 4, 1});
        REQUIRE(wide != blocks.strides.end());
        NoiseBlocks rough = blocks;
        for (double& sum : rough.strided_sums[std::size_t(wide - blocks.strides.begin())]) sum *= 2.3 * (a + b) / model({4, 4, 1});
        const NoiseLevel t = noise_level_from_blocks(rough);
        CHECK(t.texture);
        CHECK(t.sigma == t.sigma_white);
        CHECK(t.correlation == std::array<double, 3>{0.0, 0.0, 0.0});
        CHECK(t.sigma_strides == NoiseStride{1, 1, 1});
        const std::vector<std::string> notes = noise_level_notes(t);
        CHECK(std::any_of(notes.begin(), notes.end(),
                          [](const std::string& n) { return n.find("texture or structure") != std::string::npos; }));
        // Just under the limit it stays noise.
        NoiseBlocks smooth = blocks;
        for (double& sum : smooth.strided_sums[std::size_t(wide - blocks.strides.begin())]) sum *= 2.2 * (a + b) / model({4, 4, 1});
        CHECK_FALSE(noise_level_from_blocks(smooth).texture);
    }
}

TEST_CASE("Noise level: Gaussian-smoothed noise reads as its standard deviation, its width as the correlation") {
    // A sphere's distance field plus white Gaussian noise smoothed by a Gaussian of width w
    // (the filter's clamp-to-edge borders included in the truth), scaled to sigma 6.
    SyntheticOptions so;
    so.size = 96;
    so.type = ValueType::float32;
    const Volume sphere = make_synthetic("sphere", so);
    for (double w : {0.8, 1.5}) {
        CAPTURE(w);
        NoiseOptions no;
        no.kind = NoiseKind::gaussian;
        no.amplitude = 1;
        no.seed = 11;
        const Volume zero(sphere.dims(), ValueType::float32);
        const Volume smoothed = gaussian_filter(ctx(), add_noise(ctx(), zero, no), w);
        const double sd = std_of_difference(smoothed, zero);
        Volume noisy(sphere.dims(), ValueType::float32);
        for (std::size_t i = 0; i < noisy.vertices(); ++i)
            noisy.as<float>()[i] = sphere.as<float>()[i] + float(6.0 / sd) * smoothed.as<float>()[i];
        const double truth = std_of_difference(noisy, sphere);
        const NoiseLevel l = estimate_noise_level(ctx(), noisy);
        CHECK(l.sigma == doctest::Approx(truth).epsilon(0.05));
        CHECK(l.sigma_white < 0.5 * truth);
        for (int k = 0; k < 3; ++k) CHECK(l.correlation[k] == doctest::Approx(w).epsilon(0.1));
    }
}

TEST_CASE("Noise level: white noise on shaded and edged structure reads as white, not as wide correlation") {
    // An ellipsoid body shaded by 150 sin(0.05 x) cos(0.07 y), a bright ring inside it and a
    // dark background, uniform white noise of standard deviation 80 / sqrt(12) = 23.09 in the
    // body (uint16). The structure the wider taps reach raises V(s) as s grows, faster the
    // wider: read as correlation, it gave sigma 571 here (24.7x).
    const std::size_t n = 128;
    Volume v(Dims{n, n, n}, ValueType::uint16);
    std::mt19937 rng(88172645);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double c = (n - 1) / 2.0;
    for (std::size_t z = 0; z < n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const double X = double(x), Y = double(y), Z = double(z);
                const double r = std::hypot(std::hypot((X - c) / (0.45 * n), (Y - c) / (0.38 * n)), (Z - c) / (0.48 * n));
                const double rb = std::hypot((X - c) / (0.15 * n), (Y - c - 0.1 * n) / (0.12 * n));
                const double body = 1000 + 150 * std::sin(X * 0.05) * std::cos(Y * 0.07) + 80 * (u(rng) - 0.5);
                const double bone = 1800 + 1700 * (1 - std::abs(rb - 0.9) / 0.1) + 100 * (u(rng) - 0.5);
                const double value = r > 1 ? 20 + 40 * u(rng) : rb > 0.8 && rb < 1.0 ? bone : body;
                v.as<std::uint16_t>()[v.index(x, y, z)] = std::uint16_t(std::lround(value));
            }
    const NoiseLevel l = estimate_noise_level(ctx(), v);
    CHECK(l.sigma == doctest::Approx(80 / std::sqrt(12.0)).epsilon(0.05));
    CHECK(l.sigma == l.sigma_white);
    for (int k = 0; k < 3; ++k) CHECK(l.correlation[k] == 0);
}

TEST_CASE("Noise level: the map reads the noise of cells that an edge crosses, and how it varies") {
    // Gaussian noise whose standard deviation grows from 4 to 8 along x on a ball of +400 (radius
    // 30, float32, 96^3): its surface crosses a few of the 64 blocks of most of the 27 cells.
    // Each cell must read the standard deviation of its own noise within 15%, their median
    // within 5% (the mean of a cell's blocks took the edge's residuals in: cells read up to 4.8
    // times it).
    const std::size_t n = 96;
    Volume v(Dims{n, n, n}, ValueType::float32);
    std::vector<double> noise(v.vertices());
    std::mt19937 rng(4711);
    std::normal_distribution<double> g(0.0, 1.0);
    for (std::size_t z = 0; z < n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const double e = (4 + 4 * double(x) / double(n - 1)) * g(rng), c = (double(n) - 1) / 2;
                const bool ball = std::hypot(std::hypot(double(x) - c, double(y) - c), double(z) - c) <= 30;
                noise[v.index(x, y, z)] = e;
                v.as<float>()[v.index(x, y, z)] = float(100 + (ball ? 400 : 0) + 0.5 * double(z) + e);
            }
    const NoiseLevel l = estimate_noise_level(ctx(), v);
    REQUIRE(l.map_block == 32);
    REQUIRE(l.map_dims == Dims{3, 3, 3});
    std::vector<double> errors;
    for (std::size_t c = 0; c < 27; ++c) {
        const std::size_t cx = c % 3, cy = c / 3 % 3, cz = c / 9;
        double s = 0, s2 = 0, k = 0;
        for (std::size_t z = 32 * cz; z < 32 * cz + 32; ++z)
            for (std::size_t y = 32 * cy; y < 32 * cy + 32; ++y)
                for (std::size_t x = 32 * cx; x < 32 * cx + 32; ++x) {
                    const double w = noise[x + n * (y + n * z)];
                    s += w, s2 += w * w, ++k;
                }
        const double truth = std::sqrt(s2 / k - (s / k) * (s / k));
        INFO("cell " << cx << " " << cy << " " << cz << ": truth " << truth);
        CHECK(double(l.map[c]) == doctest::Approx(truth).epsilon(0.15));
        errors.push_back(std::abs(double(l.map[c]) / truth - 1));
    }
    std::nth_element(errors.begin(), errors.begin() + 13, errors.end());
    CHECK(errors[13] < 0.05);
}

TEST_CASE("Noise level: blurred structure of high contrast under white noise reads as the white noise") {
    // 40 balls of radius 4 to 16 and contrast up to 20,000 in a 96^3 uint16 volume, blurred by
    // a Gaussian of 1.5 voxels, under Gaussian noise of 8: the blur's edges rise with the taps'
    // spacing as smooth correlated noise would, but from block to block by orders of
    // magnitude. Read as correlated noise they gave sigma 657 at (4, 4, 4); the spread of the
    // blocks there refuses the correlation (structure_spread).
    const std::size_t n = 96;
    Volume body(Dims{n, n, n}, ValueType::float32);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<std::array<double, 5>> balls(40);
    for (auto& b : balls) b = {n * u(rng), n * u(rng), n * u(rng), 4 + 12 * u(rng), 20000 * (0.2 + 0.8 * u(rng))};
    for (std::size_t z = 0; z < n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                double f = 1000;
                for (const auto& b : balls) {
                    const double dx = double(x) - b[0], dy = double(y) - b[1], dz = double(z) - b[2];
                    if (dx * dx + dy * dy + dz * dz < b[3] * b[3]) f += b[4];
                }
                body.as<float>()[body.index(x, y, z)] = float(f);
            }
    const Volume blurred = gaussian_filter(ctx(), body, 1.5);
    Volume v(Dims{n, n, n}, ValueType::uint16);
    std::normal_distribution<double> g(0.0, 8.0);
    double s2 = 0;
    for (std::size_t i = 0; i < v.vertices(); ++i) {
        const double f = double(blurred.as<float>()[i]), e = g(rng);
        const double x = std::clamp(std::round(f + e), 0.0, 65535.0);
        v.as<std::uint16_t>()[i] = std::uint16_t(x);
        s2 += (x - f) * (x - f);
    }
    const NoiseLevel l = estimate_noise_level(ctx(), v);
    INFO("sigma " << l.sigma << " white " << l.sigma_white << " truth " << std::sqrt(s2 / double(v.vertices())));
    CHECK(l.sigma == doctest::Approx(std::sqrt(s2 / double(v.vertices()))).epsilon(0.05));
    CHECK(l.texture);
}

TEST_CASE("Noise level: no residual, no usable block, bad options") {
    const Volume flat(Dims{20, 20, 20}, ValueType::uint8);  // all 0: every block reads the extremes
    NoiseLevel l = estimate_noise_level(ctx(), flat);
    CHECK(std::isnan(l.sigma));
    CHECK(l.usable_blocks == 0);
    CHECK(l.flat_share == 0);
    const Volume thin = testutil::random_volume({30, 2, 30}, ValueType::float32, 0, 100, 3);
    l = estimate_noise_level(ctx(), thin);
    CHECK(std::isnan(l.sigma));
    CHECK(l.block == 4);
    CHECK(l.blocks == 64);
    // An exact ramp has no residual anywhere: no noise, on every block that reads no extreme.
    Volume ramp(Dims{40, 30, 20}, ValueType::float32);
    for (std::size_t i = 0; i < ramp.vertices(); ++i)
        ramp.as<float>()[i] = float(2 * (i % 40) + (i / 40 % 30) + 0.5 * double(i / 1200));
    l = estimate_noise_level(ctx(), ramp);
    CHECK(l.sigma == 0);
    CHECK(l.flat_blocks == l.usable_blocks);
    CHECK(l.flat_share > 0.3);
    check_level(l, ref::noise_level(ref::noise_blocks(ramp, l.block), 32, 3.0), ValueType::float32);
    NoiseLevelOptions o;
    o.block = 1;
    CHECK_THROWS_AS(estimate_noise_level(ctx(), flat, o), InputError);
    o.block = 16;
    o.map_block = 24;
    CHECK_THROWS_AS(estimate_noise_level(ctx(), flat, o), InputError);
    o.map_block = 32;
    o.clip = 0;
    CHECK_THROWS_AS(estimate_noise_level(ctx(), flat, o), InputError);
}

}  // TEST_SUITE
