// components(s) at a few isovalues by direct labelling (clfractal/components.hpp,
// count_components_at): A = {f < s} and C = {f >= s} as runs along x, joined by union-find
// plane by plane. The grid is cut into z-chunks labelled in parallel, each keeping the runs of
// its first and of its current plane only (memory O(slice)); the chunks are then joined at
// their seams. b0 of a set = runs - unions that joined two components.
#include "clfractal/components.hpp"
#include "clfractal/error.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <type_traits>

namespace clfractal {

namespace {

// A run [a, b] of one set along x, and its label.
struct Run {
    std::uint32_t a, b, id;
};

// The runs of one plane, row by row: row y is runs[row[y], row[y + 1]).
struct PlaneRuns {
    std::vector<Run> runs;
    std::vector<std::size_t> row;
    void clear() {
        runs.clear();
        row.assign(1, 0);
    }
};

// An earlier row (dy, dz) whose vertices x + lo .. x + hi neighbour vertex x (dz = 0: the same
// plane, dy = -1), from the neighbourhood of the set: 6 (faces), 26 (the cube), 14 (the
// Freudenthal edges: offsets whose signs do not mix).
struct RowLink {
    int dy, dz, lo, hi;
};

std::vector<RowLink> row_links(int adjacency) {
    std::vector<RowLink> links;
    for (int dz = -1; dz <= 0; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
            if (dz == 0 && dy >= 0) continue;
            int lo = 2, hi = -2;
            for (int dx = -1; dx <= 1; ++dx) {
                const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
                const bool mixed = std::min({dx, dy, dz}) < 0 && std::max({dx, dy, dz}) > 0;
                const bool keep = adjacency == 6 ? n == 1 : adjacency == 26 ? true : !mixed;
                if (keep) lo = std::min(lo, dx), hi = std::max(hi, dx);
            }
            if (lo <= hi) links.push_back({dy, dz, lo, hi});
        }
    return links;
}

// Union-find with path halving; the smaller label is the root.
class Forest {
public:
    std::uint32_t add() {
        parent_.push_back(std::uint32_t(parent_.size()));
        return parent_.back();
    }
    std::uint32_t find(std::uint32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    // Whether a and b were apart.
    bool unite(std::uint32_t a, std::uint32_t b) {
        a = find(a), b = find(b);
        if (a == b) return false;
        if (a < b) std::swap(a, b);
        parent_[a] = b;
        return true;
    }
    void reset(std::size_t n) {
        parent_.resize(n);
        std::iota(parent_.begin(), parent_.end(), std::uint32_t(0));
    }
    std::size_t size() const { return parent_.size(); }

private:
    std::vector<std::uint32_t> parent_;
};

// Joins each run of `cur` to the runs of `other` it neighbours (x + lo .. x + hi); returns
// the number of unions that joined two components. Both lists are in increasing x.
std::int64_t link_rows(const Run* cur, std::size_t n, const Run* other, std::size_t m, int lo, int hi,
                       Forest& forest) {
    std::int64_t unions = 0;
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::int64_t from = std::int64_t(cur[i].a) + lo, to = std::int64_t(cur[i].b) + hi;
        while (j < m && std::int64_t(other[j].b) < from) ++j;
        for (std::size_t k = j; k < m && std::int64_t(other[k].a) <= to; ++k)
            unions += forest.unite(cur[i].id, other[k].id);
    }
    return unions;
}

// Row y of plane `p` joined to row y + dy of plane `q` (the same plane or the one before).
std::int64_t link_row(const PlaneRuns& p, std::size_t y, const PlaneRuns& q, const RowLink& l, std::size_t ny,
                      Forest& forest) {
    const std::int64_t yy = std::int64_t(y) + l.dy;
    if (yy < 0 || yy >= std::int64_t(ny)) return 0;
    const Run* cur = p.runs.data() + p.row[y];
    const Run* other = q.runs.data() + q.row[std::size_t(yy)];
    return link_rows(cur, p.row[y + 1] - p.row[y], other, q.row[std::size_t(yy) + 1] - q.row[std::size_t(yy)], l.lo,
                     l.hi, forest);
}

// One set's labelling over a chunk of planes: the forest, the first and the current plane.
struct SetChunk {
    std::vector<RowLink> links;
    Forest forest;
    PlaneRuns first, prev, cur;
    std::int64_t b0 = 0;  ///< runs - joining unions within the chunk
    std::vector<std::uint32_t> relabel;

