// Marching cubes / marching tetrahedra with one vertex per intersected grid edge
// (docs/definitions.md §15 "Isosurface meshes"). Host code: meshes are extracted once per
// isovalue, not per analysis, so this is not on the hot path.
//
// Both methods run one loop over the cubes with a 256-case table (corner c of a cube is
// bit c of the case when positive; its offset is (c & 1, c >> 1 & 1, c >> 2 & 1)). The
// tables are derived on first use from the rules in mesh.hpp rather than typed in, and
// the tests check every case and every pair of neighbouring cases for a closed,
// consistently oriented surface.
#include "clfractal/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <type_traits>

#include "clfractal/local.hpp"
#include "device/name_table.hpp"
#include "extract_scratch.hpp"
#include "volume/below.hpp"

namespace clfractal {
namespace {


// A grid edge of one cube: from corner `corner` along the direction bit mask `dir`
// (x = 1, y = 2, z = 4) to corner `corner | dir`; corner & dir == 0.
struct Slot {
    int corner, dir;
};

// Triangles of every case, as slot indices.
struct CaseTable {
    std::vector<Slot> slots;
    std::array<std::size_t, 257> first{};  // case c: tris[first[c] .. first[c + 1])
    std::vector<std::array<int, 3>> tris;
};

bool positive(int cube_case, int corner) { return (cube_case >> corner) & 1; }

// Midpoint of a slot in cube coordinates: the geometry the tables are built with.
std::array<double, 3> midpoint(const Slot& s) {
    std::array<double, 3> p{};
    for (int a = 0; a < 3; ++a) p[a] = ((s.corner >> a) & 1) + 0.5 * ((s.dir >> a) & 1);
    return p;
}

double distance(const Slot& a, const Slot& b) {
    const auto p = midpoint(a), q = midpoint(b);
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

// True when both edges lie in one face of the cube. A triangle edge there would also
// be chosen by the cube across that face, giving a mesh edge with four triangles, so
// the tables never use one except as the face's own contour segment.
bool share_face(const Slot& a, const Slot& b) {
    for (int axis = 0; axis < 3; ++axis) {
        const int bit = 1 << axis;
        if (!(a.dir & bit) && !(b.dir & bit) && (a.corner & bit) == (b.corner & bit)) return true;
    }
    return false;
}

// ---- marching cubes, separating negative vertices ----
//
// On each face, the contour is the boundary of the face's negative part, oriented
// counter-clockwise around it as seen from outside the cube, and an ambiguous face
// (negatives on a diagonal) cuts off each negative corner. These segments chain into
// loops on the cube's surface, one or more around each 6-connected group of negative
// corners. Each loop around a group is triangulated as a disc, except when the only
// positive corners are two opposite ones: their group is the ring of the other six,
// bounded by two loops, and an annulus between those loops joins the two positives
// through the cube (26-connectivity of the positive set). A loop oriented
// counter-clockwise around the negative side seen from outside gives triangles whose
// normals point to that side.

// Triangulates the polygon `loop` (slot indices in order) as a disc, minimising the total
// length of its diagonals and never using one that lies in a cube face.
void triangulate_disc(const std::vector<Slot>& slots, const std::vector<int>& loop,
                      std::vector<std::array<int, 3>>& out) {
    const int m = int(loop.size());
    const double inf = std::numeric_limits<double>::infinity();
    auto chord = [&](int i, int k) {
        if (k - i == 1 || (i == 0 && k == m - 1)) return 0.0;  // a side of the polygon
        const Slot &a = slots[loop[i]], &b = slots[loop[k]];
        return share_face(a, b) ? inf : distance(a, b);
    };
    std::vector<std::vector<double>> cost(m, std::vector<double>(m, 0.0));
    std::vector<std::vector<int>> apex(m, std::vector<int>(m, -1));
    for (int len = 2; len < m; ++len)
        for (int i = 0; i + len < m; ++i) {
            const int k = i + len;
            cost[i][k] = inf;
            for (int j = i + 1; j < k; ++j) {
                const double c = cost[i][j] + cost[j][k] + chord(i, j) + chord(j, k);
                if (c < cost[i][k]) cost[i][k] = c, apex[i][k] = j;
            }
        }
    if (!(cost[0][m - 1] < inf)) throw std::logic_error("marching cubes table: no triangulation of a loop");
    std::vector<std::pair<int, int>> todo{{0, m - 1}};
    while (!todo.empty()) {
        auto [i, k] = todo.back();
        todo.pop_back();
        if (k - i < 2) continue;
        const int j = apex[i][k];
        out.push_back({loop[i], loop[j], loop[k]});  // i < j < k keeps the loop's orientation
        todo.push_back({i, j});
        todo.push_back({j, k});
    }
}

// Triangulates the annulus between loops a and b, which bound the same surface region
// (so they run in opposite senses around it): a strip walking a forwards and b backwards,
// from the start on b that gives the shortest strip.
void triangulate_annulus(const std::vector<Slot>& slots, const std::vector<int>& a, const std::vector<int>& b,
                         std::vector<std::array<int, 3>>& out) {
    const int p = int(a.size()), q = int(b.size());
    std::vector<std::array<int, 3>> best;
    double best_length = std::numeric_limits<double>::infinity();
    for (int start = 0; start < q; ++start) {
        auto bb = [&](int j) { return b[((start - j) % q + q) % q]; };
        std::vector<std::array<int, 3>> strip;
        double length = 0;
        int i = 0, j = 0;
        while (i < p || j < q) {
            // Advance along whichever loop gives the shorter new rung.
            const bool advance_a =
                j == q || (i < p && distance(slots[a[(i + 1) % p]], slots[bb(j)]) <=
                                        distance(slots[a[i % p]], slots[bb(j + 1)]));
            if (advance_a) {
                strip.push_back({a[i % p], a[(i + 1) % p], bb(j)});
                length += distance(slots[a[(i + 1) % p]], slots[bb(j)]);
                ++i;
            } else {
                strip.push_back({bb(j + 1), bb(j), a[i % p]});
                length += distance(slots[a[i % p]], slots[bb(j + 1)]);
                ++j;
            }
        }
        if (length < best_length) best_length = length, best = strip;
    }
    // The rungs (edges from loop a to loop b) must not lie in a cube face either.
    auto on_a = [&](int s) { return std::find(a.begin(), a.end(), s) != a.end(); };
    for (auto& t : best)
        for (int e = 0; e < 3; ++e)
            if (on_a(t[e]) != on_a(t[(e + 1) % 3]) && share_face(slots[t[e]], slots[t[(e + 1) % 3]]))
                throw std::logic_error("marching cubes table: annulus rung in a cube face");
    out.insert(out.end(), best.begin(), best.end());
}

// Directed contour segments of one cube case on the six faces: next[slot] is the slot the
// contour goes to (-1: none).
std::vector<int> face_segments(int cube_case, const int (&slot_of)[8][8]) {
    auto neg = [&](int c) { return !positive(cube_case, c); };
    std::vector<int> next(12, -1);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int b = (axis + 1) % 3, c = (axis + 2) % 3;
            // Corners counter-clockwise seen from +axis; reversed for the face at side 0.
            int corners[4];
            const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int k = 0; k < 4; ++k)
                corners[k] = side << axis | uv[k][0] << b | uv[k][1] << c;
            if (side == 0) std::swap(corners[1], corners[3]);
            // Side k runs from corners[k] to corners[k + 1]; the boundary of the negative
            // part leaves the face's rim where a side goes negative -> positive (a start)
            // and returns where it goes positive -> negative (an end).
            for (int k = 0; k < 4; ++k) {
                const int c0 = corners[k], c1 = corners[(k + 1) % 4];
                if (!(neg(c0) && !neg(c1))) continue;
                // Separating negatives: the start joins the nearest end before it,
                // so the segment cuts off corners[k] (and any negatives behind it).
                for (int back = 1; back < 4; ++back) {
                    const int j = (k - back + 4) % 4;
                    const int d0 = corners[j], d1 = corners[(j + 1) % 4];
                    if (!neg(d0) && neg(d1)) {
                        next[slot_of[c0][c1]] = slot_of[d0][d1];
                        break;
                    }
                }
            }
        }
    return next;
}

// Triangulate one cube case from its contour segments, appending to table.tris.
void triangulate_case(CaseTable& table, int cube_case, const std::vector<int>& next) {
    auto neg = [&](int c) { return !positive(cube_case, c); };

    // Groups of negative corners joined by cube edges (union-find on 8 corners).
    int group[8];
    std::iota(group, group + 8, 0);
    auto find = [&](int c) {
        while (group[c] != c) c = group[c] = group[group[c]];
        return c;
    };
    for (const Slot& s : table.slots)
        if (neg(s.corner) && neg(s.corner | s.dir)) group[find(s.corner)] = find(s.corner | s.dir);

    // Loops, collected per negative group.
    std::vector<std::vector<std::vector<int>>> loops_of(8);
    std::vector<bool> seen(12, false);
    for (int s0 = 0; s0 < 12; ++s0) {
        if (next[s0] < 0 || seen[s0]) continue;
        std::vector<int> loop;
        for (int s = s0; !seen[s]; s = next[s]) {
            if (next[s] < 0) throw std::logic_error("marching cubes table: open contour");
            seen[s] = true;
            loop.push_back(s);
        }
        const Slot& first = table.slots[loop[0]];
        const int negative_corner = neg(first.corner) ? first.corner : first.corner | first.dir;
        loops_of[find(negative_corner)].push_back(loop);
    }
    for (auto& loops : loops_of) {
        if (loops.size() == 1) triangulate_disc(table.slots, loops[0], table.tris);
        else if (loops.size() == 2) triangulate_annulus(table.slots, loops[0], loops[1], table.tris);
        else if (!loops.empty()) throw std::logic_error("marching cubes table: more than two loops");
    }
}

CaseTable build_marching_cubes_table() {
    CaseTable table;
    int slot_of[8][8];  // slot_of[corner][other corner] for the 12 cube edges
    for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 8; ++c)
            if (!(c & (1 << axis))) {
                slot_of[c][c | (1 << axis)] = slot_of[c | (1 << axis)][c] = int(table.slots.size());
                table.slots.push_back({c, 1 << axis});
            }

