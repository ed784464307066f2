// Smooth isosurface construction (Algorithms 1 and 2) against the plain reference
// (test/reference/smooth_reference): identical output volumes, and the guarantees of
// docs/definitions.md §18 "Smooth isosurface construction": termination, no intersected
// high-fractal edge at the end, values never increase, a threshold above every LD changes
// nothing, noise components removed and clean ones kept.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "clfractal/local.hpp"
#include "clfractal/smooth.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/smooth_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

bool same_bytes(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() && a.size_bytes() == b.size_bytes() &&
           std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

// Vertices whose value in `after` is above the one in `before` (must be none).
std::size_t increased(const Volume& before, const Volume& after) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < before.vertices(); ++i) n += after.value(i) > before.value(i);
    return n;
}

std::size_t differing(const Volume& a, const Volume& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.vertices(); ++i) n += a.value(i) != b.value(i);
    return n;
}

std::uint64_t grid_edges(const Dims& d) {
    return (d.nx - 1) * d.ny * d.nz + d.nx * (d.ny - 1) * d.nz + d.nx * d.ny * (d.nz - 1);
}

// The guarantees of one run, given the LD field it used.
void check_guarantees(const Volume& in, const SmoothResult& r, const std::vector<double>& ld, double iso, double h) {
    CHECK(r.volume.dims() == in.dims());
    CHECK(r.volume.type() == in.type());
    CHECK(r.volume.spacing == in.spacing);
    CHECK(increased(in, r.volume) == 0);
    CHECK(ref::high_fractal_edges(r.volume, ld, iso, h) == 0);
    // Each edge is queued at most once, and lowered at most once.
    CHECK(r.edges_processed <= grid_edges(in.dims()));
    CHECK(r.edges_lowered <= r.edges_processed);
    CHECK(r.initial_edges <= r.edges_processed);
    CHECK(r.vertices_changed == differing(in, r.volume));
    if (r.edges_lowered == 0) CHECK(r.vertices_changed == 0);
}

// Runs both implementations and compares everything they share.
void check_against_reference(const Volume& v, double iso, double h, int window, SmoothVariant variant, double tau) {
    CAPTURE(dims_string(v.dims()));
    CAPTURE(value_type_name(v.type()));
    CAPTURE(iso);
    CAPTURE(h);
    CAPTURE(window);
    CAPTURE(std::string(smooth_variant_name(variant)));
    const SmoothResult r = smooth_isosurface(ctx(), v, iso, h, window, variant, tau, true);
    REQUIRE(r.ld.vertices() == v.vertices());
    const Volume ld_direct = local_fractal_dimension(ctx(), v, iso, window);
    CHECK(std::memcmp(r.ld.data(), ld_direct.data(), r.ld.size_bytes()) == 0);
    const std::vector<double> ld = ref::field_values(r.ld);

    const ref::SmoothOutcome want = ref::smooth(v, ld, iso, h, variant, tau);
    CHECK(same_bytes(r.volume, want.volume));
    if (!same_bytes(r.volume, want.volume)) MESSAGE("vertices that differ: " << differing(r.volume, want.volume));
    CHECK(r.initial_edges == ref::high_fractal_edges(v, ld, iso, h));
    CHECK(r.edges_lowered == want.lowered);
    CHECK(r.edges_processed == want.distinct_queued);
    CHECK(r.edges_processed <= want.pops);
    std::size_t hot = 0;
    for (double x : ld) hot += x > h;
    CHECK(r.high_vertices == hot);
    // Plain: each lowering moves one vertex from >= s to < s for good.
    if (variant == SmoothVariant::plain) CHECK(r.vertices_changed == r.edges_lowered);
    check_guarantees(v, r, ld, iso, h);
    // Without the field to keep, a CPU device takes the flags slab by slab: thin slabs of 1 to
    // 3 slices (Tuning::slab_bytes) give the same result.
    const std::size_t saved = ctx().tuning.slab_bytes;
    ctx().tuning.slab_bytes = (1 + v.dims().nz % 3) * v.dims().nx * v.dims().ny * value_size(v.type());
    const SmoothResult s = smooth_isosurface(ctx(), v, iso, h, window, variant, tau, false);
    ctx().tuning.slab_bytes = saved;
    CHECK(same_bytes(s.volume, r.volume));
    CHECK(s.ld.vertices() == 0);
    CHECK(s.initial_edges == r.initial_edges);
    CHECK(s.high_vertices == r.high_vertices);
    CHECK(s.edges_lowered == r.edges_lowered);
    CHECK(s.edges_processed == r.edges_processed);
    CHECK(s.vertices_changed == r.vertices_changed);
}

