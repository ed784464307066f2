#include "reference/smooth_reference.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <queue>
#include <set>
#include <utility>

using clfractal::Dims;
using clfractal::ValueType;
using clfractal::Volume;

namespace ref {

namespace {

double compared_isovalue(const Volume& v, double iso) {
    return v.type() == ValueType::float32 ? double(float(iso)) : iso;
}

double type_minimum(ValueType t) { return clfractal::type_min(t); }

std::vector<double> values_of(const Volume& v) {
    std::vector<double> f(v.vertices());
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = v.value(i);
    return f;
}

Volume volume_of(const std::vector<double>& f, const Volume& like) {
    Volume out(like.dims(), like.type(), like.name);
    out.spacing = like.spacing;
    clfractal::visit(out, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t i = 0; i < f.size(); ++i) p[i] = T(f[i]);
    });
    return out;
}

struct Grid {
    long nx, ny, nz;
    explicit Grid(const Dims& d) : nx(long(d.nx)), ny(long(d.ny)), nz(long(d.nz)) {}
    long index(long x, long y, long z) const { return x + nx * (y + ny * z); }
    bool inside(long x, long y, long z) const { return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz; }
};

}  // namespace

std::vector<double> field_values(const Volume& ld) {
    std::vector<double> out(ld.vertices());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = ld.value(i);
    return out;
}

