// Isosurface components (docs/definitions.md §19 "Isosurface components", §20 "Correlation"):
// the two-sweep curve against breadth-first labelling of A = {f < s} and C = {f >= s} through
// the identity b0(A) + b0(C) - 1, at every isovalue, both modes; against the pieces of the
// marching-cubes / marching-tetrahedra mesh at generic isovalues; known shapes; and the
// correlation against a plain two-pass Pearson.
#include <doctest/doctest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <limits>
#include <sstream>

#include "clfractal/components.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "components_labelling.hpp"
#include "measures/components_slab.hpp"
#include "reference/mesh_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;

namespace {

// b0(A) + b0(C) - 1 by plain BFS (test/reference), 0 when either set is empty.
std::int64_t identity(const Volume& v, double s, Connectivity mode) {
    const auto a_adj = mode == Connectivity::cube ? ref::Adjacency::six : ref::Adjacency::fourteen;
    const auto c_adj = mode == Connectivity::cube ? ref::Adjacency::twenty_six : ref::Adjacency::fourteen;
    const std::size_t a = ref::components(v, s, false, a_adj), c = ref::components(v, s, true, c_adj);
    return a && c ? std::int64_t(a + c) - 1 : 0;
}

// The whole curve against the identity at every isovalue; returns the number of mismatches.
// Every isovalue, or, with `at_most`, that many spread evenly over the set (the first and the
// last among them): the labelling is a scan of the volume per isovalue, and an integer range
// of 60,000 values is as many isovalues.
int check_curve(const Volume& v, Connectivity mode, const IsovalueSet& iso, std::size_t at_most = 0) {
    ComponentCurve c = count_components(testutil::ctx(), v, iso, mode);
    REQUIRE(c.components.size() == iso.size());
    int bad = 0;
    const std::size_t n = iso.size(), m = at_most > 1 && n > at_most ? at_most : n;
    for (std::size_t k = 0; k < m; ++k) {
        const std::size_t j = m == n ? k : k * (n - 1) / (m - 1);
        const std::int64_t want = identity(v, iso.value(j), mode);
        if (c.components[j] != want) {
            if (bad < 5)
                MESSAGE(dims_string(v.dims()) << " " << value_type_name(v.type()) << " "
                                              << connectivity_name(mode) << " s=" << iso.value(j) << ": sweep "
                                              << c.components[j] << ", labelling " << want);
            ++bad;
        }
    }
    return bad;
}

int check_curve(const Volume& v, Connectivity mode) { return check_curve(v, mode, IsovalueSet::for_volume(v, 64)); }

Volume binary(Dims d, const std::function<bool(double, double, double)>& inside) {
    Volume v(d, ValueType::uint8);
    auto* p = v.as<std::uint8_t>();
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) p[v.index(x, y, z)] = inside(double(x), double(y), double(z)) ? 1 : 0;
    return v;
}

const Connectivity modes[] = {Connectivity::cube, Connectivity::freudenthal};
const auto& types = all_value_types;

}  // namespace