using testutil::Case;

// 1- and 2-vertex axes, primes, all four types; narrow ranges so that most edges are
// intersected and LD is high.
const Case cases[] = {
    {{1, 1, 1}, ValueType::uint8, 0, 3},         {{2, 2, 2}, ValueType::uint8, 0, 3},
    {{1, 5, 7}, ValueType::uint8, 0, 3},         {{5, 1, 7}, ValueType::uint16, 0, 5},
    {{7, 5, 1}, ValueType::int16, -4, 4},        {{2, 3, 2}, ValueType::float32, -6, 6},
    {{13, 7, 11}, ValueType::uint8, 0, 9},       {{17, 9, 5}, ValueType::uint16, 1000, 1012},
    {{11, 13, 7}, ValueType::int16, -9, 9},      {{19, 6, 9}, ValueType::float32, -8, 8},
    {{16, 16, 16}, ValueType::uint8, 0, 6},      {{15, 14, 13}, ValueType::float32, -7, 7},
    {{23, 19, 17}, ValueType::int16, -32768, -32758},
    // Revision 2 types; int32 and uint32 near their maxima (a float32 isovalue would round),
    // int8 at its minimum (the gaussian variant clamps there).
    {{13, 9, 8}, ValueType::int32, 2147483000, 2147483012}, {{9, 11, 7}, ValueType::uint32, 4294967270, 4294967290},
    {{11, 8, 9}, ValueType::int8, -128, -118},              {{12, 7, 10}, ValueType::float64, -8, 8},
};

double mid_isovalue(const Case& c) {
    const double mid = double((c.lo + c.hi) / 2);
    return is_integer(c.t) ? mid : mid / 2;
}

// A clean sphere (value 100 at radius 11, rising inwards by 10 per step) in the left part
// and, when `seed` is not 0, a noisy ball in the right part: radius 7, values 100 plus
// uniform noise in [-30, 30], background 0. The two are 33 steps apart: no LD window of size
// 8 sees both. uint8 values.
constexpr std::size_t split_x = 34;  // the sphere lies in x < split_x, the noisy ball beyond
Volume sphere_and_noisy_ball(std::uint32_t seed) {
    const Dims d{64, 36, 36};
    Volume v(d, ValueType::uint8, "sphere+ball");
    std::uint8_t* p = v.as<std::uint8_t>();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> noise(-30, 30);
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) {
                const double r = std::hypot(x - 17.0, y - 17.5, z - 17.5), rb = std::hypot(x - 50.0, y - 17.5, z - 17.5);
                double f = 100 + 10 * (11 - r);
                if (seed && rb < 7) f = 100 + noise(rng);
                p[v.index(x, y, z)] = std::uint8_t(std::lround(std::clamp(f, 0.0, 255.0)));
            }
    return v;
}

}  // namespace

