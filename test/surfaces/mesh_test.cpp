// Isosurface meshes: vertex counts against E(s), closed consistently oriented surfaces, Euler
// characteristics, pieces against the components identity of docs/definitions.md §19 (BFS in
// test/reference), PLY round trips, and preview images.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/ply.hpp"
#include "clfractal/render.hpp"
#include "clfractal/span.hpp"
#include "clfractal/synthetic.hpp"
#include "reference/mesh_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using ref::Adjacency;
using testutil::ctx;

namespace {

const MeshMethod methods[] = {MeshMethod::marching_cubes, MeshMethod::marching_tetrahedra};

std::string method_name(MeshMethod m) { return m == MeshMethod::marching_cubes ? "mc" : "mt"; }

// The connectivity each method's surface follows: (negative set, positive set).
std::pair<Adjacency, Adjacency> connectivity(MeshMethod m) {
    return m == MeshMethod::marching_cubes ? std::pair{Adjacency::six, Adjacency::twenty_six}
                                           : std::pair{Adjacency::fourteen, Adjacency::fourteen};
}

// b0(A) + b0(C) - 1 when both sets are non-empty (docs/definitions.md §19).
std::size_t expected_pieces(const Volume& v, double s, MeshMethod m) {
    const auto [neg, pos] = connectivity(m);
    const std::size_t a = ref::components(v, s, false, neg), c = ref::components(v, s, true, pos);
    return a && c ? a + c - 1 : 0;
}

// A float volume from a function of the vertex coordinates.
template <class F> Volume field_volume(Dims d, F f) {
    Volume v(d, ValueType::float32);
    float* p = v.as<float>();
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) p[v.index(x, y, z)] = float(f(double(x), double(y), double(z)));
    return v;
}

// Sets every border vertex to `value`, so that a surface below it stays inside the box.
void set_border(Volume& v, double value) {
    const auto d = v.dims();
    visit(v, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t z = 0; z < d.nz; ++z)
            for (std::size_t y = 0; y < d.ny; ++y)
                for (std::size_t x = 0; x < d.nx; ++x)
                    if (x == 0 || y == 0 || z == 0 || x + 1 == d.nx || y + 1 == d.ny || z + 1 == d.nz)
                        p[v.index(x, y, z)] = T(value);
    });
}

// A closed surface whose pieces match the components identity.
void check_closed(const Volume& v, double s, MeshMethod m) {
    CAPTURE(method_name(m));
    CAPTURE(s);
    const Mesh mesh = extract_isosurface(v, s, m);
    const ref::MeshTopology t = ref::topology(mesh);
    CHECK(t.closed_manifold());
    CHECK(t.pieces == expected_pieces(v, s, m));
    // Each piece is a closed orientable surface: Euler characteristic 2 - 2 genus.
    CHECK(t.euler % 2 == 0);
    CHECK(t.euler <= long(2 * t.pieces));
}

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("clfractal_mesh_test_" + name)).string();
}

}  // namespace