    for (int cube_case = 0; cube_case < 256; ++cube_case) {
        table.first[cube_case] = table.tris.size();
        triangulate_case(table, cube_case, face_segments(cube_case, slot_of));
    }
    table.first[256] = table.tris.size();
    return table;
}

// ---- marching tetrahedra on the Freudenthal triangulation ----
//
// Tetrahedron (0, e_p, e_p + e_q, (1,1,1)) for every permutation (p, q, r) of the axes;
// its edges are the 19 Freudenthal edges of the cube. One negative or one positive corner
// gives a triangle, two of each a quadrilateral split along its shorter diagonal. Each
// triangle is oriented by its normal against the negative corners, on slot midpoints:
// moving the vertices along their edges never flips a triangle that separates them.

CaseTable build_marching_tetrahedra_table() {
    CaseTable table;
    int slot_of[8][8];
    for (int c = 0; c < 8; ++c)
        for (int d = 1; d < 8; ++d)
            if (!(c & d)) {
                slot_of[c][c | d] = slot_of[c | d][c] = int(table.slots.size());
                table.slots.push_back({c, d});
            }
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

    for (int cube_case = 0; cube_case < 256; ++cube_case) {
        table.first[cube_case] = table.tris.size();
        for (const auto& perm : perms) {
            const int tet[4] = {0, 1 << perm[0], (1 << perm[0]) | (1 << perm[1]), 7};
            std::vector<int> neg, pos;
            for (int c : tet) (positive(cube_case, c) ? pos : neg).push_back(c);
            if (neg.empty() || pos.empty()) continue;

            std::array<double, 3> neg_centre{};
            for (int c : neg)
                for (int a = 0; a < 3; ++a) neg_centre[a] += double((c >> a) & 1) / double(neg.size());
            auto emit = [&](int s0, int s1, int s2) {
                const auto p0 = midpoint(table.slots[s0]), p1 = midpoint(table.slots[s1]),
                           p2 = midpoint(table.slots[s2]);
                const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
                const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
                const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
                const double side = n[0] * (neg_centre[0] - p0[0]) + n[1] * (neg_centre[1] - p0[1]) +
                                    n[2] * (neg_centre[2] - p0[2]);
                if (side > 0) table.tris.push_back({s0, s1, s2});
                else table.tris.push_back({s0, s2, s1});
            };
            if (neg.size() == 2) {
                const int a = neg[0], b = neg[1], c = pos[0], d = pos[1];
                // Cyclic order ac, ad, bd, bc.
                const int q[4] = {slot_of[a][c], slot_of[a][d], slot_of[b][d], slot_of[b][c]};
                if (distance(table.slots[q[0]], table.slots[q[2]]) <= distance(table.slots[q[1]], table.slots[q[3]])) {
                    emit(q[0], q[1], q[2]);
                    emit(q[0], q[2], q[3]);
                } else {
                    emit(q[1], q[2], q[3]);
                    emit(q[1], q[3], q[0]);
                }
            } else {
                const int odd = neg.size() == 1 ? neg[0] : pos[0];
                const auto& others = neg.size() == 1 ? pos : neg;
                emit(slot_of[odd][others[0]], slot_of[odd][others[1]], slot_of[odd][others[2]]);
            }
        }
    }
    table.first[256] = table.tris.size();
    return table;
}

