// components(s) at a few isovalues by direct labelling (clfractal/components.hpp,
// count_components_at): A = {f < s} and C = {f >= s} as runs along x, joined by union-find
// plane by plane. The runs of A and C alternate along a row and cover it, so a row is kept as
// bit masks (which vertices are in A, where the set changes) and one label a run; two rows'
// neighbouring runs of both sets are found with bit operations on their masks, 64 vertices at
// a time. The grid is cut into z-chunks labelled in parallel, each keeping the runs of its
// first and of its current plane only (memory O(slice)); the chunks are then joined at their
// seams. b0 of a set = its runs - the unions that joined two of its components.
#include "clfractal/components.hpp"
#include "measures/components_slab.hpp"
#include "clfractal/error.hpp"
#include "measures/row_mask.hpp"
#include "measures/target_clones.hpp"
#include "volume/below.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <numeric>
#include <optional>
#include <type_traits>
#include <vector>


namespace clfractal {

namespace {

constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

// The runs of one plane, row by row, with `words` 64-bit words a row. Bit b of word w of row
// y is vertex x = 64 w + b: in[] whether it is in A (0 beyond nx), change[] whether its set
// differs from that of x - 1 (0 at x = 0). Each change begins a run, so the runs of a row
// alternate between A (set 0) and C (set 1); run k of row y has label id[row[y] + k], and the
// run holding x is id[base[w] + ones(change bits 0..b of word w)] (base: row[y] + the changes
// in the row's earlier words).
struct PlaneRuns {
    std::size_t words = 0;
    std::vector<std::uint64_t> in, change;
    std::vector<std::uint32_t> base, id, row;
    void clear() {
        in.clear(), change.clear(), base.clear(), id.clear();
        row.assign(1, 0);
    }
    std::size_t rows() const { return row.size() - 1; }
};

// The number of bits set. x86-64 has had an instruction for it since 2008 but not in its
// baseline, so on x86-64 the functions that count (link_rows, index_row) are also compiled
// for it and chosen at load time (LINK_CLONES, target_clones.hpp); elsewhere the compiler's
// builtin serves.
inline unsigned ones(std::uint64_t x) { return unsigned(__builtin_popcountll(x)); }
#if !defined(__POPCNT__)
#define LINK_CLONES CLFRACTAL_CLONES("popcnt")
#else
#define LINK_CLONES
#endif

// The index in `id` of the run holding bit b of a word whose changes are `change` (see PlaneRuns).
inline std::uint32_t run_at(std::uint64_t change, std::uint32_t base, unsigned b) {
    return base + ones(change << (63 - b));
}

// The neighbours of a run of one set in an earlier row: the runs of the set that overlap it in x
// (on), and those that begin one past its end (hi: dx = +1) or end one before its start (lo:
// dx = -1).
struct SetLink {
    bool on = false, lo = false, hi = false;
};

// An earlier row (dy, dz) (dz = 0: the same plane, dy = -1) and how each set's runs neighbour
// runs there, from the set's neighbourhood: 6 (faces), 26 (the cube), 14 (the Freudenthal
// edges: offsets whose signs do not mix).
struct RowLink {
    int dy, dz;
    SetLink set[2];
};

SetLink set_link(int adjacency, int dy, int dz) {
    SetLink l;
    for (int dx = -1; dx <= 1; ++dx) {
        const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
        const bool mixed = std::min({dx, dy, dz}) < 0 && std::max({dx, dy, dz}) > 0;
        if (!(adjacency == 6 ? n == 1 : adjacency == 26 ? true : !mixed)) continue;
        (dx < 0 ? l.lo : dx > 0 ? l.hi : l.on) = true;
    }
    return l;
}

std::vector<RowLink> row_links(int a_adjacency, int c_adjacency) {
    std::vector<RowLink> links;
    for (int dz = -1; dz <= 0; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
            if (dz == 0 && dy >= 0) continue;
            const RowLink l{dy, dz, {set_link(a_adjacency, dy, dz), set_link(c_adjacency, dy, dz)}};
            if (l.set[0].on || l.set[1].on || l.set[0].lo || l.set[1].lo || l.set[0].hi || l.set[1].hi)
                links.push_back(l);
        }
    return links;
}

// Union-find with path halving; the smaller label is the root, so a component's root is its
// smallest label.
class Forest {
public:
    void room(std::size_t n) {
        if (size_ + n > parent_.size()) parent_.resize(std::max(2 * parent_.size(), size_ + n));
    }
    std::uint32_t find(std::uint32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    // Joins two roots (or one root with itself); returns the root of the whole.
    std::uint32_t link(std::uint32_t a, std::uint32_t b) {
        // min and max by masks: compilers tend to branch on a < b, which is hard to predict.
        const std::uint32_t lo = b ^ ((a ^ b) & (std::uint32_t(0) - std::uint32_t(a < b)));
        parent_[a ^ b ^ lo] = lo;
        return lo;
    }
    // Labels n more runs, first.. first + n - 1; returns first.
    std::uint32_t add(std::size_t n) {
        room(n);
        std::iota(parent_.begin() + std::ptrdiff_t(size_), parent_.begin() + std::ptrdiff_t(size_ + n),
                  std::uint32_t(size_));
        size_ += n;
        return std::uint32_t(size_ - n);
    }
    // Keeps labels 0..keep-1 as they are and makes keep..n-1 roots of their own.
    void truncate(std::size_t keep, std::size_t n) {
        room(n > size_ ? n - size_ : 0);
        std::iota(parent_.begin() + std::ptrdiff_t(keep), parent_.begin() + std::ptrdiff_t(n), std::uint32_t(keep));
        size_ = n;
    }
    std::size_t size() const { return size_; }

private:
    std::vector<std::uint32_t> parent_;
    std::size_t size_ = 0;
};

// Joins the components of two neighbouring runs whose labels are `c` and `o`, each replaced
// by the root; returns 1 when two components became one. Free of branches but for the finds
// (mostly one step: labels are kept at their roots), since whether the two were apart is
// seldom predictable.
inline int join(std::uint32_t& c, std::uint32_t& o, Forest& forest) {
    const std::uint32_t a = forest.find(c), b = forest.find(o);
    c = o = forest.link(a, b);
    return a != b;
}

// All ones when `b`, else 0.
inline std::uint64_t all(bool b) { return std::uint64_t(0) - std::uint64_t(b); }

// Joins the runs of row y of plane `p` to the runs of an earlier row (row yy of plane `q`) that
// neighbour them under `l`; adds to merges[s] the unions that joined two components of set s.
// Word by word: a pair of runs of one set that overlap in x begins where both rows are in the
// set and were not both at x - 1 (each pair once, the rows' runs partitioning the same x range);
// where both rows change at x into different sets, the run ending at x - 1 in one row and the
// run beginning at x in the other are of one set and meet diagonally.
LINK_CLONES void link_rows(PlaneRuns& p, std::size_t y, PlaneRuns& q, std::size_t yy, const RowLink& l,
                           std::size_t nx, Forest& forest, std::int64_t merges[2]) {
    const std::uint64_t on_a = all(l.set[0].on), on_c = all(l.set[1].on), lo_a = all(l.set[0].lo),
                        lo_c = all(l.set[1].lo), hi_a = all(l.set[0].hi), hi_c = all(l.set[1].hi);
    const std::size_t wp = y * p.words, wq = yy * q.words;
    std::uint32_t* const pid = p.id.data();
    std::uint32_t* const qid = q.id.data();
    // Rows of one run each (no change in either: most rows of most scans) overlap over the
    // whole row and meet only when of one set: one join instead of a pass over their words.
    if (p.row[y + 1] - p.row[y] == 1 && q.row[yy + 1] - q.row[yy] == 1) {
        const unsigned s = p.in[wp] & 1 ? 0 : 1;
        if (s == (q.in[wq] & 1 ? 0u : 1u) && l.set[s].on) merges[s] += join(pid[p.row[y]], qid[q.row[yy]], forest);
        return;
    }
    std::uint64_t both_a_before = 0, both_c_before = 0;
    for (std::size_t w = 0; w < p.words; ++w) {
        const std::uint64_t tp = p.change[wp + w], tq = q.change[wq + w];
        // Neither row changes set in this word (nor at its first bit): both continue the runs
        // of the word before, so no pair of runs begins or meets here, and the sets at bit 63
        // are those at the last bit of the word before. Most words of most scans.
        if ((tp | tq) == 0 && w > 0) continue;
        const std::uint64_t mp = p.in[wp + w], mq = q.in[wq + w];
        const std::uint32_t bp = p.base[wp + w], bq = q.base[wq + w];
        const std::uint64_t valid = nx - 64 * w >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << (nx - 64 * w)) - 1;
        const std::uint64_t both_a = mp & mq & on_a, both_c = ~mp & ~mq & valid & on_c;
        std::uint64_t starts = (both_a & ~(both_a << 1 | both_a_before)) | (both_c & ~(both_c << 1 | both_c_before));
        both_a_before = both_a >> 63, both_c_before = both_c >> 63;
        const std::uint64_t diagonal = tp & tq & (mp ^ mq);
        // hi: p's run ending at x - 1 meets q's run beginning at x (dx = +1), of q's set at x;
        // lo: p's run beginning at x meets q's run ending at x - 1 (dx = -1), of p's set at x.
        std::uint64_t hi = diagonal & ((mq & hi_a) | (~mq & hi_c)), lo = diagonal & ((mp & lo_a) | (~mp & lo_c));
        for (; starts; starts &= starts - 1) {
            const unsigned b = unsigned(__builtin_ctzll(starts));
            merges[~mp >> b & 1] += join(pid[run_at(tp, bp, b)], qid[run_at(tq, bq, b)], forest);
        }
        for (; hi; hi &= hi - 1) {
            const unsigned b = unsigned(__builtin_ctzll(hi));
            merges[~mq >> b & 1] += join(pid[run_at(tp, bp, b) - 1], qid[run_at(tq, bq, b)], forest);
        }
        for (; lo; lo &= lo - 1) {
            const unsigned b = unsigned(__builtin_ctzll(lo));
            merges[~mp >> b & 1] += join(pid[run_at(tp, bp, b)], qid[run_at(tq, bq, b) - 1], forest);
        }
    }
}

// The run index bases of the row whose masks were appended last to `p`, and room for its
// runs' labels.
LINK_CLONES void index_row(PlaneRuns& p) {
    std::uint32_t runs = p.row.back();
    for (std::size_t w = p.base.size(); w < p.change.size(); ++w) {
        p.base.push_back(runs);
        runs += ones(p.change[w]);
    }
    ++runs;  // the row's first run
    p.row.push_back(runs);
    p.id.resize(runs);
}

// Appends one row of the volume to plane `p`: its masks, and room for its runs' labels.
template <class T, class Less> void row_runs(const T* row, std::size_t nx, Less less, PlaneRuns& p) {
    std::uint64_t before = less(row[0]);  // whether vertex x0 - 1 is in A; at x0 = 0, no change
    for (std::size_t x0 = 0; x0 < nx; x0 += 64) {
        const std::size_t n = std::min<std::size_t>(64, nx - x0);
        const std::uint64_t m = row_mask(row + x0, n, less);
        std::uint64_t change = m ^ (m << 1 | before);
        if (n < 64) change &= (std::uint64_t(1) << n) - 1;
        before = m >> 63;
        p.in.push_back(m);
        p.change.push_back(change);
    }
    index_row(p);
}

// Row y of plane `p` joined to row y + dy of plane `q` (the same plane or the one before).
void link_row(PlaneRuns& p, std::size_t y, PlaneRuns& q, const RowLink& l, std::size_t nx, Forest& forest,
              std::int64_t merges[2]) {
    const std::int64_t yy = std::int64_t(y) + l.dy;
    if (yy >= 0 && yy < std::int64_t(q.rows())) link_rows(p, y, q, std::size_t(yy), l, nx, forest, merges);
}

// The labelling of both sets over a chunk of planes: one forest, the first, the previous and
// the current plane.
struct Chunk {
    std::vector<RowLink> links;
    std::size_t nx;
    Forest forest;
    PlaneRuns first, prev, cur;
    std::int64_t b0[2] = {0, 0};  ///< runs - joining unions within the chunk, by set
    std::uint32_t first_labels = 0;
    std::vector<std::uint32_t> relabel;