TEST_SUITE("mesh") {

TEST_CASE("one vertex per intersected grid edge: the count is E(s) from count_spans") {
    const testutil::Case cases[] = {
        {{2, 2, 2}, ValueType::uint8, 0, 5},      {{9, 8, 7}, ValueType::uint8, 0, 20},
        {{5, 11, 3}, ValueType::uint16, 990, 1020}, {{7, 6, 9}, ValueType::int16, -15, 15},
        {{8, 9, 6}, ValueType::float32, -20, 20}, {{13, 2, 5}, ValueType::int16, -3, 3},
        {{6, 7, 5}, ValueType::int8, -128, -100}, {{7, 5, 6}, ValueType::int32, 2147483620, 2147483647},
        {{5, 6, 7}, ValueType::uint32, 4294967270, 4294967295}, {{8, 6, 7}, ValueType::float64, -20, 20},
    };
    std::uint32_t seed = 3;
    for (const testutil::Case& c : cases) {
        Volume v = testutil::random_volume(c.d, c.t, c.lo, c.hi, seed++);
        v.spacing = {0.5, 2.0, 1.25};
        CAPTURE(value_type_name(c.t));
        CAPTURE(dims_string(c.d));
        // Integer data: every integer of the range. Float data (multiples of 1/2): every
        // multiple of 1/4 in the range, so half of the isovalues equal vertex values.
        IsovalueSet iso = IsovalueSet::for_volume(v);
        if (!iso.integer()) {
            std::vector<double> s;
            for (long k = 2 * c.lo; k <= 2 * c.hi + 1; ++k) s.push_back(double(k) / 4);
            iso = c.t == ValueType::float64 ? IsovalueSet::doubles(s)
                                            : IsovalueSet::floats(std::vector<float>(s.begin(), s.end()));
        }
        const auto edges = count_spans(ctx(), v, iso, SpanOptions{{SpanKind::edges}, 1, 0}).get(SpanKind::edges).counts[0];
        const auto freudenthal = ref::freudenthal_edges_brute(v, iso);
        for (std::size_t j = 0; j < iso.size(); ++j) {
            const double s = iso.value(j);
            CAPTURE(s);
            for (MeshMethod m : methods) {
                CAPTURE(method_name(m));
                const Mesh mesh = extract_isosurface(v, s, m);
                CHECK(mesh.positions.size() == (m == MeshMethod::marching_cubes ? edges[j] : freudenthal[j]));
                // Every vertex sits on its own intersected edge at the interpolation point.
                std::set<std::pair<std::uint64_t, std::uint64_t>> distinct;
                bool on_edge = true;
                for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
                    const EdgePoint& e = mesh.edge_points[i];
                    distinct.insert({e.u, e.w});
                    const double fu = v.value(e.u), fw = v.value(e.w);
                    on_edge = on_edge && e.u < e.w && std::min(fu, fw) < s && s <= std::max(fu, fw) &&
                              std::abs(double(e.t) - (s - fu) / (fw - fu)) < 1e-6;
                    const std::size_t ux = e.u % c.d.nx, uy = e.u / c.d.nx % c.d.ny, uz = e.u / (c.d.nx * c.d.ny);
                    const std::size_t wx = e.w % c.d.nx, wy = e.w / c.d.nx % c.d.ny, wz = e.w / (c.d.nx * c.d.ny);
                    const std::size_t step = (wx - ux) + (wy - uy) + (wz - uz);
                    on_edge = on_edge && wx - ux <= 1 && wy - uy <= 1 && wz - uz <= 1 &&
                              (m == MeshMethod::marching_tetrahedra || step == 1);
                    const double expect[3] = {(ux + e.t * double(wx - ux)) * 0.5, (uy + e.t * double(wy - uy)) * 2.0,
                                              (uz + e.t * double(wz - uz)) * 1.25};
                    for (int a = 0; a < 3; ++a)
                        on_edge = on_edge && std::abs(mesh.positions[i][a] - expect[a]) < 1e-4;
                }
                CHECK(on_edge);
                CHECK(distinct.size() == mesh.positions.size());
            }
        }
    }
}

TEST_CASE("flat grids have no cubes and give an empty mesh") {
    Volume v = testutil::random_volume({6, 5, 1}, ValueType::uint8, 0, 9, 1);
    for (MeshMethod m : methods) {
        const Mesh mesh = extract_isosurface(v, 5, m);
        CHECK(mesh.positions.empty());
        CHECK(mesh.triangles.empty());
    }
}

TEST_CASE("every single-cube case and every pair of neighbouring cases closes up") {
    // The cube's corners take every sign pattern inside a negative border, so every table
    // case is a closed surface, and two cubes side by side along each axis check that the
    // cases agree on their shared face (4096 patterns per axis).
    for (MeshMethod m : methods) {
        CAPTURE(method_name(m));
        std::size_t failures = 0;
        for (int cube_case = 1; cube_case < 256; ++cube_case) {
            Volume v({4, 4, 4}, ValueType::uint8);
            for (int c = 0; c < 8; ++c)
                v.as<std::uint8_t>()[v.index(1 + (c & 1), 1 + (c >> 1 & 1), 1 + (c >> 2 & 1))] = (cube_case >> c) & 1;
            const ref::MeshTopology t = ref::topology(extract_isosurface(v, 1, m));
            // Spheres, except where marching tetrahedra joins the negative corners 0 and 7
            // along the cube's diagonal through a ring of six positives: a torus.
            const long euler = m == MeshMethod::marching_tetrahedra && cube_case == 0x7e ? 0 : long(2 * t.pieces);
            const bool ok = t.closed_manifold() && t.pieces == expected_pieces(v, 1, m) && t.euler == euler;
            if (!ok) {
                ++failures;
                MESSAGE("case " << cube_case);
            }
        }
        for (int axis = 0; axis < 3; ++axis)
            for (int pattern = 1; pattern < 4096; ++pattern) {
                Dims d{4, 4, 4};
                (axis == 0 ? d.nx : axis == 1 ? d.ny : d.nz) = 5;
                Volume v(d, ValueType::uint8);
                int bit = 0;
                for (std::size_t z = 1; z + 1 < d.nz; ++z)
                    for (std::size_t y = 1; y + 1 < d.ny; ++y)
                        for (std::size_t x = 1; x + 1 < d.nx; ++x)
                            v.as<std::uint8_t>()[v.index(x, y, z)] = (pattern >> bit++) & 1;
                const ref::MeshTopology t = ref::topology(extract_isosurface(v, 1, m));
                if (!t.closed_manifold() || t.pieces != expected_pieces(v, 1, m)) {
                    ++failures;
                    MESSAGE("axis " << axis << " pattern " << pattern);
                }
            }
        CHECK(failures == 0);
    }
}