TEST_SUITE("components") {

TEST_CASE("sweep equals the labelling identity on random grids, every isovalue, both modes, all types") {
    const Dims dims[] = {{1, 1, 1}, {1, 1, 9}, {7, 1, 1}, {1, 5, 6}, {2, 2, 2}, {2, 3, 7}, {5, 5, 5},
                         {7, 6, 5}, {11, 3, 2}, {13, 7, 4}, {9, 9, 9}};
    std::uint32_t seed = 1;
    for (const Dims& d : dims)
        for (ValueType t : types)
            for (Connectivity m : modes) {
                // Few levels (many ties) and many levels; negative values for int16 and float.
                const long lo = t == ValueType::int16 || t == ValueType::float32 || t == ValueType::int8 ? -6
                                : t == ValueType::int32                                           ? -2147483647 - 1
                                : t == ValueType::uint32 ? 4294967000
                                : t == ValueType::float64 ? -6 : 0;
                CAPTURE(dims_string(d));
                CAPTURE(value_type_name(t));
                CAPTURE(connectivity_name(m));
                CHECK(check_curve(testutil::random_volume(d, t, lo, lo + 3, seed++), m) == 0);
                CHECK(check_curve(testutil::random_volume(d, t, lo, lo + 40, seed++), m) == 0);
            }
}

TEST_CASE("wide value ranges: uint16 and int16 extremes, float isovalue lists") {
    for (Connectivity m : modes) {
        Volume u = testutil::random_volume({6, 5, 4}, ValueType::uint16, 0, 65535, 77);
        u.as<std::uint16_t>()[0] = 0;
        u.as<std::uint16_t>()[1] = 65535;
        // Every integer isovalue would be 65536 BFS passes: check a strided subset by hand.
        ComponentCurve c = count_components(testutil::ctx(), u, IsovalueSet::for_volume(u), m);
        for (std::size_t j = 0; j < c.components.size(); j += 997)
            CHECK(c.components[j] == identity(u, c.isovalues.value(j), m));
        CHECK(c.components.back() == identity(u, 65535, m));
        Volume s = testutil::random_volume({5, 7, 3}, ValueType::int16, -32768, 32767, 78);
        s.as<std::int16_t>()[3] = -32768;
        ComponentCurve cs = count_components(testutil::ctx(), s, IsovalueSet::for_volume(s), m);
        for (std::size_t j = 0; j < cs.components.size(); j += 1009)
            CHECK(cs.components[j] == identity(s, cs.isovalues.value(j), m));
        // A float list that includes values below, at and above the data.
        Volume f = testutil::random_volume({8, 6, 5}, ValueType::float32, -20, 20, 79);
        CHECK(check_curve(f, m, IsovalueSet::floats({-100.f, -10.f, -0.5f, 0.f, 0.25f, 3.f, 9.5f, 10.f, 11.f, 100.f})) == 0);
        // int32 and uint32 over their whole range (uniform float64 isovalues, key sort), and
        // float64 values a float32 cannot tell apart (comparison sort, double isovalues).
        for (ValueType t : {ValueType::int32, ValueType::uint32}) {
            Volume w = testutil::random_volume({7, 6, 5}, t, long(type_min(t)), long(type_max(t)), 80);
            REQUIRE(IsovalueSet::for_volume(w, 64).float64());
            CHECK(check_curve(w, m) == 0);
        }
        Volume d(Dims{7, 8, 6}, ValueType::float64);
        const Volume k = testutil::random_volume(d.dims(), ValueType::int16, 0, 12, 81);
        for (std::size_t i = 0; i < d.vertices(); ++i) d.as<double>()[i] = 1 + std::ldexp(k.value(i), -40);
        const ComponentCurve cd = count_components(testutil::ctx(), d, IsovalueSet::for_volume(d, 24), m);
        CHECK(*std::max_element(cd.components.begin(), cd.components.end()) > 0);
        CHECK(check_curve(d, m, IsovalueSet::for_volume(d, 24)) == 0);
    }
}

TEST_CASE("structured grids: smooth fields, ties and plateaus") {
    for (Connectivity m : modes) {
        // A radial field with many exact ties.
        Volume r({12, 11, 10}, ValueType::uint8);
        for (std::size_t z = 0; z < 10; ++z)
            for (std::size_t y = 0; y < 11; ++y)
                for (std::size_t x = 0; x < 12; ++x) {
                    const double q = (x - 5.5) * (x - 5.5) + (y - 5.0) * (y - 5.0) + (z - 4.5) * (z - 4.5);
                    r.as<std::uint8_t>()[r.index(x, y, z)] = std::uint8_t(std::sqrt(q) * 3);
                }
        CHECK(check_curve(r, m) == 0);
        // A checkerboard: the extreme case of separated components.
        Volume c = binary({7, 8, 9}, [](double x, double y, double z) { return (int(x + y + z) & 1) == 1; });
        CHECK(check_curve(c, m) == 0);
        // Plateaus: a few large constant blocks with a noisy seam.
        Volume p = testutil::random_volume({10, 10, 10}, ValueType::uint8, 0, 2, 5);
        for (std::size_t i = 0; i < p.vertices(); ++i)
            if (i % 10 < 7) p.as<std::uint8_t>()[i] = std::uint8_t(i / 300);
        CHECK(check_curve(p, m) == 0);
        // Constant volumes: no isovalue separates anything.
        Volume k({4, 3, 5}, ValueType::float32);
        ComponentCurve ck = count_components(testutil::ctx(), k, IsovalueSet::floats({-1.f, 0.f, 1.f}), m);
        CHECK(ck.components == std::vector<std::int64_t>{0, 0, 0});
    }
}

TEST_CASE("components equal the connected pieces of the mesh at generic isovalues") {
    // Float data are integers / 2, so isovalues at quarter points hit no vertex.
    std::uint32_t seed = 300;
    const Dims dims[] = {{5, 4, 3}, {6, 6, 6}, {2, 7, 5}, {9, 5, 4}};
    for (const Dims& d : dims)
        for (Connectivity m : modes) {
            Volume v = testutil::random_volume(d, ValueType::float32, 0, 8, seed++);
            std::vector<float> s;
            for (int k = 0; k < 8; ++k) s.push_back(float(k) / 2 + 0.25f);
            ComponentCurve c = count_components(testutil::ctx(), v, IsovalueSet::floats(s), m);
            for (std::size_t j = 0; j < s.size(); ++j) {
                Mesh mesh = extract_isosurface(
                    v, s[j], m == Connectivity::cube ? MeshMethod::marching_cubes : MeshMethod::marching_tetrahedra);
                CAPTURE(dims_string(d));
                CAPTURE(connectivity_name(m));
                CAPTURE(s[j]);
                CHECK(std::int64_t(ref::topology(mesh).pieces) == c.components[j]);
            }
        }
}

TEST_CASE("known shapes: two balls, a hollow shell, a torus") {
    const Dims d{24, 20, 18};
    auto ball = [](double x, double y, double z, double cx, double cy, double cz, double r) {
        return (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= r * r;
    };
    Volume two = binary(d, [&](double x, double y, double z) {
        return ball(x, y, z, 6, 9, 9, 4) || ball(x, y, z, 17, 10, 8, 4.5);
    });
    Volume shell = binary(d, [&](double x, double y, double z) {
        return ball(x, y, z, 11.5, 9.5, 8.5, 7.5) && !ball(x, y, z, 11.5, 9.5, 8.5, 4);
    });
    Volume torus = binary(d, [&](double x, double y, double z) {
        const double q = std::hypot(x - 11.5, y - 9.5) - 6;
        return q * q + (z - 8.5) * (z - 8.5) <= 2.5 * 2.5;
    });
    for (Connectivity m : modes) {
        CHECK(count_components_at(testutil::ctx(), two, 1, m) == 2);
        CHECK(count_components_at(testutil::ctx(), shell, 1, m) == 2);
        CHECK(count_components_at(testutil::ctx(), torus, 1, m) == 1);
        CHECK(count_components_by_labelling(two, 1, m) == 2);
        CHECK(count_components_by_labelling(shell, 1, m) == 2);
        CHECK(count_components_by_labelling(torus, 1, m) == 1);
        // Outside the range (s <= 0: A empty; s > 1: C empty).
        CHECK(count_components_at(testutil::ctx(), two, 0, m) == 0);
        CHECK(count_components_at(testutil::ctx(), two, 2, m) == 0);
        CHECK(count_components_at(testutil::ctx(), two, 0.5, m) == 2);  // f >= 0.5 <=> f >= 1
    }
    // Diagonal contact: two voxels touching at a corner are one piece of C in cube mode
    // (26-connected) and two in Freudenthal mode unless the corner is along +(1,1,1).
    Volume diag({4, 4, 4}, ValueType::uint8);
    diag.as<std::uint8_t>()[diag.index(1, 1, 1)] = 1;
    diag.as<std::uint8_t>()[diag.index(2, 2, 2)] = 1;
    CHECK(count_components_at(testutil::ctx(), diag, 1, Connectivity::cube) == 1);
    CHECK(count_components_at(testutil::ctx(), diag, 1, Connectivity::freudenthal) == 1);
    Volume anti({4, 4, 4}, ValueType::uint8);
    anti.as<std::uint8_t>()[anti.index(2, 1, 1)] = 1;
    anti.as<std::uint8_t>()[anti.index(1, 2, 2)] = 1;
    CHECK(count_components_at(testutil::ctx(), anti, 1, Connectivity::cube) == 1);
    CHECK(count_components_at(testutil::ctx(), anti, 1, Connectivity::freudenthal) == 2);
}

TEST_CASE("the labelling baseline and count_components_at agree with the curve") {
    for (ValueType t : types)
        for (Connectivity m : modes) {
            Volume v = testutil::random_volume({7, 5, 6}, t, 0, 12, 900 + int(t));
            ComponentCurve c = count_components(testutil::ctx(), v, IsovalueSet::for_volume(v, 16), m);
            for (std::size_t j = 0; j < c.components.size(); ++j) {
                CHECK(count_components_by_labelling(v, c.isovalues.value(j), m) == c.components[j]);
                CHECK(count_components_at(testutil::ctx(), v, c.isovalues.value(j), m) == c.components[j]);
            }
        }
}

// Direct labelling at the given isovalues against the curve; the number of mismatches.
int check_direct(const Volume& v, Connectivity mode, const IsovalueSet& iso) {
    const ComponentCurve c = count_components(testutil::ctx(), v, iso, mode);
    std::vector<double> at;
    for (std::size_t j = 0; j < iso.size(); ++j) at.push_back(iso.value(j));
    const std::vector<std::int64_t> direct = count_components_at(v, at, mode);
    REQUIRE(direct.size() == at.size());
    int bad = 0;
    for (std::size_t j = 0; j < at.size(); ++j)
        if (direct[j] != c.components[j]) {
            if (bad++ < 5)
                MESSAGE(dims_string(v.dims()) << " " << value_type_name(v.type()) << " " << connectivity_name(mode)
                                              << " s=" << at[j] << ": direct " << direct[j] << ", curve "
                                              << c.components[j]);
        }
    return bad;
}

// check(v, m) on a random volume of each dims, every type and both modes, on each number of
// threads: values lo .. lo + 3 or lo + 30 in turn (lo -5 for the signed types).
template <class F>
void for_random_volumes(const std::vector<Dims>& dims, std::initializer_list<int> threads, std::uint32_t seed,
                        F&& check) {
    const int before = omp_get_max_threads();
    for (int t : threads) {
        omp_set_num_threads(t);
        for (const Dims& d : dims)
            for (ValueType type : types)
                for (Connectivity m : modes) {
                    CAPTURE(t);
                    CAPTURE(dims_string(d));
                    CAPTURE(value_type_name(type));
                    CAPTURE(connectivity_name(m));
                    const long lo = type == ValueType::int8 || type == ValueType::int16 ? -5 : 0;
                    const Volume v = testutil::random_volume(d, type, lo, lo + (seed % 2 ? 3 : 30), seed);
                    ++seed;
                    check(v, m);
                }
    }
    omp_set_num_threads(before);
}

TEST_CASE("direct labelling at a few isovalues: the curve and BFS, every type, both modes, any number of z-chunks") {
    // Rows of 70 and 97: the blocks of 32 that row_runs passes over, and their tails. 1 .. 7
    // threads: 2 chunks a thread, so seams fall between every pair of planes somewhere.
    for_random_volumes({{1, 1, 1}, {1, 1, 9}, {9, 1, 1}, {1, 8, 1}, {2, 3, 7}, {7, 6, 5}, {13, 7, 11}, {5, 4, 23},
                        {70, 3, 5}, {97, 2, 3}},
                       {1, 2, 3, 7}, 500, [](const Volume& v, Connectivity m) {
                           CHECK(check_direct(v, m, IsovalueSet::for_volume(v, 24)) == 0);
                       });
    // Against breadth-first search directly, and isovalues outside the data (one set empty: 0).
    Volume v = testutil::random_volume({17, 12, 19}, ValueType::uint8, 0, 9, 601);
    for (Connectivity m : modes) {
        const std::vector<double> at = {-3, 0, 0.5, 1, 4.2, 9, 10, 300};
        const std::vector<std::int64_t> direct = count_components_at(v, at, m);
        for (std::size_t j = 0; j < at.size(); ++j) CHECK(direct[j] == identity(v, at[j], m));
        CHECK(direct.front() == 0);
        CHECK(direct.back() == 0);
    }
    // Float data at float32 isovalues between stored values.
    Volume f = testutil::random_volume({9, 8, 10}, ValueType::float32, -20, 20, 602);
    for (Connectivity m : modes) CHECK(check_direct(f, m, IsovalueSet::floats({-7.25f, -0.5f, 0.f, 3.75f})) == 0);
    CHECK_THROWS_AS(count_components_at(v, {1.0, INFINITY}), InputError);
}

// The first k slices of v, as a volume of their own.
Volume first_slices(const Volume& v, std::size_t k) {
    const Dims d = v.dims();
    Volume out(Dims{d.nx, d.ny, k}, v.type());
    std::memcpy(out.data(), v.data(), out.size_bytes());
    return out;
}

// v pushed into a ComponentsAtStream `batch` slices at a time; after each push the counts must
// be count_components_at of the slices so far. Returns the mismatches.
int check_stream(const Volume& v, const std::vector<double>& at, Connectivity m, std::size_t batch) {
    const Dims d = v.dims();
    ComponentsAtStream stream(d.nx, d.ny, v.type(), at, m);
    CHECK(stream.counts() == std::vector<std::int64_t>(at.size(), 0));
    const std::size_t slice = d.nx * d.ny * value_size(v.type());
    int bad = 0;
    for (std::size_t z = 0; z < d.nz; z += batch) {
        const std::size_t n = std::min(batch, d.nz - z);
        stream.push_slices(static_cast<const char*>(v.data()) + z * slice, n);
        if (stream.slices() != z + n) ++bad;
        if (stream.counts() != count_components_at(first_slices(v, z + n), at, m) && bad++ < 5)
            MESSAGE(dims_string(d) << " " << value_type_name(v.type()) << " " << connectivity_name(m) << ": batch "
                                   << batch << ", after " << z + n << " slices the stream differs");
    }
    return bad;
}

TEST_CASE("the components stream: count_components_at of the slices so far, any batches, every type, both modes") {
    for_random_volumes({{1, 1, 1}, {9, 1, 1}, {1, 8, 4}, {2, 3, 7}, {7, 6, 5}, {13, 7, 11}, {70, 3, 5}, {97, 2, 3}},
                       {1, 3}, 900, [](const Volume& v, Connectivity m) {
                           const IsovalueSet iso = IsovalueSet::for_volume(v, 6);
                           std::vector<double> at = {-300, 1e6};  // one set empty: 0
                           for (std::size_t j = 0; j < iso.size(); ++j) at.push_back(iso.value(j));
                           for (std::size_t batch : {std::size_t(1), std::size_t(2), std::size_t(3), v.dims().nz})
                               CHECK(check_stream(v, at, m, batch) == 0);
                       });
    // Against breadth-first search directly, one slice at a time and all at once.
    const Volume v = testutil::random_volume({17, 12, 19}, ValueType::uint8, 0, 9, 901);
    const std::vector<double> at = {0.5, 1, 4.2, 9};
    for (Connectivity m : modes)
        for (std::size_t batch : {1, 19}) {
            ComponentsAtStream stream(17, 12, ValueType::uint8, at, m);
            for (std::size_t z = 0; z < 19; z += batch)
                stream.push_slices(v.as<std::uint8_t>() + z * 17 * 12, std::min<std::size_t>(batch, 19 - z));
            const std::vector<std::int64_t> c = stream.counts();
            for (std::size_t j = 0; j < at.size(); ++j) CHECK(c[j] == identity(v, at[j], m));
        }
    CHECK_THROWS_AS(ComponentsAtStream(4, 4, ValueType::uint8, {NAN}), InputError);
    CHECK_THROWS_AS(ComponentsAtStream(0, 4, ValueType::uint8, {1}), InputError);
    CHECK_THROWS_AS(ComponentsAtStream(std::size_t(1) << 15, std::size_t(1) << 15, ValueType::uint8, {1}), InputError);
    // nx * ny would wrap to 0 in 64 bits: still refused.
    CHECK_THROWS_AS(ComponentsAtStream(std::size_t(1) << 20, std::size_t(1) << 44, ValueType::uint8, {1}), InputError);
}

TEST_CASE("direct labelling at float isovalues beyond the type's range: 0, as the whole grid is A or C") {
    // 1e39 and -1e39 are finite doubles but +-Inf as float32: every value below, or none. The
    // float64 ones are the same for a double volume. Once such an isovalue threw inside the
    // parallel labelling and ended the process.
    const Volume f = testutil::random_volume({9, 7, 8}, ValueType::float32, 0, 2, 77);
    const Volume g = testutil::random_volume({9, 7, 8}, ValueType::float64, 0, 2, 78);
    for (const Volume* v : {&f, &g}) {
        CAPTURE(value_type_name(v->type()));
        const double big = v->type() == ValueType::float32 ? 1e39 : 1e308;
        const std::vector<double> at = {1.0, big, -big, 3.5e38};
        const std::int64_t want = identity(*v, 1.0, Connectivity::cube);
        REQUIRE(want > 0);
        const std::vector<std::int64_t> c = count_components_at(*v, at);
        CHECK(c == std::vector<std::int64_t>{want, 0, 0, v->type() == ValueType::float32 ? 0 : identity(*v, 3.5e38, Connectivity::cube)});
        ComponentsAtStream stream(9, 7, v->type(), at);
        stream.push_slices(v->data(), 3);
        stream.push_slices(static_cast<const unsigned char*>(v->data()) + 3 * 9 * 7 * value_size(v->type()), 5);
        CHECK(stream.counts() == c);
    }
}

TEST_CASE("direct labelling on structured shapes: nested shells, a torus, a checkerboard") {
    // Shells alternate in and out around the centre (each a component of A or of C); the
    // checkerboard makes every vertex its own 6-component of A while C is one 26-component.
    Volume shells({30, 27, 33}, ValueType::uint8), checker({16, 15, 14}, ValueType::uint8);
    for (std::size_t z = 0; z < 33; ++z)
        for (std::size_t y = 0; y < 27; ++y)
            for (std::size_t x = 0; x < 30; ++x) {
                const double r = std::sqrt(std::pow(x - 14.5, 2) + std::pow(y - 13.0, 2) + std::pow(z - 16.0, 2));
                shells.as<std::uint8_t>()[shells.index(x, y, z)] = std::uint8_t(int(r / 3) % 2 ? 200 : 10);
            }
    for (std::size_t i = 0; i < checker.vertices(); ++i) {
        const std::size_t x = i % 16, y = i / 16 % 15, z = i / (16 * 15);
        checker.as<std::uint8_t>()[i] = (x + y + z) % 2 ? 1 : 0;
    }
    const Volume torus = binary({40, 32, 12}, [](double x, double y, double z) {
        const double q = std::hypot(x - 20, y - 16) - 10;
        return q * q + (z - 6) * (z - 6) <= 9;
    });
    // Long runs: a slab of ones whose edges fall inside and at the ends of 32-vertex blocks.
    const Volume slab = binary({100, 5, 4}, [](double x, double y, double) { return x >= 31 + y && x < 64 + 2 * y; });
    for (const Volume* v : std::initializer_list<const Volume*>{&shells, &checker, &torus, &slab})
        for (Connectivity m : modes) {
            const std::vector<std::int64_t> direct = count_components_at(*v, {0.5, 1, 100}, m);
            for (std::size_t j = 0; j < 3; ++j) CHECK(direct[j] == identity(*v, std::vector<double>{0.5, 1, 100}[j], m));
        }
    CHECK(count_components_at(checker, {1}, Connectivity::cube)[0] == std::int64_t(checker.vertices() / 2));
}

// count_components_at at `at` on the device (Tuning::labelling forced, from the host volume and
// from a DeviceVolume) against the host labelling and, up to 20,000 vertices, breadth-first
// search; the number of mismatches.
int check_device_labelling(const Volume& v, const std::vector<double>& at, Connectivity m) {
    testutil::TuningGuard guard;
    testutil::ctx().tuning.labelling = LabellingPath::device;
    const std::vector<std::int64_t> host = count_components_at(v, at, m);
    const std::vector<std::int64_t> device = count_components_at(testutil::ctx(), v, at, m);
    const DeviceVolume dv(testutil::ctx(), v);
    const std::vector<std::int64_t> resident = count_components_at(dv, at, m);
    REQUIRE(device.size() == at.size());
    REQUIRE(resident.size() == at.size());
    int bad = 0;
    for (std::size_t j = 0; j < at.size(); ++j) {
        const std::int64_t bfs = v.vertices() <= 20000 ? identity(v, at[j], m) : host[j];
        if (device[j] != host[j] || resident[j] != host[j] || host[j] != bfs) {
            if (bad++ < 5)
                MESSAGE(dims_string(v.dims()) << " " << std::string(value_type_name(v.type())) << " "
                                              << std::string(connectivity_name(m)) << " s=" << at[j]
                                              << ": device " << device[j] << ", resident "
                                              << resident[j] << ", host " << host[j] << ", BFS " << bfs);
        }
    }
    return bad;
}

// The isovalues of for_volume(v, k) and four outside the data (below the type, below and above
// the values, far above).
std::vector<double> isovalues_in_and_out(const Volume& v, std::size_t k, long lo, long hi) {
    const IsovalueSet iso = IsovalueSet::for_volume(v, k);
    std::vector<double> at = {-1e12, double(lo) - 1, double(hi) + 1, 1e12};
    for (std::size_t j = 0; j < iso.size(); ++j) at.push_back(iso.value(j));
    return at;
}

TEST_CASE("device labelling at a few isovalues: the host labelling and BFS, every type, both modes, thin and long grids") {
    // Rows (ny * nz) that are no multiple of the work-group size, single rows, single planes,
    // long rows and long z: every kind of seam between the runs the work-items join.
    const std::vector<Dims> dims = {{1, 1, 1}, {1, 9, 7},  {9, 1, 7},   {9, 7, 1},  {1, 1, 40}, {40, 1, 1},
                                    {2, 3, 7}, {13, 7, 11}, {130, 2, 3}, {2, 3, 130}, {33, 17, 9}};
    std::uint32_t seed = 7100;
    for (const Dims& d : dims)
        for (ValueType t : types)
            for (Connectivity m : modes)
                for (long span : {3L, 30L}) {
                    const long lo = t == ValueType::int8 || t == ValueType::int16 ? -5 : 0;
                    const Volume v = testutil::random_volume(d, t, lo, lo + span, seed++);
                    CHECK(check_device_labelling(v, isovalues_in_and_out(v, 12, lo, lo + span), m) == 0);
                }
}

TEST_CASE("device labelling: one-valued volumes, extreme values, float isovalues beyond the type, structured shapes") {
    for (ValueType t : types)
        for (Connectivity m : modes) {
            // One value everywhere: A or C empty at every isovalue.
            const Volume flat = testutil::random_volume({11, 6, 5}, t, 5, 5, 1);
            // (Float data holds 2.5: random_volume halves its integers.)
            const std::vector<double> at = {2.5, 4, 5, 5.5, 6};
            CHECK(check_device_labelling(flat, at, m) == 0);
            testutil::TuningGuard guard;
            testutil::ctx().tuning.labelling = LabellingPath::device;
            CHECK(count_components_at(testutil::ctx(), flat, at, m) == std::vector<std::int64_t>(at.size(), 0));
        }
    // The ends of the wide types' ranges.
    const Volume i32 = testutil::random_volume({12, 9, 8}, ValueType::int32, -2147483648L, -2147483640L, 2);
    const Volume u32 = testutil::random_volume({12, 9, 8}, ValueType::uint32, 4294967287L, 4294967295L, 3);
    const Volume f64 = testutil::random_volume({12, 9, 8}, ValueType::float64, -1000000, -999990, 4);
    for (Connectivity m : modes) {
        CHECK(check_device_labelling(i32, {-2147483645.5, -2147483644, -2147483642.2, 3e9}, m) == 0);
        CHECK(check_device_labelling(u32, {4294967290.5, 4294967292, 4294967294.9, -1}, m) == 0);
        CHECK(check_device_labelling(f64, {-499997.25, -499996.5, -499995.0000001}, m) == 0);
    }
    // float32 isovalues that round to +-Inf, and the largest finite one.
    const Volume f = testutil::random_volume({9, 7, 8}, ValueType::float32, 0, 2, 77);
    for (Connectivity m : modes) CHECK(check_device_labelling(f, {1.0, 1e39, -1e39, 3.5e38, 0.5}, m) == 0);
    // A checkerboard (every vertex of A its own 6-component: the most unions) and shells.
    Volume checker({20, 19, 18}, ValueType::uint8), shells({30, 27, 33}, ValueType::uint8);
    for (std::size_t i = 0; i < checker.vertices(); ++i)
        checker.as<std::uint8_t>()[i] = (i % 20 + i / 20 % 19 + i / (20 * 19)) % 2 ? 1 : 0;
    for (std::size_t i = 0; i < shells.vertices(); ++i) {
        const double x = double(i % 30), y = double(i / 30 % 27), z = double(i / (30 * 27));
        const double r = std::sqrt(std::pow(x - 14.5, 2) + std::pow(y - 13.0, 2) + std::pow(z - 16.0, 2));
        shells.as<std::uint8_t>()[i] = std::uint8_t(int(r / 3) % 2 ? 200 : 10);
    }
    for (Connectivity m : modes) {
        CHECK(check_device_labelling(checker, {0.5, 1}, m) == 0);
        CHECK(check_device_labelling(shells, {10, 11, 200, 201}, m) == 0);
    }
    CHECK_THROWS_AS(count_components_at(testutil::ctx(), i32, {1.0, NAN}), InputError);
}

TEST_CASE("device labelling on noisy spheres: the host labelling at five isovalues, both modes") {
    // Many work-items joining the same components at once: the unions' races.
    for (std::size_t n : {48, 71})
        for (double noise : {5.0, 40.0}) {
            SyntheticOptions o;
            o.size = n;
            o.noise = noise;
            const Volume v = make_synthetic("noisy-sphere", o);
            for (Connectivity m : modes) {
                CAPTURE(n);
                CAPTURE(noise);
                CHECK(check_device_labelling(v, {40, 90, 128, 160, 220}, m) == 0);
            }
        }
}

TEST_CASE("the labelling path: host on CPU devices, device elsewhere; the device path uploads the volume once") {
    CHECK(testutil::ctx().tuning.labelling == (testutil::ctx().is_cpu() ? LabellingPath::host : LabellingPath::device));
    CHECK(parse_variant<LabellingPath>("device") == LabellingPath::device);
    CHECK(std::string(variant_name(LabellingPath::host)) == "host");
    testutil::TuningGuard guard;
    const Volume v = testutil::random_volume({10, 9, 8}, ValueType::uint16, 0, 9, 5);
    for (LabellingPath path : {LabellingPath::host, LabellingPath::device}) {
        testutil::ctx().tuning.labelling = path;
        const std::uint64_t before = testutil::ctx().uploads();
        CHECK(count_components_at(testutil::ctx(), v, 4.5) == identity(v, 4.5, Connectivity::cube));
        CHECK(testutil::ctx().uploads() - before == (path == LabellingPath::device ? 1u : 0u));
    }
}

TEST_CASE("the device histogram: local and global variants give the same curve") {
    Volume a = testutil::random_volume({17, 13, 11}, ValueType::uint8, 0, 255, 11);
    Volume b = testutil::random_volume({17, 13, 11}, ValueType::uint16, 0, 60000, 12);
    Volume s = testutil::random_volume({16, 3, 9}, ValueType::int16, -300, 300, 13);
    testutil::TuningGuard guard;
    for (std::size_t local_bytes : {std::size_t(0), std::size_t(1) << 20})
    for (Volume* v : {&a, &b, &s}) {
        testutil::ctx().tuning.local_hist_bytes = local_bytes;  // 0: global atomics only
        CAPTURE(local_bytes);
        CAPTURE(value_type_name(v->type()));
        ComponentCurve c = count_components(testutil::ctx(), *v, IsovalueSet::for_volume(*v));
        std::int64_t total = 0;
        for (std::size_t j = 0; j < c.components.size(); j += std::max<std::size_t>(1, c.components.size() / 40)) {
            CHECK(c.components[j] == identity(*v, c.isovalues.value(j), Connectivity::cube));
            total += c.components[j];
        }
        CHECK(total > 0);
    }
}

TEST_CASE("value histogram and neighbour masks on the host (volume above the device slab limit): same curves") {
    testutil::TuningGuard guard;
    for (ValueType t : types)
        for (Connectivity m : modes) {
            Volume v = testutil::random_volume({9, 7, 6}, t, 0, 9, 1200 + int(t));
            const IsovalueSet iso = IsovalueSet::for_volume(v, 32);
            testutil::ctx().tuning.slab_bytes = 0;
            const ComponentCurve device = count_components(testutil::ctx(), v, iso, m);
            testutil::ctx().tuning.slab_bytes = 64;  // smaller than any of these volumes
            const ComponentCurve host = count_components(testutil::ctx(), v, iso, m);
            CHECK(device.components == host.components);
            CHECK(check_curve(v, m, iso) == 0);
        }
}

TEST_CASE("windowed sweeps (the order built a window at a time): the whole-order curves, every window size") {
    testutil::TuningGuard guard;
    // Wide and narrow ranges, a plateau value over many windows (the value split over segments).
    Volume wide = testutil::random_volume({23, 19, 17}, ValueType::uint16, 0, 60000, 31);
    Volume narrow = testutil::random_volume({31, 7, 29}, ValueType::uint8, 0, 5, 32);
    Volume signed16 = testutil::random_volume({13, 17, 19}, ValueType::int16, -300, 300, 33);
    Volume plateau = testutil::random_volume({40, 30, 20}, ValueType::int8, -3, 3, 34);
    for (std::size_t i = 0; i < plateau.vertices(); i += 3) plateau.as<std::int8_t>()[i] = 0;
    Volume small_plateau = testutil::random_volume({13, 11, 9}, ValueType::int8, -3, 3, 38);
    for (std::size_t i = 0; i < small_plateau.vertices(); i += 3) small_plateau.as<std::int8_t>()[i] = 0;
    // Rows of more than 64 vertices (the scan takes 64 at a time) and 32-bit values far from 0.
    Volume rows = testutil::random_volume({150, 5, 7}, ValueType::uint16, 100, 2100, 35);
    Volume far = testutil::random_volume({67, 6, 5}, ValueType::int32, 1000000000, 1000000150, 36);
    Volume negative = testutil::random_volume({71, 5, 6}, ValueType::int32, -1000000150, -1000000000, 37);
    for (Volume* v : {&wide, &narrow, &signed16, &plateau, &small_plateau, &rows, &far, &negative})
        for (Connectivity m : modes) {
            CAPTURE(value_type_name(v->type()));
            CAPTURE(connectivity_name(m));
            const IsovalueSet iso = IsovalueSet::for_volume(*v, 64);
            testutil::ctx().tuning.component_window = 0;
            const ComponentCurve whole = count_components(testutil::ctx(), *v, iso, m);
            // Both sweeps at once (two forests) and one after the other (one forest).
            for (bool together : {true, false})
                for (std::size_t window : {std::size_t(1), std::size_t(97), std::size_t(5000), std::size_t(1) << 24}) {
                    CAPTURE(together);
                    CAPTURE(window);
                    testutil::ctx().tuning.component_window = window;
                    testutil::ctx().tuning.component_sweeps_together = together;
                    CHECK(count_components(testutil::ctx(), *v, iso, m).components == whole.components);
                }
            // The whole-order curve against the labelling at 128 of its isovalues (the wide
            // uint16 grid has 60,000).
            CHECK(check_curve(*v, m, iso, 128) == 0);
        }
}

// The slabs [b_r, b_{r+1}] of v (consecutive slabs share slice b_{r+1}), counted and joined.
std::vector<std::int64_t> joined_slabs(const Volume& v, const std::vector<std::size_t>& starts, const IsovalueSet& iso,
                                       Connectivity mode) {
    const Dims d = v.dims();
    const std::size_t slice = d.nx * d.ny * value_size(v.type());
    std::vector<SlabLinks> links;
    std::vector<std::int64_t> sum(iso.size(), 0);
    for (std::size_t r = 0; r < starts.size(); ++r) {
        const std::size_t z0 = starts[r], z1 = r + 1 < starts.size() ? starts[r + 1] + 1 : d.nz;
        Volume slab(Dims{d.nx, d.ny, z1 - z0}, v.type());
        std::memcpy(slab.data(), static_cast<const char*>(v.data()) + z0 * slice, (z1 - z0) * slice);
        SlabComponents s = count_slab_components(testutil::ctx(), slab, iso, mode, r > 0, r + 1 < starts.size());
        for (std::size_t j = 0; j < iso.size(); ++j) sum[j] += s.components[j];
        links.push_back(std::move(s.links));
    }
    return join_slab_components(sum, links, d.nx * d.ny);
}

TEST_CASE("slabs sharing a slice, joined: the whole-volume curve (cuts anywhere, both modes, windowed or not)") {
    testutil::TuningGuard guard;
    Volume narrow = testutil::random_volume({9, 7, 12}, ValueType::uint8, 0, 4, 41);
    Volume wide = testutil::random_volume({6, 11, 10}, ValueType::uint16, 0, 60000, 42);
    Volume floats = testutil::random_volume({8, 5, 9}, ValueType::float32, -20, 20, 43);
    Volume plateau = testutil::random_volume({10, 10, 8}, ValueType::int16, -2, 2, 44);
    for (Volume* v : {&narrow, &wide, &floats, &plateau})
        for (Connectivity m : modes)
            for (std::size_t window : {std::size_t(0), std::size_t(37), std::size_t(38)})
            for (std::size_t sub : {std::size_t(0), std::size_t(1)}) {
                if (sub && window) continue;
                CAPTURE(value_type_name(v->type()));
                CAPTURE(connectivity_name(m));
                CAPTURE(window);
                CAPTURE(sub);
                // Window 38: the windowed sweeps one after the other (37: at once).
                testutil::ctx().tuning.component_window = window;
                testutil::ctx().tuning.component_sweeps_together = window != 38;
                const IsovalueSet iso = IsovalueSet::for_volume(*v, 50);
                testutil::ctx().tuning.component_slab_slices = std::numeric_limits<std::size_t>::max();
                const std::vector<std::int64_t> whole = count_components(testutil::ctx(), *v, iso, m).components;
                // The parts themselves in z-slabs of two slices (0: parts in one piece).
                if (sub) testutil::ctx().tuning.component_slab_slices = sub;
                const std::size_t nz = v->dims().nz;
                CHECK(joined_slabs(*v, {0}, iso, m) == whole);
                // Single cuts, slabs of two slices, and uneven cuts.
                for (std::size_t b : {std::size_t(1), nz / 2, nz - 2}) CHECK(joined_slabs(*v, {0, b}, iso, m) == whole);
                std::vector<std::size_t> pairs;
                for (std::size_t b = 0; b + 1 < nz; ++b) pairs.push_back(b);
                CHECK(joined_slabs(*v, pairs, iso, m) == whole);
                CHECK(joined_slabs(*v, {0, 1, nz / 2, nz - 2}, iso, m) == whole);
            }
    // Isovalues outside the data (every vertex in A, or in C) and a single isovalue.
    const IsovalueSet outside = IsovalueSet::integers(-3, 8);
    CHECK(joined_slabs(narrow, {0, 3, 7}, outside, Connectivity::cube) ==
          count_components(testutil::ctx(), narrow, outside, Connectivity::cube).components);
}

// The curve with every component_slab_slices of `steps` (and 1 and 3 threads) against the
// curve in one piece; returns the number of differing curves.
int sliced_against_whole(const Volume& v, const IsovalueSet& iso, Connectivity m, const std::vector<std::size_t>& steps) {
    testutil::TuningGuard guard;
    Tuning& t = testutil::ctx().tuning;
    t.component_slab_slices = std::numeric_limits<std::size_t>::max();
    const std::vector<std::int64_t> whole = count_components(testutil::ctx(), v, iso, m).components;
    REQUIRE(whole.size() == iso.size());
    const int threads = omp_get_max_threads();
    int bad = 0;
    for (int n : {1, 3})
        for (std::size_t step : steps) {
            t.component_slab_slices = step;
            omp_set_num_threads(n);
            const std::vector<std::int64_t> sliced = count_components(testutil::ctx(), v, iso, m).components;
            omp_set_num_threads(threads);
            if (sliced != whole) {
                if (bad < 3)
                    MESSAGE(dims_string(v.dims()) << " " << value_type_name(v.type()) << " " << connectivity_name(m)
                                                  << ": slabs " << step << " slices apart on " << n
                                                  << " threads differ from the curve in one piece");
                ++bad;
            }
        }
    return bad;
}

TEST_CASE("z-slabs counted on every core and joined: the curve in one piece at every isovalue, every type, both modes") {
    // Thin grids (one piece: fewer than 3 slices), slabs 1, 2, 3 slices apart and uneven last
    // slabs (4 and 5 apart), more slabs than the runs of 1 and 3 threads, rows past 64.
    const Dims dims[] = {{5, 4, 1}, {6, 5, 2}, {4, 7, 3}, {9, 7, 11}, {6, 5, 23}, {70, 3, 9}};
    const std::vector<std::size_t> steps{1, 2, 3, 4, 5};
    std::uint32_t seed = 600;
    for (const Dims& d : dims)
        for (ValueType t : types)
            for (Connectivity m : modes) {
                CAPTURE(dims_string(d));
                CAPTURE(value_type_name(t));
                CAPTURE(connectivity_name(m));
                const double lo = t == ValueType::uint8 || t == ValueType::uint16 || t == ValueType::uint32 ? 0 : -50;
                // Few levels (plateaus across the seams) and many.
                for (double span : {3.0, 200.0}) {
                    const Volume v = testutil::random_volume(d, t, long(lo), long(lo + span), seed++);
                    CHECK(sliced_against_whole(v, IsovalueSet::for_volume(v, 64), m, steps) == 0);
                }
                // Isovalue sets given as lists, and integers partly outside the data.
                const Volume v = testutil::random_volume(d, t, long(lo), long(lo + 40), seed++);
                IsovalueSet iso;
                if (t == ValueType::float32) iso = IsovalueSet::floats({float(lo - 1), float(lo + 0.5), float(lo + 7), float(lo + 20.25), float(lo + 39), float(lo + 41)});
                else if (t == ValueType::float64 || t == ValueType::int32 || t == ValueType::uint32)
                    iso = IsovalueSet::doubles({lo - 1, lo + 0.5, lo + 7, lo + 20.25, lo + 39, lo + 41});
                else iso = IsovalueSet::integers(long(lo) - 3, long(lo) + 25);
                CHECK(sliced_against_whole(v, iso, m, steps) == 0);
            }
}

TEST_CASE("z-slabs: against labelling, the default slab depth, the windowed sweeps, a device volume") {
    testutil::TuningGuard guard;
    Tuning& t = testutil::ctx().tuning;
    for (Connectivity m : modes) {
        CAPTURE(connectivity_name(m));
        // Against BFS labelling of A and C at every isovalue, slabs of two slices.
        const Volume a = testutil::random_volume({8, 6, 9}, ValueType::int16, -5, 5, 701);
        t.component_slab_slices = 1;
        CHECK(check_curve(a, m) == 0);
        t.component_slab_slices = 0;
        // Windowed sweeps inside the slabs, at once and one after the other.
        const Volume w = testutil::random_volume({23, 19, 17}, ValueType::uint16, 0, 60000, 702);
        for (bool together : {true, false}) {
            CAPTURE(together);
            t.component_window = 97;
            t.component_sweeps_together = together;
            CHECK(sliced_against_whole(w, IsovalueSet::for_volume(w, 64), m, {2, 7}) == 0);
        }
        t.component_window = 0;
        t.component_sweeps_together = true;
    }
    // The default depth (no tuning): a volume beyond two slabs of 2^22 vertices is cut (here
    // 163 slices apart, the last slab of 4).
    const Volume big = testutil::random_volume({160, 160, 330}, ValueType::uint8, 0, 30, 703);
    const IsovalueSet iso = IsovalueSet::for_volume(big);
    const ComponentCurve sliced = count_components(testutil::ctx(), big, iso, Connectivity::cube);
    t.component_slab_slices = std::numeric_limits<std::size_t>::max();
    const ComponentCurve whole = count_components(testutil::ctx(), big, iso, Connectivity::cube);
    CHECK(sliced.components == whole.components);
    // A volume on the device, downloaded and cut.
    t.component_slab_slices = 3;
    const Volume small = testutil::random_volume({9, 8, 13}, ValueType::uint8, 0, 9, 704);
    const DeviceVolume dv(testutil::ctx(), small);
    const IsovalueSet iso_small = IsovalueSet::for_volume(small);
    t.component_slab_slices = std::numeric_limits<std::size_t>::max();
    const std::vector<std::int64_t> one = count_components(testutil::ctx(), small, iso_small).components;
    t.component_slab_slices = 3;
    CHECK(count_components(dv, iso_small).components == one);
}

TEST_CASE("parse_connectivity") {
    CHECK(parse_connectivity("cube") == Connectivity::cube);
    CHECK(parse_connectivity("freudenthal") == Connectivity::freudenthal);
    CHECK_THROWS_AS(parse_connectivity("six"), InputError);
}

TEST_CASE("Pearson correlation against a plain two-pass computation") {
    auto two_pass = [](const std::vector<double>& x, const std::vector<double>& y) {
        double mx = 0, my = 0;
        for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
        mx /= double(x.size());
        my /= double(y.size());
        double sxy = 0, sxx = 0, syy = 0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            sxy += (x[i] - mx) * (y[i] - my);
            sxx += (x[i] - mx) * (x[i] - mx);
            syy += (y[i] - my) * (y[i] - my);
        }
        return sxy / std::sqrt(sxx * syy);
    };
    std::mt19937 rng(5);
    std::normal_distribution<double> g(0, 1);
    const double tol = testutil::ctx().has_fp64() ? 1e-12 : 1e-5;
    for (std::size_t n : {2, 3, 17, 256, 1000}) {
        std::vector<double> x(n), y(n);
        for (std::size_t i = 0; i < n; ++i) {
            x[i] = 2.2 + 0.1 * g(rng);
            y[i] = 1000 * x[i] + 50 * g(rng) + 1e4;
        }
        CHECK(std::abs(pearson(testutil::ctx(), x, y) - two_pass(x, y)) < tol);
    }
    CHECK(std::abs(pearson(testutil::ctx(), {1, 2, 3}, {3, 2, 1}) + 1) < tol);
    CHECK(std::isnan(pearson(testutil::ctx(), {1}, {2})));
    CHECK(std::isnan(pearson(testutil::ctx(), {1, 1, 1}, {1, 2, 3})));

    // correlate_components: only isovalues with D defined and E >= (two smallest dims) / 4.
    const Dims d{8, 40, 10};  // threshold 8 * 10 / 4 = 20 edges
    std::vector<double> fd{2.1, NAN, 2.3, 2.5, 2.2, 2.4};
    std::vector<std::uint64_t> e{100, 100, 19, 20, 40, 80};
    std::vector<std::int64_t> c{3, 9, 9, 7, 2, 12};
    ComponentCorrelation r = correlate_components(testutil::ctx(), fd, e, c, d);
    CHECK(r.used == 4);
    CHECK(std::abs(r.components - two_pass({2.1, 2.5, 2.2, 2.4}, {3, 7, 2, 12})) < tol);
    CHECK(std::abs(r.components_per_area - two_pass({2.1, 2.5, 2.2, 2.4}, {0.03, 0.35, 0.05, 0.15})) < tol);
}

}  // TEST_SUITE("components")

