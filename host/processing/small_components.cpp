#include "clfractal/small_components.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
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

// A union-find forest over the vertices, union by size: a root holds -(its component's
// size), any other member its parent.
template <class I> struct Forest {
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

// Components of {v : in(v)} under `adjacency` (6 or 26) by one raster-order pass: each member
// joins its members among the neighbours already passed (offsets before it in x-fastest
// order). Returns the number of components; `small(v)` is called for every member of a
// component with at most k vertices, and `small_count` gets their number.
template <class I, class In, class Small>
std::size_t label(const Dims& d, int adjacency, In&& in, std::size_t k, Forest<I>& forest, Small&& small,
                  std::size_t& small_count) {
    struct Offset {
        int dx, dy, dz;
    };
    std::vector<Offset> before;
    for (int dz = -1; dz <= 0; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                if (adjacency == 6 && std::abs(dx) + std::abs(dy) + std::abs(dz) != 1) continue;
                before.push_back({dx, dy, dz});
            }
    const long nx = long(d.nx), ny = long(d.ny), nz = long(d.nz);
    forest.parent.assign(d.vertices(), I(-1));
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y)
            for (long x = 0; x < nx; ++x) {
                const I v = I(x + nx * (y + ny * z));
                if (!in(std::size_t(v))) continue;
                for (const Offset& o : before) {
                    if (x + o.dx < 0 || x + o.dx >= nx || y + o.dy < 0 || y + o.dy >= ny || z + o.dz < 0) continue;
                    const I u = I(long(v) + o.dx + nx * (o.dy + ny * o.dz));
                    if (in(std::size_t(u))) forest.unite(v, u);
                }
            }
    std::size_t components = 0;
    small_count = 0;
    const std::size_t n = d.vertices();
    for (std::size_t v = 0; v < n; ++v) {
        if (!in(v)) continue;
        const I p = forest.parent[v];
        if (p < 0) {
            ++components;
            if (std::size_t(-p) <= k) ++small_count;
        }
    }
    if (small_count == 0) return components;
    for (std::size_t v = 0; v < n; ++v)
        if (in(v) && std::size_t(-forest.parent[std::size_t(forest.find(I(v)))]) <= k) small(v);
    return components;
}

template <class T, class I>
void filter_typed(const Volume& v, const Threshold<T>& th, std::size_t k, SmallComponentsConnectivity mode,
                  SmallComponentsResult& r) {
    const Dims d = v.dims();
    const T* f = v.as<T>();
    T* g = r.volume.as<T>();
    const T s = th.at_or_above;
    const int positive_adjacency = mode == SmallComponentsConnectivity::cube ? 26 : 6;
    Forest<I> forest;
    std::size_t ignored = 0;
    auto none = [](std::size_t) {};
    // (1) small components of {f >= s} go just below s.
    r.positive_before = label<I>(d, positive_adjacency, [&](std::size_t i) { return f[i] >= s; }, k, forest,
                                 [&](std::size_t i) {
                                     g[i] = th.below;
                                     ++r.lowered;
                                 },
                                 r.positive_removed);
    // (2) small components of {g < s}, the negative set after (1), go to s.
    const std::size_t negative_after_one = label<I>(d, 6, [&](std::size_t i) { return g[i] < s; }, k, forest,
                                                    [&](std::size_t i) {
                                                        g[i] = s;
                                                        ++r.raised;
                                                    },
                                                    r.negative_removed);
    r.negative_after = negative_after_one - r.negative_removed;
    // The negative set of the input: (1) only added components to it, so count it apart.
    r.negative_before = label<I>(d, 6, [&](std::size_t i) { return f[i] < s; }, 0, forest, none, ignored);
    r.positive_after = label<I>(d, positive_adjacency, [&](std::size_t i) { return g[i] >= s; }, 0, forest, none,
                                ignored);
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