    explicit SetChunk(int adjacency) : links(row_links(adjacency)) {
        first.clear();
        prev.clear();
        cur.clear();
    }
    void add_run(std::uint32_t a, std::uint32_t b) {
        cur.runs.push_back({a, b, forest.add()});
        ++b0;
    }
    // Row y of the current plane is complete: join it to the earlier rows.
    void end_row(std::size_t y, std::size_t ny, bool has_prev) {
        cur.row.push_back(cur.runs.size());
        for (const RowLink& l : links)
            if (l.dz == 0 || has_prev) b0 -= link_row(cur, y, l.dz == 0 ? cur : prev, l, ny, forest);
    }
    // The plane is complete: keep labels of the first and the current plane only, renumbered
    // 0.. by component.
    void end_plane(bool is_first) {
        if (is_first) first = cur;
        relabel.assign(forest.size(), UINT32_MAX);
        std::uint32_t next = 0;
        auto renumber = [&](PlaneRuns& p) {
            for (Run& r : p.runs) {
                std::uint32_t& to = relabel[forest.find(r.id)];
                if (to == UINT32_MAX) to = next++;
                r.id = to;
            }
        };
        renumber(first);
        renumber(cur);
        forest.reset(next);
        std::swap(prev, cur);
        cur.clear();
    }
};

// The runs of one row into A (less) and C. Blocks of 32 vertices all on the side of the
// current run are passed over with one count (vectorised); the others vertex by vertex.
template <class T, class Less>
void row_runs(const T* row, std::size_t nx, Less less, SetChunk& a, SetChunk& c) {
    constexpr std::size_t block = 32;
    bool in = less(row[0]);
    std::size_t s = 0, x = 1;
    while (x < nx) {
        if (x + block <= nx) {
            unsigned n = 0;
            for (std::size_t i = 0; i < block; ++i) n += less(row[x + i]);
            if (n == (in ? block : 0)) {
                x += block;
                continue;
            }
        }
        for (const std::size_t end = std::min(nx, x + block); x < end; ++x) {
            const bool b = less(row[x]);
            if (b == in) continue;
            (in ? a : c).add_run(std::uint32_t(s), std::uint32_t(x - 1));
            s = x;
            in = b;
        }
    }
    (in ? a : c).add_run(std::uint32_t(s), std::uint32_t(nx - 1));
}

struct ChunkResult {
    std::int64_t b0[2] = {0, 0};
    PlaneRuns first[2], last[2];  ///< labels: components of the chunk, 0..labels-1
    std::uint32_t labels[2] = {0, 0};
};

template <class T, class Less>
ChunkResult label_chunk(const T* f, const Dims& d, std::size_t z0, std::size_t z1, Less less, int a_adj, int c_adj) {
    SetChunk a(a_adj), c(c_adj);
    for (std::size_t z = z0; z < z1; ++z) {
        for (std::size_t y = 0; y < d.ny; ++y) {
            row_runs(f + (z * d.ny + y) * d.nx, d.nx, less, a, c);
            a.end_row(y, d.ny, z > z0);
            c.end_row(y, d.ny, z > z0);
        }
        a.end_plane(z == z0);
        c.end_plane(z == z0);
    }
    ChunkResult r;
    SetChunk* sets[2] = {&a, &c};
    for (int s = 0; s < 2; ++s) {
        r.b0[s] = sets[s]->b0;
        r.first[s] = std::move(sets[s]->first);
        r.last[s] = std::move(sets[s]->prev);
        r.labels[s] = std::uint32_t(sets[s]->forest.size());
    }
    return r;
}

// b0 of set s over the whole grid: the chunks' b0 less the unions their seams make.
std::int64_t join_chunks(const std::vector<ChunkResult>& chunks, int s, int adjacency, std::size_t ny) {
    std::vector<std::uint32_t> base(chunks.size() + 1, 0);
    for (std::size_t t = 0; t < chunks.size(); ++t) base[t + 1] = base[t] + chunks[t].labels[s];
    Forest forest;
    forest.reset(base.back());
    std::int64_t b0 = 0;
    for (const ChunkResult& c : chunks) b0 += c.b0[s];
    // Each chunk's seam planes with global labels.
    auto global = [&](PlaneRuns p, std::size_t t) {
        for (Run& r : p.runs) r.id += base[t];
        return p;
    };
    const std::vector<RowLink> links = row_links(adjacency);
    for (std::size_t t = 1; t < chunks.size(); ++t) {
        const PlaneRuns p = global(chunks[t].first[s], t), q = global(chunks[t - 1].last[s], t - 1);
        for (std::size_t y = 0; y < ny; ++y)
            for (const RowLink& l : links)
                if (l.dz == -1) b0 -= link_row(p, y, q, l, ny, forest);
    }
    return b0;
}

template <class T, class Less> std::int64_t components_with(const Volume& v, Less less, Connectivity mode) {
    const Dims d = v.dims();
    const int a_adj = mode == Connectivity::cube ? 6 : 14, c_adj = mode == Connectivity::cube ? 26 : 14;
    const std::size_t chunks = std::min<std::size_t>(d.nz, 2 * std::size_t(omp_get_max_threads()));
    std::vector<ChunkResult> r(chunks);
    const T* f = v.as<T>();
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t t = 0; t < chunks; ++t)
        r[t] = label_chunk<T>(f, d, d.nz * t / chunks, d.nz * (t + 1) / chunks, less, a_adj, c_adj);
    const std::int64_t a = join_chunks(r, 0, a_adj, d.ny), c = join_chunks(r, 1, c_adj, d.ny);
    return a > 0 && c > 0 ? a + c - 1 : 0;
}

// A = {f < s} compared as count_components compares (IsovalueSet::single(type, s)): integer
// data f < ceil(s), float data f < s in the data's type (the set holds s in that type), each
// as one comparison in the data's own type.
template <class T> std::int64_t components_at(const Volume& v, double isovalue, Connectivity mode) {
    const IsovalueSet iso = IsovalueSet::single(v.type(), isovalue);
    if constexpr (std::is_integral_v<T>) {
        const std::int64_t c = iso.first();
        if (sizeof(T) < 8 || std::is_signed_v<T>) {
            // Every value, or none, below c: A or C is the whole grid.
            if (c > std::int64_t(std::numeric_limits<T>::max()) || c <= std::int64_t(std::numeric_limits<T>::min()))
                return 0;
            const T t = T(c);
            return components_with<T>(v, [t](T x) { return x < t; }, mode);
        }
        return components_with<T>(v, [c](T x) { return std::int64_t(x) < c; }, mode);
    } else {
        const T t = T(iso.list().front());
        return components_with<T>(v, [t](T x) { return x < t; }, mode);
    }
}

}  // namespace

std::vector<std::int64_t> count_components_at(const Volume& v, const std::vector<double>& isovalues,
                                              Connectivity mode) {
    for (double s : isovalues)
        if (!std::isfinite(s)) throw InputError("isovalue must be finite");
    std::vector<std::int64_t> out;
    const Dims d = v.dims();
    if (v.vertices() == 0) return std::vector<std::int64_t>(isovalues.size(), 0);
    if (d.nx >= (std::size_t(1) << 31) || d.nx * d.ny >= (std::size_t(1) << 30))
        throw InputError("components at an isovalue: at most 2^30 vertices a slice");
    for (double s : isovalues)
        out.push_back(visit(v, [&](const auto* p) {
            using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
            return components_at<T>(v, s, mode);
        }));
    return out;
}

}  // namespace clfractal
