// Slab-wise extraction and vertex clustering (docs/definitions.md §37) against a plain
// reference: the whole mesh clustered by a std::map of cells, in the definition's words.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/mesh_cluster.hpp"
#include "clfractal/synthetic.hpp"
#include "test_util.hpp"

using namespace clfractal;

namespace {

// Clustering of the whole mesh as the definition states it, with cells of edge `cell` whose
// indices are divided (floor) by `factor`.
Mesh reference_clusters(const Mesh& m, double cell, std::int64_t factor = 1) {
    const auto down = [&](std::int64_t i) { return i >= 0 ? i / factor : -((-i + factor - 1) / factor); };
    std::map<std::array<std::int64_t, 3>, std::uint32_t> id;
    std::vector<std::array<double, 3>> sum;
    std::vector<double> ld_sum;
    std::vector<std::uint32_t> n, ld_n, of(m.positions.size());
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        std::array<std::int64_t, 3> key;
        for (int k = 0; k < 3; ++k) key[k] = down(std::int64_t(std::floor(m.positions[i][k] / cell)));
        auto it = id.find(key);
        if (it == id.end()) {
            it = id.emplace(key, std::uint32_t(n.size())).first;
            sum.push_back({0, 0, 0}), ld_sum.push_back(0), n.push_back(0), ld_n.push_back(0);
        }
        of[i] = it->second;
        for (int k = 0; k < 3; ++k) sum[of[i]][k] += m.positions[i][k];
        ++n[of[i]];
        if (!m.ld.empty() && !std::isnan(m.ld[i])) ld_sum[of[i]] += m.ld[i], ++ld_n[of[i]];
    }
    Mesh r;
    for (std::size_t j = 0; j < n.size(); ++j) {
        r.positions.push_back({float(sum[j][0] / n[j]), float(sum[j][1] / n[j]), float(sum[j][2] / n[j])});
        r.ld.push_back(ld_n[j] ? float(ld_sum[j] / ld_n[j]) : NAN);
    }
    std::set<std::array<std::uint32_t, 3>> seen;
    for (const auto& t : m.triangles) {
        const std::array<std::uint32_t, 3> u{of[t[0]], of[t[1]], of[t[2]]};
        if (u[0] == u[1] || u[1] == u[2] || u[0] == u[2]) continue;
        auto s = u;
        std::sort(s.begin(), s.end());
        if (seen.insert(s).second) r.triangles.push_back(u);
    }
    return r;
}

bool same_float(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

void check_same(const Mesh& got, const Mesh& want) {
    REQUIRE(got.positions.size() == want.positions.size());
    REQUIRE(got.triangles.size() == want.triangles.size());
    std::size_t bad = 0;
    for (std::size_t j = 0; j < want.positions.size(); ++j)
        for (int k = 0; k < 3; ++k) bad += got.positions[j][k] != want.positions[j][k];
    for (std::size_t j = 0; j < want.ld.size(); ++j) bad += !same_float(got.ld[j], want.ld[j]);
    CHECK(bad == 0);
    CHECK(got.triangles == want.triangles);
    REQUIRE(got.colors.size() == got.ld.size());
    for (std::size_t j = 0; j < got.ld.size(); ++j) {
        const Rgb c = ld_colour(got.ld[j]);
        if (got.colors[j] != std::array<std::uint8_t, 3>{c.r, c.g, c.b}) ++bad;
    }
    CHECK(bad == 0);
}

Volume noisy_sphere(std::size_t n, double noise, std::uint32_t seed) {
    Volume v({n, n + 3, n - 2}, ValueType::uint8);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-noise, noise);
    auto* p = v.as<std::uint8_t>();
    const double c = (n - 1) / 2.0;
    for (std::size_t z = 0; z < v.dims().nz; ++z)
        for (std::size_t y = 0; y < v.dims().ny; ++y)
            for (std::size_t x = 0; x < v.dims().nx; ++x) {
                const double r = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                p[v.index(x, y, z)] = std::uint8_t(std::clamp(std::lround(255 * std::exp(-r * r / (0.1 * n * n)) + u(rng)), 0L, 255L));
            }
    return v;
}

}  // namespace