const CaseTable& case_table(MeshMethod method) {
    static const CaseTable mc = build_marching_cubes_table();
    static const CaseTable mt = build_marching_tetrahedra_table();
    return method == MeshMethod::marching_cubes ? mc : mt;
}

// ---- extraction ----

constexpr std::uint32_t no_vertex = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t max_mesh_elements = std::size_t(std::numeric_limits<std::int32_t>::max());

// Walks the cubes layer by layer (z, z + 1). Vertex indices of the grid edges live in
// per-slice arrays that roll with the layer, so memory is O(nx ny), not O(edges):
// `lower`/`upper` hold the edges within slice z / z + 1 (directions x, y, x+y), `across`
// those from slice z to z + 1 (z, x+z, y+z, x+y+z). The arrays are never cleared: vertex
// indices (plus the scratch's base) grow as they are made, so an entry made before the layer
// that owns the array now (`lower`: the layer before; `upper`, `across`: this one), or by an
// earlier call, reads as stale.
// Cube layers z0 <= z < z1 only (a slab of the volume); positive vertices: cut.at_or_above.
template <class T>
Mesh extract(const T* f, const Dims& d, double s, const detail::Below<T>& cut, const std::array<double, 3>& spacing,
             const CaseTable& table, std::size_t z0, std::size_t z1, detail::ExtractScratch& scratch) {
    Mesh mesh = std::move(scratch.spare);
    scratch.spare = Mesh();
    mesh.positions.clear(), mesh.triangles.clear(), mesh.edge_points.clear(), mesh.ld.clear(), mesh.colors.clear();
    const std::size_t nx = d.nx, ny = d.ny, plane = nx * ny;
    // A base past 2^31 leaves room for no more than 2^31 - 1 vertices below no_vertex: start over.
    if (scratch.plane != plane || scratch.base > (std::uint32_t(1) << 31)) {
        scratch.plane = plane, scratch.base = 0;
        scratch.sign_lower.assign(plane, 0), scratch.sign_upper.assign(plane, 0), scratch.cases.assign(nx, 0);
        scratch.lower.assign(plane * 3, no_vertex), scratch.upper.assign(plane * 3, no_vertex);
        scratch.across.assign(plane * 4, no_vertex);
    }
    std::vector<std::uint8_t>&sign_lower = scratch.sign_lower, &sign_upper = scratch.sign_upper, &cases = scratch.cases;
    std::vector<std::uint32_t>&lower = scratch.lower, &upper = scratch.upper, &across = scratch.across;
    const std::uint32_t base = scratch.base;
    scratch.plane = 0;  // a throw below leaves the arrays to be made again
    const auto fill_signs = [&](std::vector<std::uint8_t>& sign_of, std::size_t z) {
        const T* __restrict slice = f + z * plane;
        std::uint8_t* __restrict sign = sign_of.data();
        const detail::Below<T> c = cut;  // a copy, which the bytes cannot alias
        for (std::size_t i = 0; i < plane; ++i) sign[i] = c.at_or_above(slice[i]);
    };
    // The first vertex made by the layer before / this layer, plus base.
    std::uint32_t lower_from = base, layer_from = base;

    auto vertex = [&](const Slot& slot, std::size_t x, std::size_t y, std::size_t z) -> std::uint32_t {
        const std::size_t cx = x + (slot.corner & 1), cy = y + (slot.corner >> 1 & 1);
        const std::size_t in_plane = cy * nx + cx;
        const bool in_lower = !(slot.dir & 4) && !(slot.corner & 4);
        std::uint32_t& id = (slot.dir & 4) ? across[in_plane * 4 + (slot.dir - 4)]
                                           : (in_lower ? lower : upper)[in_plane * 3 + (slot.dir - 1)];
        if (id != no_vertex && id >= (in_lower ? lower_from : layer_from)) return id - base;
        if (mesh.positions.size() >= max_mesh_elements)
            throw InputError("isosurface has more than 2^31 - 1 vertices (the PLY limit)");
        const std::size_t cz = z + (slot.corner >> 2 & 1);
        const int dx = slot.dir & 1, dy = slot.dir >> 1 & 1, dz = slot.dir >> 2 & 1;
        const std::size_t u = cz * plane + in_plane, w = u + dx + dy * nx + dz * plane;
        const double fu = double(f[u]), fw = double(f[w]);
        const double t = (s - fu) / (fw - fu);  // fu != fw: the edge is intersected
        const std::uint32_t made = std::uint32_t(mesh.positions.size());
        id = base + made;
        mesh.positions.push_back({float((double(cx) + t * dx) * spacing[0]), float((double(cy) + t * dy) * spacing[1]),
                                  float((double(cz) + t * dz) * spacing[2])});
        mesh.edge_points.push_back({u, w, float(t)});
        return made;
    };

    fill_signs(sign_lower, z0);
    for (std::size_t z = z0; z + 1 < d.nz && z < z1; ++z) {
        fill_signs(sign_upper, z + 1);
        lower_from = z == z0 ? base : layer_from;
        layer_from = base + std::uint32_t(mesh.positions.size());
        for (std::size_t y = 0; y + 1 < ny; ++y) {
            const std::uint8_t* __restrict l0 = &sign_lower[y * nx];
            const std::uint8_t* __restrict u0 = &sign_upper[y * nx];
            std::uint8_t* __restrict row = cases.data();
            // The row's cube cases at once; a case 0 or 255 has no triangles and is skipped
            // eight at a time.
            for (std::size_t x = 0; x + 1 < nx; ++x)
                row[x] = std::uint8_t(l0[x] | l0[x + 1] << 1 | l0[x + nx] << 2 | l0[x + nx + 1] << 3 | u0[x] << 4 |
                                      u0[x + 1] << 5 | u0[x + nx] << 6 | u0[x + nx + 1] << 7);
            for (std::size_t x = 0; x + 1 < nx; ++x) {
                if (x + 9 < nx) {
                    std::uint64_t word;
                    std::memcpy(&word, &cases[x], 8);
                    if (word == 0 || word == ~std::uint64_t(0)) {
                        x += 7;
                        continue;
                    }
                }
                const int cube_case = cases[x];
                for (std::size_t k = table.first[cube_case]; k < table.first[cube_case + 1]; ++k) {
                    const auto& tri = table.tris[k];
                    mesh.triangles.push_back({vertex(table.slots[tri[0]], x, y, z),
                                              vertex(table.slots[tri[1]], x, y, z),
                                              vertex(table.slots[tri[2]], x, y, z)});
                }
            }
        }
        if (mesh.triangles.size() > max_mesh_elements)
            throw InputError("isosurface has more than 2^31 - 1 triangles (the PLY limit)");
        std::swap(lower, upper);
        std::swap(sign_lower, sign_upper);
    }
    scratch.base = base + std::uint32_t(mesh.positions.size());
    scratch.plane = plane;
    return mesh;
}

}  // namespace