TEST_CASE("a sphere is one closed surface, Euler characteristic 2, normals outwards") {
    // Inside values are high: the negative side is outside, where the normals point.
    SyntheticOptions o;
    o.size = 32;
    const Volume v = make_synthetic("sphere", o);
    const double s = 100, radius = 16 * (1 - s / 255);  // 255 (1 - d / 16) = s
    for (MeshMethod m : methods) {
        CAPTURE(method_name(m));
        const ref::MeshTopology t = ref::topology(extract_isosurface(v, s, m));
        CHECK(t.closed_manifold());
        CHECK(t.pieces == 1);
        CHECK(t.euler == 2);
        CHECK(t.signed_volume == doctest::Approx(4.0 / 3 * M_PI * radius * radius * radius).epsilon(0.05));
    }
}

TEST_CASE("a torus has Euler characteristic 0, normals into the tube") {
    // Distance to a ring of radius N/4 = 10: the tube {f < 4} is the negative side.
    SyntheticOptions o;
    o.size = 40;
    const Volume v = make_synthetic("torus", o);
    for (MeshMethod m : methods) {
        CAPTURE(method_name(m));
        const ref::MeshTopology t = ref::topology(extract_isosurface(v, 4, m));
        CHECK(t.closed_manifold());
        CHECK(t.pieces == 1);
        CHECK(t.euler == 0);
        CHECK(-t.signed_volume == doctest::Approx(2 * M_PI * M_PI * 10 * 4 * 4).epsilon(0.05));
    }
}

TEST_CASE("two separate balls are two spheres: Euler characteristic 4") {
    const Volume v = field_volume({40, 24, 24}, [](double x, double y, double z) {
        const double a = std::sqrt((x - 10) * (x - 10) + (y - 11.5) * (y - 11.5) + (z - 11.5) * (z - 11.5));
        const double b = std::sqrt((x - 28) * (x - 28) + (y - 11.5) * (y - 11.5) + (z - 11.5) * (z - 11.5));
        return std::max(6 - a, 6 - b);
    });
    for (MeshMethod m : methods) {
        CAPTURE(method_name(m));
        const ref::MeshTopology t = ref::topology(extract_isosurface(v, 0, m));
        CHECK(t.closed_manifold());
        CHECK(t.pieces == 2);
        CHECK(t.euler == 4);
    }
}

TEST_CASE("noisy surfaces inside the box are closed manifolds with the predicted pieces") {
    // A noisy ball with a negative border: many handles, holes and small islands.
    for (ValueType type : {ValueType::uint8, ValueType::float32}) {
        SyntheticOptions o;
        o.size = 24;
        o.type = type;
        Volume v = make_synthetic("sphere", o);
        visit(v, [&](auto* p) {
            using T = std::remove_pointer_t<decltype(p)>;
            for (std::size_t i = 0; i < v.vertices(); ++i)
                p[i] = T(std::clamp(double(p[i]) + 90 * uniform_noise(7, i), 0.0, 255.0));
        });
        set_border(v, 0);
        for (double s : {1.0, 30.0, 64.0, 100.0, 128.0, 171.0, 200.0, 240.0})
            for (MeshMethod m : methods) check_closed(v, s, m);
    }
}

TEST_CASE("pieces equal b0(A) + b0(C) - 1 on random grids with a negative border") {
    std::uint32_t seed = 100;
    for (ValueType type : {ValueType::uint8, ValueType::int16, ValueType::float32})
        for (int trial = 0; trial < 12; ++trial) {
            const Dims d{std::size_t(5 + trial % 4), std::size_t(6 + trial % 3), std::size_t(5 + trial % 5)};
            Volume v = testutil::random_volume(d, type, 1, 9, seed++);
            set_border(v, 0);
            const double step = type == ValueType::float32 ? 0.5 : 1;
            for (double s = step; s <= 9 * step; s += step)
                for (MeshMethod m : methods) check_closed(v, s, m);
        }
}

