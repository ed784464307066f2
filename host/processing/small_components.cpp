#include "clfractal/small_components.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <type_traits>
#include <vector>

#include "clfractal/error.hpp"
#include "device/name_table.hpp"

namespace clfractal {

template <> struct detail::NameTable<SmallComponentsConnectivity> {
    static constexpr const char* what = "small-components connectivity";
    static constexpr std::pair<SmallComponentsConnectivity, const char*> names[] = {
        {SmallComponentsConnectivity::cube, "cube"}, {SmallComponentsConnectivity::six, "six"}};
};
CLFRACTAL_NAME_TABLE(SmallComponentsConnectivity)

SmallComponentsConnectivity parse_small_components_connectivity(const std::string& name) {
    return parse_variant<SmallComponentsConnectivity>(name);
}

const char* small_components_connectivity_name(SmallComponentsConnectivity c) { return variant_name(c); }

namespace {

// The isovalue in the data's type and the two new values: the largest value of the type
// below it (step 1) and the smallest at or above it (step 2, the isovalue itself).
template <class T> struct Threshold {
    T at_or_above, below;
};

template <class T> Threshold<T> threshold_of(double s, ValueType type) {
    std::ostringstream text;
    text << "small-components filter: isovalue " << s << " ";
    const std::string where = text.str();
    if constexpr (std::is_integral_v<T>) {
        const double c = std::ceil(s);
        if (c <= double(std::numeric_limits<T>::min()))
            throw InputError(where + "leaves no " + value_type_name(type) + " value below it");
        if (c > double(std::numeric_limits<T>::max()))
            throw InputError(where + "leaves no " + value_type_name(type) + " value at or above it");
        return {T(c), T(T(c) - 1)};
    } else {
        const T t = T(s);
        if (!std::isfinite(t))
            throw InputError(where + "is outside the " + std::string(value_type_name(type)) + " range");
        const T below = std::nextafter(t, -std::numeric_limits<T>::infinity());
        if (!std::isfinite(below))
            throw InputError(where + "leaves no finite " + std::string(value_type_name(type)) + " value below it");
        return {t, below};
    }
}

// The runs along x of one set, labelled by union-find: ids 0, 1, ... in raster order (plane
// by plane, row by row, in x within a row); a root holds -(its component's vertices), any
// other run its parent (union by size, path halving).
template <class I> struct RunForest {
    std::vector<I> parent;

    I find(I x) {
        while (parent[std::size_t(x)] >= 0) {
            const I p = parent[std::size_t(x)];
            if (parent[std::size_t(p)] < 0) return p;
            parent[std::size_t(x)] = parent[std::size_t(p)];  // path halving
            x = parent[std::size_t(x)];
        }
        return x;
    }
    void unite(I a, I b) {
        a = find(a);
        b = find(b);
        if (a == b) return;
        if (parent[std::size_t(a)] > parent[std::size_t(b)]) std::swap(a, b);  // a is the larger
        parent[std::size_t(a)] += parent[std::size_t(b)];
        parent[std::size_t(b)] = a;
    }
};

// The members of a row as bytes, 1 in the set.
template <class T, class In> void row_members(const T* row, std::size_t nx, In in, unsigned char* m) {
    for (std::size_t x = 0; x < nx; ++x) m[x] = in(row[x]) ? 1 : 0;
}

// The first x' >= x with m[x'] != side (0 or 1), or nx; eight bytes at a time where the
// first byte of a word is its lowest.
std::size_t next_change(const unsigned char* m, std::size_t x, std::size_t nx, unsigned char side) {
    constexpr bool little_endian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;
    const std::uint64_t fill = side ? 0x0101010101010101ull : 0;
    for (; little_endian && x + 8 <= nx; x += 8) {
        std::uint64_t w;
        std::memcpy(&w, m + x, 8);
        if (w != fill) return x + std::size_t(__builtin_ctzll(w ^ fill)) / 8;  // the first byte that differs
    }
    for (; x < nx; ++x)
        if (m[x] != side) break;
    return x;
}

// run(a, b) for each run [a, b] of the members m[0 .. nx), in increasing x.
template <class F> void for_runs(const unsigned char* m, std::size_t nx, F&& run) {
    for (std::size_t a = next_change(m, 0, nx, 0); a < nx;) {
        const std::size_t b = next_change(m, a, nx, 1);
        run(a, b - 1);
        a = next_change(m, b, nx, 0);
    }
}

// The runs of one plane, row by row: row y is runs[row[y] .. row[y + 1]).
struct PlaneRuns {
    struct Run {
        std::uint32_t a, b;
    };
    std::vector<Run> runs;
    std::vector<std::size_t> row;
};

// The runs of plane z of the set `in` of `f`; `m`: nx bytes of scratch.
template <class T, class In>
void plane_runs(const T* f, const Dims& d, std::size_t z, In in, unsigned char* m, PlaneRuns& p) {
    p.runs.clear();
    p.row.assign(1, 0);
    for (std::size_t y = 0; y < d.ny; ++y) {
        row_members(f + (z * d.ny + y) * d.nx, d.nx, in, m);
        for_runs(m, d.nx, [&](std::size_t a, std::size_t b) { p.runs.push_back({std::uint32_t(a), std::uint32_t(b)}); });
        p.row.push_back(p.runs.size());
    }
}

// Row y of plane p (first id pid) joined to row y + dy of plane q (first id qid): runs that
// hold vertices x of the one and x + dx of the other, |dx| <= reach (0: faces, 1: the cube).
template <class I>
void link_rows(const PlaneRuns& p, I pid, std::size_t y, const PlaneRuns& q, I qid, long dy, std::size_t ny, long reach,
               RunForest<I>& forest) {
    const long yy = long(y) + dy;
    if (yy < 0 || yy >= long(ny)) return;
    std::size_t j = q.row[std::size_t(yy)];
    const std::size_t j_end = q.row[std::size_t(yy) + 1];
    for (std::size_t i = p.row[y]; i < p.row[y + 1]; ++i) {
        const long from = long(p.runs[i].a) - reach, to = long(p.runs[i].b) + reach;
        while (j < j_end && long(q.runs[j].b) < from) ++j;
        for (std::size_t l = j; l < j_end && long(q.runs[l].a) <= to; ++l)
            forest.unite(pid + I(i), qid + I(l));
    }
}

// The plane's rows joined to its earlier rows (dy = -1) and, when `prev` holds the plane
// before, to that plane's rows (dy = 0, and -1 and 1 within the cube).
template <class I>
void link_plane(const PlaneRuns& cur, I cid, const PlaneRuns* prev, I pid, std::size_t ny, int adjacency,
                RunForest<I>& forest) {
    const long reach = adjacency == 26 ? 1 : 0;
    for (std::size_t y = 0; y < ny; ++y) {
        link_rows(cur, cid, y, cur, cid, -1, ny, reach, forest);
        if (!prev) continue;
        for (long dy = -reach; dy <= reach; ++dy) link_rows(cur, cid, y, *prev, pid, dy, ny, reach, forest);
    }
}

// The runs of the set `in` of `f` along x.
template <class T, class In> std::size_t count_runs(const T* f, const Dims& d, In in) {
    std::size_t n = 0;
    for (std::size_t row = 0; row < d.ny * d.nz; ++row) {
        const T* r = f + row * d.nx;
        n += std::size_t(in(r[0]));
        for (std::size_t x = 1; x < d.nx; ++x) n += std::size_t(in(r[x]) & !in(r[x - 1]));
    }
    return n;
}

// Components of {v : in(f[v])} under `adjacency` (6 or 26) by one raster-order pass over
// the runs along x: each run is joined to the runs of the rows before it that it touches
// (the row before in its plane; within the cube, also the rows y - 1 .. y + 1 of the plane
// before, else row y). Two planes of runs are held; the forest has one entry a run.
template <class T, class I, class In>
void label_runs(const T* f, const Dims& d, int adjacency, In in, RunForest<I>& forest) {
    std::vector<unsigned char> m(d.nx);
    PlaneRuns prev, cur;
    forest.parent.clear();
    forest.parent.reserve(count_runs(f, d, in));
    I prev_id = 0;
    for (std::size_t z = 0; z < d.nz; ++z) {
        const I id = I(forest.parent.size());
        plane_runs(f, d, z, in, m.data(), cur);
        // Sizes: each run its own component to begin with.
        for (const PlaneRuns::Run& r : cur.runs) forest.parent.push_back(-I(r.b - r.a + 1));
        link_plane(cur, id, z > 0 ? &prev : nullptr, prev_id, d.ny, adjacency, forest);
        std::swap(prev, cur);
        prev_id = id;
    }
}

// The components of a labelled set, and those with at most k vertices with their vertices.
struct Tally {
    std::size_t components = 0, small = 0, small_vertices = 0;
};

template <class I> Tally tally(const RunForest<I>& forest, std::size_t k) {
    std::size_t components = 0, small = 0, vertices = 0;
    for (const I p : forest.parent) {
        if (p >= 0) continue;
        ++components;
        if (std::size_t(-p) <= k) ++small, vertices += std::size_t(-p);
    }
    return {components, small, vertices};
}

// Sets g to `value` on the runs of the set `in` of `f` whose components have at most k
// vertices (f may be g: each row's members are read before it is written).
template <class T, class I, class In>
void set_small(const T* f, const Dims& d, In in, RunForest<I>& forest, std::size_t k, T* g, T value) {
    std::vector<unsigned char> m(d.nx);
    std::size_t id = 0;
    for (std::size_t row = 0; row < d.ny * d.nz; ++row) {
        const std::size_t at = row * d.nx;
        row_members(f + at, d.nx, in, m.data());
        for_runs(m.data(), d.nx, [&](std::size_t a, std::size_t b) {
            const I r = forest.find(I(id++));
            if (std::size_t(-forest.parent[std::size_t(r)]) <= k) std::fill(g + at + a, g + at + b + 1, value);
        });
    }
}

// The components of the set `in` of `f` (6- or 26-connected); those with at most k vertices
// set to `value` in g, their number in `removed`, their vertices in `set`.
template <class T, class I, class In>
std::size_t remove_small(const T* f, const Dims& d, int adjacency, In in, std::size_t k, T* g, T value,
                         std::size_t& removed, std::size_t& set) {
    RunForest<I> forest;
    label_runs(f, d, adjacency, in, forest);
    const Tally t = tally(forest, k);
    removed = t.small;
    set = t.small_vertices;
    if (g && t.small) set_small(f, d, in, forest, k, g, value);
    return t.components;
}

template <class T, class I>
void filter_typed(const Volume& v, const Threshold<T>& th, std::size_t k, SmallComponentsConnectivity mode,
                  SmallComponentsResult& r) {
    const Dims d = v.dims();
    const T* f = v.as<T>();
    T* g = r.volume.as<T>();
    const T s = th.at_or_above;
    const int positive_adjacency = mode == SmallComponentsConnectivity::cube ? 26 : 6;
    auto at_or_above = [s](T x) { return x >= s; };
    auto below = [s](T x) { return x < s; };
    std::size_t none = 0, ignored = 0;
    // (1) small components of {f >= s} go just below s.
    r.positive_before =
        remove_small<T, I>(f, d, positive_adjacency, at_or_above, k, g, th.below, r.positive_removed, r.lowered);
    // (2) small components of {g < s}, the negative set after (1), go to s.
    const std::size_t negative_after_one = remove_small<T, I>(g, d, 6, below, k, g, s, r.negative_removed, r.raised);
    r.negative_after = negative_after_one - r.negative_removed;
    // The negative set of the input: (1) only added components to it, so count it apart
    // (the same set when (1) changed nothing).
    r.negative_before = r.lowered == 0 ? negative_after_one
                                       : remove_small<T, I>(f, d, 6, below, 0, nullptr, s, none, ignored);
    // The positive set of the result: that of the input when nothing changed.
    r.positive_after = r.lowered == 0 && r.raised == 0
                           ? r.positive_before
                           : remove_small<T, I>(g, d, positive_adjacency, at_or_above, 0, nullptr, s, none, ignored);
}

}  // namespace

SmallComponentsResult small_components_filter(const Volume& v, double iso, std::size_t k,
                                              SmallComponentsConnectivity mode) {
    if (!std::isfinite(iso)) throw InputError("small-components filter: the isovalue must be finite");
    check_finite(v, v.name.empty() ? "small-components filter" : v.name);
    const auto t0 = std::chrono::steady_clock::now();
    SmallComponentsResult r;
    r.volume = v;
    visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        const Threshold<T> th = threshold_of<T>(iso, v.type());
        r.isovalue = double(th.at_or_above);
        r.lowered_value = double(th.below);
        r.raised_value = double(th.at_or_above);
        if (v.vertices() < (std::size_t(1) << 31)) filter_typed<T, std::int32_t>(v, th, k, mode, r);
        else filter_typed<T, std::int64_t>(v, th, k, mode, r);
    });
    visit(r.volume, [&](const auto* g) {
        const auto* f = v.as<std::remove_const_t<std::remove_pointer_t<decltype(g)>>>();
        for (std::size_t i = 0; i < v.vertices(); ++i) r.changed += g[i] != f[i];
    });
    r.changed_share = v.vertices() ? double(r.changed) / double(v.vertices()) : 0.0;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

}  // namespace clfractal
