// Components by breadth-first labelling (components_labelling.hpp): plain single-threaded
// C++, independent of the sweeps it checks (its own neighbourhoods, no device).
#include "components_labelling.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <type_traits>
#include <vector>

namespace clfractal {

namespace {

struct Offset {
    int dx, dy, dz;
};

// The offsets of a 3x3x3 neighbourhood: 6 (faces), 26 (all) or 14 (the Freudenthal edges:
// the offsets whose non-zero components share one sign).
std::vector<Offset> neighbourhood(int adjacency) {
    std::vector<Offset> o;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
                const bool mixed = (dx < 0 || dy < 0 || dz < 0) && (dx > 0 || dy > 0 || dz > 0);
                if (n > 0 && (adjacency == 26 || (adjacency == 6 && n == 1) || (adjacency == 14 && !mixed)))
                    o.push_back({dx, dy, dz});
            }
    return o;
}

template <class T>
std::int64_t labelling(const Volume& v, T s, Connectivity mode) {
    const T* f = v.as<T>();
    const Dims d = v.dims();
    const std::size_t n = v.vertices(), nx = d.nx, ny = d.ny, nz = d.nz;
    std::vector<unsigned char> seen(n, 0);
    std::vector<std::size_t> stack;
    std::int64_t b[2] = {0, 0};  // b0(A), b0(C)
    const std::vector<Offset> nb[2] = {neighbourhood(mode == Connectivity::cube ? 6 : 14),
                                       neighbourhood(mode == Connectivity::cube ? 26 : 14)};
    for (std::size_t start = 0; start < n; ++start) {
        if (seen[start]) continue;
        const bool positive = f[start] >= s;
        ++b[positive];
        seen[start] = 1;
        stack.push_back(start);
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            const long x = long(i % nx), y = long(i / nx % ny), z = long(i / (nx * ny));
            for (const Offset& o : nb[positive]) {
                const long a = x + o.dx, bb = y + o.dy, c = z + o.dz;
                if (a < 0 || bb < 0 || c < 0 || a >= long(nx) || bb >= long(ny) || c >= long(nz)) continue;
                const std::size_t j = std::size_t(a) + nx * (std::size_t(bb) + ny * std::size_t(c));
                if (!seen[j] && (f[j] >= s) == positive) {
                    seen[j] = 1;
                    stack.push_back(j);
                }
            }
        }
    }
    return b[0] && b[1] ? b[0] + b[1] - 1 : 0;
}

}  // namespace

std::int64_t count_components_by_labelling(const Volume& v, double isovalue, Connectivity mode) {
    return visit(v, [&](const auto* p) -> std::int64_t {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_integral<T>::value) {
            // f >= s  <=>  f >= ceil(s); clamped to the type's range (all or nothing beyond it).
            const double c = std::ceil(isovalue);
            if (c <= double(std::numeric_limits<T>::min())) return 0;  // A empty
            if (c > double(std::numeric_limits<T>::max())) return 0;   // C empty
            return labelling<T>(v, T(c), mode);
        } else {
            return labelling<T>(v, T(isovalue), mode);
        }
    });
}

}  // namespace clfractal