TEST_SUITE("mesh") {

TEST_CASE("mesh: slabs of cube layers give the whole mesh, vertex by vertex and triangle by triangle") {
    const Volume v = noisy_sphere(21, 30, 5);
    for (MeshMethod m : {MeshMethod::marching_cubes, MeshMethod::marching_tetrahedra})
        for (std::size_t layers : {1, 2, 5, 100}) {
            CAPTURE(layers);
            const Mesh whole = extract_isosurface(v, 128, m);
            std::vector<std::array<float, 3>> corners, want;
            for (const auto& t : whole.triangles)
                for (auto i : t) want.push_back(whole.positions[i]);
            for (std::size_t z0 = 0; z0 < v.dims().nz; z0 += layers) {
                const Mesh part = extract_isosurface_layers(v, 128, z0, z0 + layers, m);
                for (const auto& t : part.triangles)
                    for (auto i : t) corners.push_back(part.positions[i]);
            }
            REQUIRE(!want.empty());
            CHECK(corners == want);
        }
    CHECK(extract_isosurface_layers(v, 128, 5, 5).triangles.empty());
    CHECK(extract_isosurface_layers(v, 128, v.dims().nz - 1, v.dims().nz + 4).triangles.empty());
    CHECK_THROWS_AS(extract_isosurface_layers(v, NAN, 0, 3), InputError);
}

TEST_CASE("mesh: clusters built slab by slab equal the reference clustering of the whole mesh") {
    Context& ctx = testutil::ctx();
    const Volume v = noisy_sphere(26, 40, 9);
    const Volume ld = local_fractal_dimension(ctx, v, 120, 4);
    Mesh whole = extract_isosurface(v, 120);
    color_by_ld(whole, ld);
    for (double cell : {0.3, 1.0, 2.5, 7.0})
        for (std::size_t layers : {1, 3, 0}) {
            CAPTURE(cell);
            CAPTURE(layers);
            const MeshClusters c = cluster_isosurface(v, 120, cell, &ld, MeshMethod::marching_cubes, layers);
            CHECK(c.input_triangles() == whole.triangles.size());
            check_same(c.mesh(), reference_clusters(whole, cell));
            for (std::uint32_t f : {1u, 2u, 3u, 5u}) {
                CAPTURE(f);
                check_same(c.coarsened(f).mesh(), reference_clusters(whole, cell, f));
            }
        }
    // Without an LD field every cluster's LD is undefined.
    const Mesh plain = cluster_isosurface(v, 120, 2.0).mesh();
    REQUIRE(!plain.ld.empty());
    CHECK(std::all_of(plain.ld.begin(), plain.ld.end(), [](float x) { return std::isnan(x); }));
    CHECK_THROWS_AS(MeshClusters(0.0), InputError);
    CHECK_THROWS_AS(cluster_isosurface(v, INFINITY, 1.0), InputError);
}

TEST_CASE("mesh: bounded_mesh takes the smallest factor within the budget") {
    const Volume v = noisy_sphere(30, 60, 2);
    const MeshClusters c = cluster_isosurface(v, 100, 0.5);
    REQUIRE(c.triangles() > 200);
    std::uint32_t f = 0;
    const Mesh same = bounded_mesh(c, c.triangles(), &f);
    CHECK(f == 1);
    CHECK(same.triangles.size() == c.triangles());
    for (std::size_t budget : {c.triangles() / 2, c.triangles() / 10, std::size_t(50)}) {
        CAPTURE(budget);
        const Mesh b = bounded_mesh(c, budget, &f);
        CHECK(b.triangles.size() <= budget);
        CHECK(f >= 2);
        CHECK(c.coarsened(f - 1).triangles() > budget);
        CHECK(b.triangles == c.coarsened(f).mesh().triangles);
    }
    CHECK_THROWS_AS(bounded_mesh(c, 0), std::invalid_argument);
}

}  // TEST_SUITE