TEST_SUITE("realdata") {

TEST_CASE("components: sweep equals the labelling identity at every isovalue on small real volumes") {
    const std::string dir = testutil::shared_data_or_skip("real-volume component checks");
    if (dir.empty()) return;
    // The small volumes, fully (BFS per isovalue is the expensive side); the large ones
    // are checked by `clfractal components --verify` (docs/guide/components.md).
    for (const char* name : {"bucky_32x32x32_uint8.raw", "m4_totaldensity_31x22x25_float32.raw",
                             "nucleon_41x41x41_uint8.raw", "fuel_cropped_64x33x32_uint8.raw",
                             "hydrogen_3d_orbital_64x64x64_float32.raw", "neghip_slc_66x66x66_uint8.raw"}) {
        Volume v = read_volume(dir + "/" + name);
        for (Connectivity m : modes) {
            CAPTURE(name);
            CAPTURE(connectivity_name(m));
            IsovalueSet iso = IsovalueSet::for_volume(v);
            ComponentCurve c = count_components(testutil::ctx(), v, iso, m);
            int bad = 0;
            for (std::size_t j = 0; j < iso.size(); ++j)
                bad += c.components[j] != count_components_by_labelling(v, iso.value(j), m);
            CHECK(bad == 0);
        }
    }
}

}  // TEST_SUITE("realdata")