TEST_CASE("per-vertex fields interpolate along the grid edge") {
    Volume v = testutil::random_volume({7, 6, 5}, ValueType::int16, -9, 9, 21);
    // A field equal to 10 x + y: linear, so interpolation reproduces it at every vertex.
    const Volume field = field_volume(v.dims(), [](double x, double y, double) { return 10 * x + y; });
    for (MeshMethod m : methods) {
        const Mesh mesh = extract_isosurface(v, 1, m);
        REQUIRE(!mesh.positions.empty());
        const std::vector<float> f = interpolate_on_vertices(mesh, field);
        for (std::size_t i = 0; i < f.size(); ++i)
            CHECK(f[i] == doctest::Approx(10 * mesh.positions[i][0] + mesh.positions[i][1]).epsilon(1e-5));
    }
    // NaN at either end gives NaN; a wrong grid is refused.
    Volume nan_field = field;
    nan_field.as<float>()[0] = std::nanf("");
    const Mesh mesh = extract_isosurface(v, 1);
    const std::vector<float> f = interpolate_on_vertices(mesh, nan_field);
    for (std::size_t i = 0; i < f.size(); ++i)
        CHECK(std::isnan(f[i]) == (mesh.edge_points[i].u == 0));
    CHECK_THROWS_AS(interpolate_on_vertices(mesh, Volume({2, 2, 2}, ValueType::float32)), InputError);
    CHECK_THROWS_AS(interpolate_on_vertices(mesh, Volume(v.dims(), ValueType::uint8)), InputError);
}

TEST_CASE("LD colouring follows the thesis colour map") {
    SyntheticOptions o;
    o.size = 48;
    o.noise = 16;
    const Volume v = make_synthetic("noisy-sphere", o);
    const Volume ld = local_fractal_dimension(ctx(), v, 128, 8);
    Mesh mesh = extract_isosurface(v, 128);
    color_by_ld(mesh, ld);
    REQUIRE(mesh.colors.size() == mesh.positions.size());
    REQUIRE(mesh.ld.size() == mesh.positions.size());
    // The noise grows from 0 at x = 0 to 16 at x = N - 1: the clean half of the sphere (x below
    // its centre) is smooth, the noisy half rough. Red vertices lie almost all on the noisy
    // half, blue ones mostly on the clean half.
    const double centre = (o.size - 1) / 2.0;
    std::size_t red = 0, blue = 0, red_noisy = 0, blue_clean = 0;
    for (std::size_t i = 0; i < mesh.colors.size(); ++i) {
        const Rgb c = ld_colour(mesh.ld[i]);
        CHECK(mesh.colors[i] == std::array<std::uint8_t, 3>{c.r, c.g, c.b});
        const bool noisy_half = mesh.positions[i][0] > centre;
        red += mesh.ld[i] >= ld_red;
        blue += mesh.ld[i] <= ld_blue;
        red_noisy += mesh.ld[i] >= ld_red && noisy_half;
        blue_clean += mesh.ld[i] <= ld_blue && !noisy_half;
    }
    CAPTURE(red);
    CAPTURE(blue);
    CHECK(red > 0);
    CHECK(blue > 0);
    CHECK(10 * red_noisy >= 9 * red);
    CHECK(4 * blue_clean >= 3 * blue);
}