TEST_SUITE("smooth") {

TEST_CASE("both variants equal the plain reference: every type, awkward sizes, both LD kernels") {
    testutil::TuningGuard guard;
    for (const char* local_variant : {"rows", "vertices"}) {
        ctx().tuning.local_variant = parse_variant<LocalVariant>(local_variant);
        CAPTURE(std::string(local_variant));
        std::uint32_t seed = 11;
        for (const Case& c : cases) {
            const Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
            const double iso = mid_isovalue(c);
            for (double h : {2.0, 2.5, 2.8}) {
                check_against_reference(v, iso, h, 8, SmoothVariant::plain, 1.0);
                check_against_reference(v, iso, h, 8, SmoothVariant::gaussian, 1.0);
            }
            // Another isovalue (between values for integer data), window and tau.
            check_against_reference(v, iso + 0.5, 2.3, 4, SmoothVariant::plain, 1.0);
            check_against_reference(v, iso + 0.5, 2.3, 4, SmoothVariant::gaussian, 0.6);
            check_against_reference(v, iso, 1.5, 2, SmoothVariant::gaussian, 2.5);
            // An isovalue that float32 rounds (compared as float32 on float data).
            check_against_reference(v, iso + 0.3, 2.4, 8, SmoothVariant::gaussian, 1.0);
        }
    }
}

TEST_CASE("the gaussian variant clamps at the type's minimum and lowers neighbours") {
    // uint8 with zeros next to the surface: a wrapping decrement would raise them to ~255.
    Volume v = testutil::random_volume({12, 11, 10}, ValueType::uint8, 0, 40, 3);
    for (std::size_t i = 0; i < v.vertices(); i += 3) v.as<std::uint8_t>()[i] = 0;
    check_against_reference(v, 20, 1.0, 4, SmoothVariant::gaussian, 1.5);
    const SmoothResult plain = smooth_isosurface(ctx(), v, 20, 1.0, 4, SmoothVariant::plain);
    const SmoothResult gauss = smooth_isosurface(ctx(), v, 20, 1.0, 4, SmoothVariant::gaussian, 1.5);
    CHECK(plain.edges_lowered > 0);
    // Gaussian lowering also changes vertices that were never the upper end of an edge.
    CHECK(gauss.vertices_changed > gauss.edges_lowered / 4);
    // float32 near -FLT_MAX stays finite.
    Volume f({6, 5, 4}, ValueType::float32);
    float* q = f.as<float>();
    for (std::size_t i = 0; i < f.vertices(); ++i) q[i] = (i * 7919) % 5 < 2 ? -3.0e38f : 3.0e38f;
    check_against_reference(f, 0.0, -1.0, 2, SmoothVariant::gaussian, 1.0);
    const SmoothResult rf = smooth_isosurface(ctx(), f, 0.0, -1.0, 2, SmoothVariant::gaussian, 1.0);
    for (std::size_t i = 0; i < f.vertices(); ++i) CHECK(std::isfinite(rf.volume.as<float>()[i]));
}

TEST_CASE("a threshold at or above every LD changes nothing") {
    std::uint32_t seed = 101;
    for (const Case& c : cases) {
        const Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        const double iso = mid_isovalue(c);
        const Volume ld = local_fractal_dimension(ctx(), v, iso, 8);
        double top = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < ld.vertices(); ++i)
            if (!std::isnan(ld.as<float>()[i])) top = std::max(top, double(ld.as<float>()[i]));
        for (SmoothVariant variant : {SmoothVariant::plain, SmoothVariant::gaussian})
            for (double h : {top, top + 0.01, 1e30}) {
                CAPTURE(dims_string(c.d)); CAPTURE(h);
                const SmoothResult r = smooth_isosurface(ctx(), v, iso, h, 8, variant);
                CHECK(same_bytes(r.volume, v));
                CHECK(r.initial_edges == 0);
                CHECK(r.edges_processed == 0);
                CHECK(r.vertices_changed == 0);
                CHECK(r.high_vertices == 0);
            }
    }
}