    Chunk(const std::vector<RowLink>& l, std::size_t nx_) : links(l), nx(nx_) {
        for (PlaneRuns* p : {&first, &prev, &cur}) p->words = (nx + 63) / 64, p->clear();
    }
    // Row y of the current plane is scanned: label its runs, then join them to the earlier rows.
    void end_row(std::size_t y, bool has_prev) {
        const std::uint32_t k0 = cur.row[y], n = cur.row[y + 1] - k0;
        std::iota(cur.id.begin() + k0, cur.id.begin() + k0 + n, forest.add(n));
        const unsigned s = cur.in[y * cur.words] & 1 ? 0 : 1;  // the set of the row's first run
        b0[s] += (n + 1) / 2, b0[s ^ 1] += n / 2;
        std::int64_t merges[2] = {0, 0};
        for (const RowLink& l : links)
            if (l.dz == 0 || has_prev) link_row(cur, y, l.dz == 0 ? cur : prev, l, nx, forest, merges);
        b0[0] -= merges[0], b0[1] -= merges[1];
    }
    // The plane is complete. The first plane's components become labels 0..F-1 and keep them
    // (its runs are needed at the seams); a later component holding one of them has its root
    // among them (the smallest label). Each later plane's runs are renumbered F.. by component
    // and the labels beyond dropped, so the forest holds O(slice) labels.
    void end_plane(bool is_first) {
        const std::uint32_t keep = is_first ? 0 : first_labels;
        relabel.assign(forest.size() - keep, none);
        std::uint32_t next = keep;
        for (std::uint32_t& id : cur.id) {
            std::uint32_t root = forest.find(id);
            if (root >= keep) {
                std::uint32_t& to = relabel[root - keep];
                if (to == none) to = next++;
                root = to;
            }
            id = root;
        }
        forest.truncate(keep, next);
        if (is_first) first_labels = next, first = cur;
        std::swap(prev, cur);
        cur.clear();
    }
};

struct ChunkResult {
    std::int64_t b0[2] = {0, 0};
    PlaneRuns first, last;  ///< labels: components of the chunk, 0..labels-1
    std::uint32_t labels = 0;
};

// The labelling of the planes [z0, z1) at several isovalues (`below`, one an isovalue) in one
// pass: each row is read once and labelled at every isovalue while it is in the cache (a pass
// an isovalue read the volume that many times from memory).
template <class T, class Less>
std::vector<ChunkResult> label_chunk(const T* f, const Dims& d, std::size_t z0, std::size_t z1,
                                     const std::vector<Less>& below, const std::vector<RowLink>& links) {
    std::vector<Chunk> c;
    c.reserve(below.size());
    for (std::size_t k = 0; k < below.size(); ++k) c.emplace_back(links, d.nx);
    for (std::size_t z = z0; z < z1; ++z) {
        for (std::size_t y = 0; y < d.ny; ++y) {
            const T* row = f + (z * d.ny + y) * d.nx;
            for (std::size_t k = 0; k < below.size(); ++k) {
                row_runs(row, d.nx, below[k], c[k].cur);
                c[k].end_row(y, z > z0);
            }
        }
        for (Chunk& ck : c) ck.end_plane(z == z0);
    }
    std::vector<ChunkResult> out(c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
        ChunkResult& r = out[k];
        r.b0[0] = c[k].b0[0], r.b0[1] = c[k].b0[1];
        // The first plane's labels to their roots (the last plane's are roots already).
        for (std::uint32_t& id : c[k].first.id) id = c[k].forest.find(id);
        r.first = std::move(c[k].first);
        r.last = std::move(c[k].prev);
        r.labels = std::uint32_t(c[k].forest.size());
    }
    return out;
}

// The labelling of the planes so far, for joining more after them: b0 of both sets, and the
// last plane with the labels of its components, 0..labels-1.
struct Prefix {
    std::int64_t b0[2] = {0, 0};
    PlaneRuns last;
    std::uint32_t labels = 0;
    bool any = false;
};

// Extends `p` by chunks of the planes that follow it (consecutive z-ranges, in order): their
// b0 less the unions their seams make (with `p`'s last plane and with each other), and the
// last chunk's last plane relabelled by the components of the whole.
void extend(Prefix& p, std::vector<ChunkResult>& chunks, const std::vector<RowLink>& links, std::size_t nx,
            std::size_t ny) {
    if (chunks.empty()) return;
    if (p.any) {
        ChunkResult front;
        front.first = front.last = std::move(p.last);
        front.labels = p.labels;
        chunks.insert(chunks.begin(), std::move(front));
    }
    std::vector<std::uint32_t> base(chunks.size() + 1, 0);
    std::uint64_t labels = 0;  // the chunks' labels side by side must stay below `none`
    for (std::size_t t = 0; t < chunks.size(); ++t) {
        labels += chunks[t].labels;
        if (labels >= none) throw InputError("components at an isovalue: more than 2^32 - 1 runs at the seams of a batch");
        base[t + 1] = std::uint32_t(labels);
    }
    Forest forest;
    forest.truncate(0, base.back());
    std::int64_t merges[2] = {0, 0};
    for (std::size_t t = 0; t < chunks.size(); ++t)  // the seam planes with labels of the whole
        for (PlaneRuns* q : {&chunks[t].first, &chunks[t].last})
            for (std::uint32_t& id : q->id) id += base[t];
    for (std::size_t t = 1; t < chunks.size(); ++t)
        for (std::size_t y = 0; y < ny; ++y)
            for (const RowLink& l : links)
                if (l.dz == -1) link_row(chunks[t].first, y, chunks[t - 1].last, l, nx, forest, merges);
    p.b0[0] -= merges[0], p.b0[1] -= merges[1];
    for (const ChunkResult& c : chunks) p.b0[0] += c.b0[0], p.b0[1] += c.b0[1];
    // The last plane's components, numbered 0.. in order of appearance.
    std::vector<std::uint32_t> relabel(base.back(), none);
    p.labels = 0;
    p.last = std::move(chunks.back().last);
    for (std::uint32_t& id : p.last.id) {
        std::uint32_t& to = relabel[forest.find(id)];
        if (to == none) to = p.labels++;
        id = to;
    }
    p.any = true;
}

std::int64_t components_of(const Prefix& p) { return p.b0[0] > 0 && p.b0[1] > 0 ? p.b0[0] + p.b0[1] - 1 : 0; }

// A = {f < s}: detail::below (volume/below.hpp).
using detail::Below;
using detail::below;

// The components of both sets at every isovalue, so far: `prefix` (one an isovalue) extended by
// the planes [0, d.nz) of `f`, cut into z-chunks labelled on every core, each chunk at up to
// `together` isovalues in one pass over its rows.
template <class T>
void label_planes(const T* f, const Dims& d, ValueType type, const std::vector<double>& isovalues,
                  const std::vector<RowLink>& links, std::vector<Prefix>& prefix) {
    constexpr std::size_t together = 8;  // bounds the labellings a thread keeps at once
    const std::size_t n = isovalues.size();
    const std::size_t chunks = std::min<std::size_t>(d.nz, 2 * std::size_t(omp_get_max_threads()));
    // The isovalues with a surface (A and C both possible), in groups labelled together.
    std::vector<std::size_t> cut;  // indices into isovalues
    std::vector<Below<T>> compare;
    for (std::size_t j = 0; j < n; ++j)
        if (const auto b = below<T>(type, isovalues[j])) cut.push_back(j), compare.push_back(*b);
    const std::size_t groups = (cut.size() + together - 1) / together;
    std::vector<std::vector<ChunkResult>> r(cut.size(), std::vector<ChunkResult>(chunks));
    // An exception cannot leave the parallel loop (the process would end): the first is
    // kept and thrown after it (host memory running out).
    std::exception_ptr failed;
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t k = 0; k < groups * chunks; ++k) {
        const std::size_t g = k / chunks, t = k % chunks;
        const std::size_t j0 = g * together, j1 = std::min(cut.size(), j0 + together);
        try {
            const std::vector<Below<T>> these(compare.begin() + std::ptrdiff_t(j0), compare.begin() + std::ptrdiff_t(j1));
            std::vector<ChunkResult> done = label_chunk<T>(f, d, d.nz * t / chunks, d.nz * (t + 1) / chunks, these, links);
            for (std::size_t i = 0; i < done.size(); ++i) r[j0 + i][t] = std::move(done[i]);
        } catch (...) {
#pragma omp critical(components_at_failure)
            if (!failed) failed = std::current_exception();
        }
    }
    if (failed) std::rethrow_exception(failed);
    for (std::size_t i = 0; i < cut.size(); ++i) extend(prefix[cut[i]], r[i], links, d.nx, d.ny);
}

std::vector<RowLink> links_of(Connectivity mode) {
    return mode == Connectivity::cube ? row_links(6, 26) : row_links(14, 14);
}

void check_slice(std::size_t nx, std::size_t ny) {
    // (Each axis first, so that nx * ny cannot wrap.)
    constexpr std::size_t most = std::size_t(1) << 30;
    if (nx >= most || ny >= most || nx * ny >= most)
        throw InputError("components at an isovalue: at most 2^30 vertices a slice");
}

}  // namespace