SmoothOutcome smooth(const Volume& v, const std::vector<double>& ld, double iso, double h,
                     clfractal::SmoothVariant variant, double tau) {
    const Grid g(v.dims());
    const double s = compared_isovalue(v, iso);
    std::vector<double> f = values_of(v);
    auto intersected = [&](long p, long q) { return std::min(f[p], f[q]) < s && s <= std::max(f[p], f[q]); };
    auto high = [&](long p, long q) { return intersected(p, q) && (ld[p] > h || ld[q] > h); };

    SmoothOutcome out;
    std::set<std::pair<long, long>> seen;
    std::queue<std::pair<long, long>> queue;
    auto push = [&](long p, long q) {
        queue.push({p, q});
        seen.insert({std::min(p, q), std::max(p, q)});
    };

    // Algorithm 1: every vertex in index order, its +x, +y, +z edge.
    for (long z = 0; z < g.nz; ++z)
        for (long y = 0; y < g.ny; ++y)
            for (long x = 0; x < g.nx; ++x) {
                const long i = g.index(x, y, z);
                if (x + 1 < g.nx && high(i, g.index(x + 1, y, z))) push(i, g.index(x + 1, y, z));
                if (y + 1 < g.ny && high(i, g.index(x, y + 1, z))) push(i, g.index(x, y + 1, z));
                if (z + 1 < g.nz && high(i, g.index(x, y, z + 1))) push(i, g.index(x, y, z + 1));
            }

    // Algorithm 2.
    while (!queue.empty()) {
        auto [p, q] = queue.front();
        queue.pop();
        ++out.pops;
        if (!intersected(p, q)) continue;
        ++out.lowered;
        const long vv = f[p] > f[q] ? p : q, u = vv == p ? q : p;
        const double delta = f[vv] - f[u];
        std::set<long> changed{vv};
        f[vv] = f[u];
        if (variant == clfractal::SmoothVariant::gaussian) {
            const long x = vv % g.nx, y = (vv / g.nx) % g.ny, z = vv / (g.nx * g.ny);
            for (long dz = -1; dz <= 1; ++dz)
                for (long dy = -1; dy <= 1; ++dy)
                    for (long dx = -1; dx <= 1; ++dx) {
                        if ((dx == 0 && dy == 0 && dz == 0) || !g.inside(x + dx, y + dy, z + dz)) continue;
                        const long w = g.index(x + dx, y + dy, z + dz);
                        const double d2 = double(dx * dx + dy * dy + dz * dz);
                        const double amount = delta * std::exp(-d2 / (2.0 * tau * tau));
                        double lowered;
                        if (v.type() == ValueType::float32)
                            lowered = double(float(std::max(type_minimum(v.type()), f[w] - amount)));
                        else if (v.type() == ValueType::float64)
                            lowered = std::max(type_minimum(v.type()), f[w] - amount);
                        else
                            lowered = std::max(type_minimum(v.type()), f[w] - std::floor(amount + 0.5));
                        if (lowered != f[w]) {
                            f[w] = lowered;
                            changed.insert(w);
                        }
                    }
        }
        // Every edge around every changed vertex (increasing index), now intersected and
        // high fractal, in increasing index of its other end.
        for (long c : changed) {
            const long x = c % g.nx, y = (c / g.nx) % g.ny, z = c / (g.nx * g.ny);
            const long around[6][3] = {{0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
            for (const auto& o : around) {
                if (!g.inside(x + o[0], y + o[1], z + o[2])) continue;
                const long w = g.index(x + o[0], y + o[1], z + o[2]);
                if (high(c, w)) push(c, w);
            }
        }
    }
    out.distinct_queued = seen.size();
    out.volume = volume_of(f, v);
    return out;
}

std::uint64_t intersected_edges(const Volume& v, double iso) {
    return high_fractal_edges(v, std::vector<double>(v.vertices(), std::numeric_limits<double>::infinity()), iso,
                              0.0);
}

std::uint64_t high_fractal_edges(const Volume& v, const std::vector<double>& ld, double iso, double h) {
    const Grid g(v.dims());
    const double s = compared_isovalue(v, iso);
    std::uint64_t n = 0;
    auto edge = [&](long p, long q) {
        const double a = std::min(v.value(p), v.value(q)), b = std::max(v.value(p), v.value(q));
        if (a < s && s <= b && (ld[p] > h || ld[q] > h)) ++n;
    };
    for (long z = 0; z < g.nz; ++z)
        for (long y = 0; y < g.ny; ++y)
            for (long x = 0; x < g.nx; ++x) {
                const long i = g.index(x, y, z);
                if (x + 1 < g.nx) edge(i, g.index(x + 1, y, z));
                if (y + 1 < g.ny) edge(i, g.index(x, y + 1, z));
                if (z + 1 < g.nz) edge(i, g.index(x, y, z + 1));
            }
    return n;
}

std::uint64_t components_bfs(const Volume& v, double iso) {
    const Grid g(v.dims());
    const double s = compared_isovalue(v, iso);
    const std::size_t n = v.vertices();
    std::vector<bool> positive(n), visited(n, false);
    for (std::size_t i = 0; i < n; ++i) positive[i] = v.value(i) >= s;
    std::uint64_t components[2] = {0, 0};  // negative (6-connected), positive (26-connected)
    std::queue<long> queue;
    for (std::size_t start = 0; start < n; ++start) {
        if (visited[start]) continue;
        const bool pos = positive[start];
        ++components[pos];
        visited[start] = true;
        queue.push(long(start));
        while (!queue.empty()) {
            const long c = queue.front();
            queue.pop();
            const long x = c % g.nx, y = (c / g.nx) % g.ny, z = c / (g.nx * g.ny);
            for (long dz = -1; dz <= 1; ++dz)
                for (long dy = -1; dy <= 1; ++dy)
                    for (long dx = -1; dx <= 1; ++dx) {
                        const int steps = (dx != 0) + (dy != 0) + (dz != 0);
                        if (steps == 0 || (!pos && steps > 1) || !g.inside(x + dx, y + dy, z + dz)) continue;
                        const long w = g.index(x + dx, y + dy, z + dz);
                        if (visited[w] || positive[w] != pos) continue;
                        visited[w] = true;
                        queue.push(w);
                    }
        }
    }
    return components[0] && components[1] ? components[0] + components[1] - 1 : 0;
}

}  // namespace ref