TEST_CASE("a clean sphere and a noisy ball: the ball's components go, the sphere stays") {
    const Volume sphere = sphere_and_noisy_ball(0);
    const double iso = 100, h = 2.5;
    REQUIRE(ref::components_bfs(sphere, iso) == 1);
    const std::uint64_t sphere_cubes = intersected_counts(ctx(), sphere, iso).cubes;
    int clean_runs = 0;  // runs that leave exactly the sphere
    for (std::uint32_t seed : {1u, 2u, 3u, 4u}) {
        const Volume v = sphere_and_noisy_ball(seed);
        const std::uint64_t before = ref::components_bfs(v, iso);
        CHECK(before > 3);  // the sphere and the noise pieces of the ball
        std::size_t ball_positive = 0;
        for (std::size_t i = 0; i < v.vertices(); ++i) ball_positive += i % 64 >= split_x && v.value(i) >= iso;
        for (SmoothVariant variant : {SmoothVariant::plain, SmoothVariant::gaussian}) {
            CAPTURE(seed);
            CAPTURE(std::string(smooth_variant_name(variant)));
            const SmoothResult r = smooth_isosurface(ctx(), v, iso, h, 8, variant, 1.0, true);
            check_guarantees(v, r, ref::field_values(r.ld), iso, h);
            const std::uint64_t after = ref::components_bfs(r.volume, iso);
            std::size_t left = 0, sphere_changed = 0;
            for (std::size_t i = 0; i < v.vertices(); ++i) {
                if (i % 64 >= split_x) left += r.volume.value(i) >= iso;
                else sphere_changed += r.volume.value(i) != sphere.value(i);
            }
            // The ball's components go: what can remain are a few vertices on its rim, where
            // the window is half empty and LD <= h (thesis §5.1: the result depends on h).
            CHECK(after >= 1);
            CHECK(after - 1 <= (before - 1) / 3);
            CHECK(left * 100 <= ball_positive);
            clean_runs += after == 1 && left == 0;
            // The sphere keeps its surface. A digital sphere has LD up to about 2.6-2.8 at a
            // few vertices with k = 8 (box counts of a curved staircase), so h = 2.5 may lower
            // a few of its vertices.
            const std::uint64_t cubes = intersected_counts(ctx(), r.volume, iso).cubes;
            const std::uint64_t ball_cubes = left ? 27 * left : 0;  // at most 8 per positive vertex, and neighbours
            CHECK(double(cubes) >= 0.97 * double(sphere_cubes));
            CHECK(cubes <= sphere_cubes + sphere_cubes / 20 + ball_cubes);
            MESSAGE("seed " << seed << ", " << std::string(smooth_variant_name(variant)) << ": components " << before << " -> "
                            << after << ", intersected cubes " << intersected_counts(ctx(), v, iso).cubes << " -> "
                            << cubes << " (the sphere alone: " << sphere_cubes << "), ball vertices >= s "
                            << ball_positive << " -> " << left << ", sphere vertices changed " << sphere_changed);
        }
    }
    CHECK(clean_runs >= 4);
}

TEST_CASE("intersected_counts equals the reference edge count") {
    std::uint32_t seed = 5;
    for (const Case& c : cases) {
        const Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        const double iso = mid_isovalue(c);
        CHECK(intersected_counts(ctx(), v, iso).edges == ref::intersected_edges(v, iso));
        CHECK(intersected_counts(ctx(), v, iso + 0.25).edges == ref::intersected_edges(v, iso + 0.25));
    }
}

TEST_CASE("bad arguments") {
    const Volume v = testutil::random_volume({5, 5, 5}, ValueType::uint8, 0, 9, 1);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, 4, 2.2, 5), InputError);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, 4, 2.2, 0), InputError);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, std::nan(""), 2.2), InputError);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, 4, std::nan("")), InputError);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, 4, 2.2, 8, SmoothVariant::gaussian, 0.0), InputError);
    CHECK_THROWS_AS(smooth_isosurface(ctx(), v, 4, 2.2, 8, SmoothVariant::gaussian, -1.0), InputError);
    CHECK_NOTHROW(smooth_isosurface(ctx(), v, 4, 2.2, 8, SmoothVariant::plain, 0.0));  // tau unused
    CHECK_THROWS_AS(parse_smooth_variant("blocky"), InputError);
    CHECK(parse_smooth_variant("gaussian") == SmoothVariant::gaussian);
}

}  // TEST_SUITE("smooth")

