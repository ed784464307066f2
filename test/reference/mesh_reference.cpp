#include "reference/mesh_reference.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <queue>

namespace ref {

namespace {

const int freudenthal[7][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}};

std::vector<std::array<int, 3>> offsets(Adjacency adjacency) {
    std::vector<std::array<int, 3>> o;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int steps = std::abs(dx) + std::abs(dy) + std::abs(dz);
                if (steps == 0) continue;
                bool keep = adjacency == Adjacency::twenty_six || (adjacency == Adjacency::six && steps == 1);
                if (adjacency == Adjacency::fourteen)
                    for (const auto& f : freudenthal)
                        keep = keep || (dx == f[0] && dy == f[1] && dz == f[2]) ||
                               (dx == -f[0] && dy == -f[1] && dz == -f[2]);
                if (keep) o.push_back({dx, dy, dz});
            }
    return o;
}

}  // namespace

std::vector<std::uint64_t> freudenthal_edges_brute(const Volume& v, const IsovalueSet& iso) {
    const auto d = v.dims();
    std::vector<std::uint64_t> n(iso.size(), 0);
    for (std::size_t z = 0; z < d.nz; ++z)
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x)
                for (const auto& f : freudenthal) {
                    if (x + f[0] >= d.nx || y + f[1] >= d.ny || z + f[2] >= d.nz) continue;
                    const double p = v.value(v.index(x, y, z)), q = v.value(v.index(x + f[0], y + f[1], z + f[2]));
                    const double a = std::min(p, q), b = std::max(p, q);
                    for (std::size_t j = 0; j < iso.size(); ++j)
                        if (a < iso.value(j) && iso.value(j) <= b) ++n[j];
                }
    return n;
}

std::size_t components(const Volume& v, double s, bool positive, Adjacency adjacency) {
    const auto d = v.dims();
    const auto o = offsets(adjacency);
    auto in_set = [&](std::size_t i) { return (v.value(i) >= s) == positive; };
    std::vector<bool> seen(v.vertices(), false);
    std::size_t count = 0;
    for (std::size_t start = 0; start < v.vertices(); ++start) {
        if (seen[start] || !in_set(start)) continue;
        ++count;
        std::queue<std::size_t> todo;
        todo.push(start);
        seen[start] = true;
        while (!todo.empty()) {
            const std::size_t i = todo.front();
            todo.pop();
            const long x = long(i % d.nx), y = long(i / d.nx % d.ny), z = long(i / (d.nx * d.ny));
            for (const auto& e : o) {
                const long a = x + e[0], b = y + e[1], c = z + e[2];
                if (a < 0 || b < 0 || c < 0 || a >= long(d.nx) || b >= long(d.ny) || c >= long(d.nz)) continue;
                const std::size_t j = v.index(std::size_t(a), std::size_t(b), std::size_t(c));
                if (!seen[j] && in_set(j)) {
                    seen[j] = true;
                    todo.push(j);
                }
            }
        }
    }
    return count;
}

MeshTopology topology(const Mesh& m) {
    MeshTopology t;
    const std::size_t nv = m.positions.size();
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    std::vector<std::map<std::uint32_t, std::vector<std::uint32_t>>> link(nv);  // vertex -> its fan's edges
    std::vector<std::size_t> parent(nv);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::size_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    std::vector<bool> used(nv, false);
    for (const auto& tri : m.triangles) {
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) ++t.degenerate;
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = tri[e], b = tri[(e + 1) % 3], c = tri[(e + 2) % 3];
            used[a] = true;
            ++directed[{a, b}];
            link[a][b].push_back(c);
            parent[find(a)] = find(b);
        }
        const auto &p = m.positions[tri[0]], &q = m.positions[tri[1]], &r = m.positions[tri[2]];
        t.signed_volume += (double(p[0]) * (double(q[1]) * r[2] - double(q[2]) * r[1]) -
                            double(p[1]) * (double(q[0]) * r[2] - double(q[2]) * r[0]) +
                            double(p[2]) * (double(q[0]) * r[1] - double(q[1]) * r[0])) / 6;
    }
    for (const auto& [edge, n] : directed) {
        const auto back = directed.find({edge.second, edge.first});
        const int reverse = back == directed.end() ? 0 : back->second;
        if (edge.first < edge.second || reverse == 0) {
            ++t.edges;
            if (n + reverse != 2) ++t.open_or_branching;
            else if (n != 1) ++t.misoriented;
        }
    }
    for (std::size_t i = 0; i < nv; ++i) {
        if (!used[i]) {
            ++t.unused_vertices;
            continue;
        }
        // On a closed oriented manifold the triangles around a vertex form one cycle: each
        // neighbour starts exactly one fan edge, and walking them returns after all of them.
        bool ok = true;
        for (const auto& [from, to] : link[i]) ok = ok && to.size() == 1;
        std::size_t steps = 0;
        if (ok) {
            std::uint32_t at = link[i].begin()->first;
            do {
                const auto it = link[i].find(at);
                if (it == link[i].end()) break;
                at = it->second[0];
                ++steps;
            } while (at != link[i].begin()->first && steps <= link[i].size());
            ok = at == link[i].begin()->first && steps == link[i].size();
        }
        if (!ok) ++t.non_manifold_vertices;
        if (find(i) == i) ++t.pieces;
    }
    t.euler = long(nv - t.unused_vertices) - long(t.edges) + long(m.triangles.size());
    return t;
}

}  // namespace ref