template <> struct detail::NameTable<MeshMethod> {
    static constexpr const char* what = "--method";
    static constexpr std::pair<MeshMethod, const char*> names[] = {
        {MeshMethod::marching_cubes, "mc"},
        {MeshMethod::marching_cubes, "marching-cubes"},
        {MeshMethod::marching_tetrahedra, "mt"},
        {MeshMethod::marching_tetrahedra, "marching-tetrahedra"}};
};
CLFRACTAL_NAME_TABLE(MeshMethod)

MeshMethod parse_mesh_method(const std::string& name) { return parse_variant<MeshMethod>(name); }

Mesh detail::extract_isosurface_layers(const Volume& v, double s, std::size_t z0, std::size_t z1, MeshMethod method,
                                       ExtractScratch& scratch) {
    if (!std::isfinite(s)) throw InputError("isovalue must be a finite number");
    const Dims& d = v.dims();
    if (d.nx < 2 || d.ny < 2 || d.nz < 2 || z0 >= z1 || z0 + 1 >= d.nz) return {};
    const CaseTable& table = case_table(method);
    return visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        const auto cut = detail::below<T>(v.type(), s);
        if (!cut) return Mesh();  // every value on one side: no cube is crossed
        return extract(p, d, v.type() == ValueType::float32 ? double(float(s)) : s, *cut, v.spacing, table, z0, z1,
                       scratch);
    });
}