TEST_SUITE("smooth_realdata") {

// Every real volume in shared/data at a few isovalues (a fifth and two fifths into the value
// range) and thresholds (2.2 plain, 2.5 plain, 2.5 gaussian): the guarantees, and equality with
// the reference on the small ones. Volumes over 4 M vertices: the first isovalue, two runs.
TEST_CASE("real volumes: the guarantees at a few isovalues and thresholds") {
    const auto reals = testutil::real_volumes("real-volume smooth checks");
    if (reals.empty()) return;
    int volumes = 0, runs = 0;
    for (const testutil::RealVolume& real : reals) {
        const std::string& file = real.file();
        const Volume v = read_volume(real.path);
        const ValueRange range = value_range(v);
        const bool small = v.vertices() <= 300000, large = v.vertices() > 4000000;
        std::vector<double> isovalues;
        for (double t : {0.2, 0.4}) {
            double s = range.min + t * (range.max - range.min);
            if (is_integer(v.type())) s = std::round(s);
            isovalues.push_back(s);
            if (large) break;  // one isovalue for the largest volumes keeps the suite short
        }
        for (double iso : isovalues) {
            struct Run {
                double h;
                SmoothVariant variant;
            };
            for (const Run& run : {Run{2.2, SmoothVariant::plain}, Run{2.5, SmoothVariant::plain},
                                   Run{2.5, SmoothVariant::gaussian}}) {
                if (large && run.h == 2.5 && run.variant == SmoothVariant::plain) continue;  // time
                CAPTURE(file);
                CAPTURE(iso);
                CAPTURE(run.h);
                CAPTURE(std::string(smooth_variant_name(run.variant)));
                if (small) {
                    check_against_reference(v, iso, run.h, 8, run.variant, 1.0);
                } else {
                    const SmoothResult r = smooth_isosurface(ctx(), v, iso, run.h, 8, run.variant, 1.0, true);
                    check_guarantees(v, r, ref::field_values(r.ld), iso, run.h);
                }
                ++runs;
            }
        }
        ++volumes;
    }
    MESSAGE("real volumes checked: " << volumes << ", runs: " << runs);
    CHECK(volumes >= 16);
}

// The figures of docs/guide/smooth.md: intersected cubes and components (BFS) before and after, on two
// noisy real volumes.
TEST_CASE("real volumes: intersected cubes and components before and after") {
    const std::string dir = testutil::shared_data_or_skip("real-volume smooth figures");
    if (dir.empty()) return;
    struct Real {
        const char* file;
        double iso;
    };
    for (const Real& r : {Real{"seg3d_mr_160x232x160_uint8.raw", 60}, Real{"engine_256x256x128_uint8.raw", 100}}) {
        const Volume v = read_volume(dir + "/" + r.file);
        const std::uint64_t cubes = intersected_counts(ctx(), v, r.iso).cubes;
        const std::uint64_t components = ref::components_bfs(v, r.iso);
        for (double h : {2.2, 2.5})
            for (SmoothVariant variant : {SmoothVariant::plain, SmoothVariant::gaussian}) {
                const SmoothResult s = smooth_isosurface(ctx(), v, r.iso, h, 8, variant);
                MESSAGE(std::string(r.file) << " s=" << r.iso << " h=" << h << " " << std::string(smooth_variant_name(variant))
                               << ": intersected cubes " << cubes << " -> " << intersected_counts(ctx(), s.volume, r.iso).cubes
                               << ", components " << components << " -> " << ref::components_bfs(s.volume, r.iso)
                               << ", edges processed " << s.edges_processed << ", vertices changed "
                               << s.vertices_changed);
                CHECK(increased(v, s.volume) == 0);
            }
    }
}

}  // TEST_SUITE("smooth_realdata")