TEST_CASE("PLY files read back identically, with and without colours and LD") {
    Volume v = testutil::random_volume({9, 7, 8}, ValueType::float32, -9, 9, 5);
    v.spacing = {1, 1, 2.5};
    Mesh mesh = extract_isosurface(v, 0.25, MeshMethod::marching_tetrahedra);
    REQUIRE(!mesh.triangles.empty());
    const std::string path = temp_path("roundtrip.ply");
    for (int variant = 0; variant < 4; ++variant) {
        CAPTURE(variant);
        mesh.colors.clear();
        mesh.ld.clear();
        if (variant & 1)
            for (std::size_t i = 0; i < mesh.positions.size(); ++i)
                mesh.colors.push_back({std::uint8_t(i), std::uint8_t(3 * i), std::uint8_t(255 - i)});
        if (variant & 2)
            for (std::size_t i = 0; i < mesh.positions.size(); ++i)
                mesh.ld.push_back(i % 7 ? 2.0f + float(i) / 1000 : std::nanf(""));
        write_ply(mesh, path);
        const Mesh back = read_ply(path);
        CHECK(back.positions == mesh.positions);
        CHECK(back.triangles == mesh.triangles);
        CHECK(back.colors == mesh.colors);
        REQUIRE(back.ld.size() == mesh.ld.size());
        CHECK((mesh.ld.empty() || std::memcmp(back.ld.data(), mesh.ld.data(), 4 * mesh.ld.size()) == 0));  // NaN included
        CHECK(back.edge_points.empty());
    }
    // The header a PLY reader sees, byte for byte.
    std::ifstream in(path, std::ios::binary);
    std::string header((std::istreambuf_iterator<char>(in)), {});
    header = header.substr(0, header.find("end_header\n") + 11);
    CHECK(header == "ply\nformat binary_little_endian 1.0\ncomment written by clfractal\nelement vertex " +
                        std::to_string(mesh.positions.size()) +
                        "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar "
                        "green\nproperty uchar blue\nproperty float ld\nelement face " +
                        std::to_string(mesh.triangles.size()) +
                        "\nproperty list uchar int vertex_indices\nend_header\n");

    // Truncated or foreign files are refused with the path in the message; a missing
    // directory is refused without leaving anything behind.
    const auto size = std::filesystem::file_size(path);
    std::filesystem::resize_file(path, size - 5);
    CHECK_THROWS_WITH_AS(read_ply(path), doctest::Contains("truncated"), InputError);
    std::ofstream(path) << "ply\nformat ascii 1.0\nend_header\n";
    CHECK_THROWS_WITH_AS(read_ply(path), doctest::Contains(path.c_str()), InputError);
    std::filesystem::remove(path);
    CHECK_THROWS_AS(write_ply(mesh, temp_path("no/such/dir/x.ply")), InputError);
    // An empty mesh is a valid file.
    write_ply(Mesh{}, path);
    CHECK(read_ply(path).positions.empty());
    std::filesystem::remove(path);
}

TEST_CASE("the rasterizer keeps the nearest surface and covers what it should") {
    // Seen from +x (azimuth 0, elevation 0), a red square at x = 0 behind a blue one at
    // x = 1 that covers its centre; the order of the triangles must not matter.
    Mesh m;
    m.positions = {{0, -2, -2}, {0, 2, -2}, {0, 2, 2}, {0, -2, 2}, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}};
    m.colors = {{255, 0, 0}, {255, 0, 0}, {255, 0, 0}, {255, 0, 0}, {0, 0, 255}, {0, 0, 255}, {0, 0, 255}, {0, 0, 255}};
    const std::array<std::uint32_t, 3> red[] = {{0, 1, 2}, {0, 2, 3}}, blue[] = {{4, 5, 6}, {4, 6, 7}};
    RenderOptions o;
    o.width = o.height = 101;
    o.azimuth_deg = o.elevation_deg = 0;
    for (int order = 0; order < 2; ++order) {
        m.triangles.clear();
        for (const auto& t : order ? red : blue) m.triangles.push_back(t);
        for (const auto& t : order ? blue : red) m.triangles.push_back(t);
        const Image im = render_mesh(m, o);
        const auto centre = im.pixel(50, 50), edge = im.pixel(50, 8);
        CHECK((centre[2] > 100 && centre[0] == 0));  // blue in front
        CHECK((edge[0] > 100 && edge[2] == 0));      // red around it
        CHECK(im.pixel(1, 1) == std::array<std::uint8_t, 3>{255, 255, 255});  // margin
    }
    CHECK(render_mesh(Mesh{}, o).pixel(50, 50) == o.background);
    o.supersample = 0;
    CHECK_THROWS_AS(render_mesh(m, o), InputError);
}