Mesh extract_isosurface_layers(const Volume& v, double s, std::size_t z0, std::size_t z1, MeshMethod method) {
    detail::ExtractScratch scratch;
    return detail::extract_isosurface_layers(v, s, z0, z1, method, scratch);
}

Mesh extract_isosurface(const Volume& v, double s, MeshMethod method) {
    return extract_isosurface_layers(v, s, 0, v.dims().nz, method);
}

std::vector<float> interpolate_on_vertices(const Mesh& mesh, const Volume& field) {
    std::vector<float> out;
    detail::interpolate_on_vertices(mesh, field, out);
    return out;
}

void detail::interpolate_on_vertices(const Mesh& mesh, const Volume& field, std::vector<float>& out) {
    if (field.type() != ValueType::float32) throw InputError("per-vertex field: expected float32 values");
    if (mesh.edge_points.size() != mesh.positions.size())
        throw InputError("per-vertex field: the mesh has no grid edges (extract it, do not read it back)");
    const float* f = field.as<float>();
    out.resize(mesh.edge_points.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const EdgePoint& e = mesh.edge_points[i];
        if (e.u >= field.vertices() || e.w >= field.vertices())
            throw InputError("per-vertex field: its dims " + dims_string(field.dims()) + " do not match the mesh's grid");
        out[i] = f[e.u] + e.t * (f[e.w] - f[e.u]);
    }
}

void color_by_ld(Mesh& mesh, const Volume& ld_field) {
    mesh.ld = interpolate_on_vertices(mesh, ld_field);
    mesh.colors.resize(mesh.ld.size());
    std::transform(mesh.ld.begin(), mesh.ld.end(), mesh.colors.begin(), [](float ld) {
        const Rgb c = ld_colour(ld);
        return std::array<std::uint8_t, 3>{c.r, c.g, c.b};
    });
}

Mesh extract_isosurface(const DeviceVolume& v, double s, MeshMethod method) {
    return extract_isosurface(v.download(), s, method);
}

void color_by_ld(Mesh& mesh, const DeviceVolume& ld_field) { color_by_ld(mesh, ld_field.download()); }

}  // namespace clfractal