TEST_SUITE("realdata") {

TEST_CASE("direct labelling equals the curve at eight isovalues of every real volume, both modes") {
    const auto volumes = testutil::real_volumes("direct labelling on real volumes");
    for (const testutil::RealVolume& real : volumes) {
        const Volume v = read_volume(real.path);
        const IsovalueSet iso = IsovalueSet::for_volume(v);
        std::vector<double> at;
        for (std::size_t q = 1; q <= 8; ++q) at.push_back(iso.value(q * (iso.size() - 1) / 9));
        for (Connectivity m : modes) {
            CAPTURE(real.file());
            CAPTURE(connectivity_name(m));
            const ComponentCurve c = count_components(testutil::ctx(), v, iso, m);
            const std::vector<std::int64_t> direct = count_components_at(v, at, m);
            for (std::size_t q = 1; q <= 8; ++q) CHECK(direct[q - 1] == c.components[q * (iso.size() - 1) / 9]);
            // Streamed 7 slices at a time: the same counts.
            ComponentsAtStream stream(v.dims().nx, v.dims().ny, v.type(), at, m);
            const std::size_t slice = v.dims().nx * v.dims().ny * value_size(v.type());
            for (std::size_t z = 0; z < v.dims().nz; z += 7)
                stream.push_slices(static_cast<const char*>(v.data()) + z * slice, std::min<std::size_t>(7, v.dims().nz - z));
            CHECK(stream.counts() == direct);
        }
    }
}

}  // TEST_SUITE("realdata")
