#include "reference/small_components_reference.hpp"

#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <type_traits>

namespace reference {

Labels label_components(const clfractal::Dims& d, const std::vector<bool>& member, int adjacency) {
    Labels out;
    out.label.assign(d.vertices(), -1);
    const long nx = long(d.nx), ny = long(d.ny), nz = long(d.nz);
    for (std::size_t seed = 0; seed < d.vertices(); ++seed) {
        if (!member[seed] || out.label[seed] >= 0) continue;
        const long c = long(out.sizes.size());
        out.sizes.push_back(0);
        std::deque<std::size_t> queue{seed};
        out.label[seed] = c;
        while (!queue.empty()) {
            const std::size_t v = queue.front();
            queue.pop_front();
            ++out.sizes.back();
            const long x = long(v % d.nx), y = long(v / d.nx % d.ny), z = long(v / (d.nx * d.ny));
            for (long dz = -1; dz <= 1; ++dz)
                for (long dy = -1; dy <= 1; ++dy)
                    for (long dx = -1; dx <= 1; ++dx) {
                        const long steps = std::labs(dx) + std::labs(dy) + std::labs(dz);
                        if (steps == 0 || (adjacency == 6 && steps > 1)) continue;
                        const long X = x + dx, Y = y + dy, Z = z + dz;
                        if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
                        const std::size_t u = std::size_t(X + nx * (Y + ny * Z));
                        if (member[u] && out.label[u] < 0) {
                            out.label[u] = c;
                            queue.push_back(u);
                        }
                    }
        }
    }
    return out;
}

namespace {

template <class T>
SmallComponents filter(const clfractal::Volume& v, double s, std::size_t k, int positive_adjacency) {
    // The isovalue in the data's type and its neighbours in the type.
    T at_or_above, below;
    if constexpr (std::is_integral_v<T>) {
        at_or_above = T(std::ceil(s));
        below = T(at_or_above - 1);
    } else {
        at_or_above = T(s);
        below = std::nextafter(at_or_above, -std::numeric_limits<T>::infinity());
    }
    const std::size_t n = v.vertices();
    SmallComponents r;
    r.volume = v;
    T* g = r.volume.as<T>();
    auto set_of = [&](bool positive) {
        std::vector<bool> m(n);
        for (std::size_t i = 0; i < n; ++i) m[i] = positive ? g[i] >= at_or_above : g[i] < at_or_above;
        return m;
    };
    auto small_count = [&](const Labels& l) {
        std::size_t c = 0;
        for (std::size_t size : l.sizes) c += size <= k;
        return c;
    };
    const Labels negative_in = label_components(v.dims(), set_of(false), 6);
    r.negative_before = negative_in.sizes.size();
    const Labels positive = label_components(v.dims(), set_of(true), positive_adjacency);
    r.positive_before = positive.sizes.size();
    r.positive_removed = small_count(positive);
    for (std::size_t i = 0; i < n; ++i)
        if (positive.label[i] >= 0 && positive.sizes[std::size_t(positive.label[i])] <= k) g[i] = below;
    const Labels negative = label_components(v.dims(), set_of(false), 6);
    r.negative_removed = small_count(negative);
    for (std::size_t i = 0; i < n; ++i)
        if (negative.label[i] >= 0 && negative.sizes[std::size_t(negative.label[i])] <= k) g[i] = at_or_above;
    r.positive_after = label_components(v.dims(), set_of(true), positive_adjacency).sizes.size();
    r.negative_after = label_components(v.dims(), set_of(false), 6).sizes.size();
    const T* f = v.as<T>();
    for (std::size_t i = 0; i < n; ++i) r.changed += g[i] != f[i];
    return r;
}

}  // namespace

SmallComponents small_components_filter(const clfractal::Volume& v, double s, std::size_t k, int positive_adjacency) {
    return clfractal::visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        return filter<T>(v, s, k, positive_adjacency);
    });
}

}  // namespace reference