TEST_CASE("preview PNGs: a shaded sphere, and red and blue on the LD-coloured noisy sphere") {
    SyntheticOptions o;
    o.size = 48;
    o.noise = 16;
    const Volume v = make_synthetic("noisy-sphere", o);
    Mesh mesh = extract_isosurface(v, 128);
    const std::string path = temp_path("preview.png");
    RenderOptions ro;
    ro.width = 320;
    ro.height = 240;

    write_png(render_mesh(mesh, ro), path);
    Image im = read_png(path);
    REQUIRE(im.width == 320);
    REQUIRE(im.height == 240);
    std::size_t background = 0;
    std::set<int> shades;
    for (std::size_t y = 0; y < im.height; ++y)
        for (std::size_t x = 0; x < im.width; ++x) {
            const auto p = im.pixel(x, y);
            if (p == ro.background) ++background;
            else shades.insert(p[0]);
        }
    CHECK(background > im.width * im.height / 4);
    CHECK(background < im.width * im.height * 3 / 4);
    CHECK(shades.size() > 50);  // Lambert shading, not a flat silhouette
    CHECK(im.pixel(160, 120) != ro.background);

    color_by_ld(mesh, local_fractal_dimension(ctx(), v, 128, 8));
    write_png(render_mesh(mesh, ro), path);
    im = read_png(path);
    std::size_t red = 0, blue = 0;
    for (std::size_t y = 0; y < im.height; ++y)
        for (std::size_t x = 0; x < im.width; ++x) {
            const auto p = im.pixel(x, y);
            red += p[0] > 60 && p[0] > 3 * p[2] && p[1] < 10;
            blue += p[2] > 60 && p[2] > 3 * p[0] && p[1] < 10;
        }
    CHECK(red > 500);
    CHECK(blue > 500);
    std::filesystem::remove(path);
    CHECK_THROWS_AS(read_png(path), InputError);
    CHECK_THROWS_AS(write_png(im, temp_path("no/such/dir/x.png")), InputError);
}

TEST_CASE("busiest slice: the most crossed x and y edges, the nearest to the middle among equals, every type") {
    // The definition on doubles: an edge is crossed when exactly one end lies below s (float32
    // data: s rounded to float32); NaN is never below.
    const auto reference = [](const Volume& v, double iso) {
        const Dims d = v.dims();
        const double s = v.type() == ValueType::float32 ? double(float(iso)) : iso;
        std::vector<std::size_t> n(d.nz, 0);
        for (std::size_t z = 0; z < d.nz; ++z)
            for (std::size_t y = 0; y < d.ny; ++y)
                for (std::size_t x = 0; x < d.nx; ++x) {
                    const bool a = v.value(v.index(x, y, z)) < s;
                    if (x + 1 < d.nx) n[z] += a != (v.value(v.index(x + 1, y, z)) < s);
                    if (y + 1 < d.ny) n[z] += a != (v.value(v.index(x, y + 1, z)) < s);
                }
        std::size_t best = d.nz / 2;
        const auto dist = [&](std::size_t k) { return k > d.nz / 2 ? k - d.nz / 2 : d.nz / 2 - k; };
        for (std::size_t z = 0; z < d.nz; ++z)
            if (n[z] > n[best] || (n[z] == n[best] && dist(z) < dist(best))) best = z;
        return best;
    };
    std::uint32_t seed = 70;
    std::size_t checked = 0, off_middle = 0;
    for (ValueType t : {ValueType::uint8, ValueType::int8, ValueType::uint16, ValueType::int16, ValueType::uint32,
                        ValueType::int32, ValueType::float32, ValueType::float64})
        for (const Dims& d : {Dims{19, 7, 9}, Dims{1, 5, 6}, Dims{33, 2, 11}}) {
            Volume v = testutil::random_volume(d, t, 0, 12, seed++);
            // Slices of fewer levels cross less: the answer moves with them.
            visit(v, [&](auto* p) {
                for (std::size_t z = 0; z < d.nz; ++z)
                    if ((z * 7 + seed) % 3 == 0)
                        for (std::size_t i = 0; i < d.nx * d.ny; ++i) p[z * d.nx * d.ny + i] = p[z * d.nx * d.ny + i] > 6 ? 12 : 0;
            });
            if (!is_integer(t))
                visit(v, [&](auto* p) {
                    using T = std::remove_pointer_t<decltype(p)>;
                    if constexpr (std::is_floating_point_v<T>) p[v.index(0, 1, d.nz - 1)] = T(NAN);
                });
            for (double iso : {-1e12, -0.5, 0.0, 2.5, 3.0, 6.0, 7.25, 12.0, 12.5, 1e12}) {
                CAPTURE(std::string(value_type_name(t)));
                CAPTURE(dims_string(d));
                CAPTURE(iso);
                const std::size_t want = reference(v, iso);
                CHECK(busiest_slice(v, iso) == want);
                ++checked;
                off_middle += want != d.nz / 2;
            }
        }
    CHECK(checked == 240);
    CHECK(off_middle > 60);  // the cases tell the slices apart
}

}  // TEST_SUITE