void check_isovalues(const std::vector<double>& isovalues) {
    for (double s : isovalues)
        if (!std::isfinite(s)) throw InputError("isovalue must be finite");
}

std::vector<std::int64_t> count_components_at(const Volume& v, const std::vector<double>& isovalues,
                                              Connectivity mode) {
    check_isovalues(isovalues);
    const Dims d = v.dims();
    if (v.vertices() == 0) return std::vector<std::int64_t>(isovalues.size(), 0);
    check_slice(d.nx, d.ny);
    std::vector<Prefix> prefix(isovalues.size());
    visit(v, [&](const auto* f) { label_planes(f, d, v.type(), isovalues, links_of(mode), prefix); });
    std::vector<std::int64_t> out;
    for (const Prefix& p : prefix) out.push_back(components_of(p));
    return out;
}

struct ComponentsAtStream::Impl {
    std::size_t nx = 0, ny = 0, nz = 0;
    ValueType type = ValueType::uint8;
    std::vector<RowLink> links;
    std::vector<double> isovalues;
    std::vector<Prefix> prefix;  ///< one an isovalue
};

ComponentsAtStream::ComponentsAtStream(std::size_t nx, std::size_t ny, ValueType type,
                                       const std::vector<double>& isovalues, Connectivity mode)
    : impl_(std::make_unique<Impl>()) {
    check_isovalues(isovalues);
    if (nx == 0 || ny == 0) throw InputError("components stream: slices of no vertex");
    check_slice(nx, ny);
    impl_->nx = nx, impl_->ny = ny, impl_->type = type;
    impl_->links = links_of(mode);
    impl_->isovalues = isovalues;
    impl_->prefix.resize(isovalues.size());
}

ComponentsAtStream::~ComponentsAtStream() = default;
ComponentsAtStream::ComponentsAtStream(ComponentsAtStream&&) noexcept = default;
ComponentsAtStream& ComponentsAtStream::operator=(ComponentsAtStream&&) noexcept = default;

void ComponentsAtStream::push_slices(const void* slices, std::size_t count) {
    if (count == 0) return;
    Impl& m = *impl_;
    if (!slices) throw InputError("components stream: no slices (NULL)");
    check_finite(slices, m.type, m.nx * m.ny * count, Dims{m.nx, m.ny, m.nz + count}, m.nz * m.nx * m.ny,
                 "components stream");
    visit_type(m.type, [&](auto zero) {
        label_planes(static_cast<const decltype(zero)*>(slices), Dims{m.nx, m.ny, count}, m.type, m.isovalues,
                     m.links, m.prefix);
    });
    m.nz += count;
}

std::size_t ComponentsAtStream::slices() const { return impl_->nz; }

std::vector<std::int64_t> ComponentsAtStream::counts() const {
    std::vector<std::int64_t> out;
    for (const Prefix& p : impl_->prefix) out.push_back(components_of(p));
    return out;
}

}  // namespace clfractal
