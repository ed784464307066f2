#include "reference/filter_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

using namespace clfractal;

namespace reference {

namespace {

long clampi(long i, long n) { return std::min(std::max(i, 0L), n - 1); }

// Value at (x, y, z) with clamp-to-edge.
double at(const Volume& v, long x, long y, long z) {
    const Dims& d = v.dims();
    return v.value(v.index(clampi(x, long(d.nx)), clampi(y, long(d.ny)), clampi(z, long(d.nz))));
}

}  // namespace

Volume median_filter(const Volume& v) {
    Volume out(v.dims(), v.type());
    const Dims& d = v.dims();
    visit(out, [&](auto* o) {
        using T = std::remove_pointer_t<decltype(o)>;
        const T* p = v.as<T>();
        for (long z = 0; z < long(d.nz); ++z)
            for (long y = 0; y < long(d.ny); ++y)
                for (long x = 0; x < long(d.nx); ++x) {
                    T n[27];
                    int k = 0;
                    for (long dz = -1; dz <= 1; ++dz)
                        for (long dy = -1; dy <= 1; ++dy)
                            for (long dx = -1; dx <= 1; ++dx)
                                n[k++] = p[v.index(clampi(x + dx, long(d.nx)), clampi(y + dy, long(d.ny)),
                                                   clampi(z + dz, long(d.nz)))];
                    std::nth_element(n, n + 13, n + 27);
                    o[v.index(x, y, z)] = n[13];
                }
    });
    return out;
}

std::vector<double> gaussian_filter(const Volume& v, double sigma) {
    const int r = int(std::ceil(3 * sigma));
    std::vector<double> w(2 * r + 1);
    double sum = 0;
    for (int i = -r; i <= r; ++i) sum += w[i + r] = std::exp(-double(i) * i / (2 * sigma * sigma));
    for (double& x : w) x /= sum;
    const Dims& d = v.dims();
    const long nx = long(d.nx), ny = long(d.ny), nz = long(d.nz);
    std::vector<double> a(v.vertices()), b(v.vertices());
    for (std::size_t i = 0; i < v.vertices(); ++i) a[i] = v.value(i);
    auto idx = [&](long x, long y, long z) { return std::size_t(x + nx * (y + ny * z)); };
    // z, then y, then x (the order does not matter in exact arithmetic).
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y)
            for (long x = 0; x < nx; ++x) {
                double s = 0;
                for (int k = -r; k <= r; ++k) s += w[k + r] * a[idx(x, y, clampi(z + k, nz))];
                b[idx(x, y, z)] = s;
            }
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y)
            for (long x = 0; x < nx; ++x) {
                double s = 0;
                for (int k = -r; k <= r; ++k) s += w[k + r] * b[idx(x, clampi(y + k, ny), z)];
                a[idx(x, y, z)] = s;
            }
    for (long z = 0; z < nz; ++z)
        for (long y = 0; y < ny; ++y)
            for (long x = 0; x < nx; ++x) {
                double s = 0;
                for (int k = -r; k <= r; ++k) s += w[k + r] * a[idx(clampi(x + k, nx), y, z)];
                b[idx(x, y, z)] = s;
            }
    return b;
}

std::vector<double> bilateral_filter(const Volume& v, double sigma_s, double sigma_r, const float* ld) {
    const int r = int(std::ceil(2 * sigma_s));
    const Dims& d = v.dims();
    std::vector<double> out(v.vertices());
    for (long z = 0; z < long(d.nz); ++z)
        for (long y = 0; y < long(d.ny); ++y)
            for (long x = 0; x < long(d.nx); ++x) {
                const std::size_t i = v.index(x, y, z);
                const double c = v.value(i);
                double sr = sigma_r;
                if (ld) {
                    if (!(ld[i] > 2.0f)) {
                        out[i] = c;
                        continue;
                    }
                    sr = sigma_r * std::min(double(ld[i]) - 2.0, 1.0);
                }
                double num = 0, den = 0;
                for (long dz = -r; dz <= r; ++dz)
                    for (long dy = -r; dy <= r; ++dy)
                        for (long dx = -r; dx <= r; ++dx) {
                            const double f = at(v, x + dx, y + dy, z + dz);
                            const double wgt = std::exp(-double(dx * dx + dy * dy + dz * dz) / (2 * sigma_s * sigma_s)) *
                                               std::exp(-(f - c) * (f - c) / (2 * sr * sr));
                            num += wgt * f;
                            den += wgt;
                        }
                out[i] = num / den;
            }
    return out;
}

double store_as(ValueType t, double x) {
    switch (t) {
    case ValueType::uint8: return std::clamp(std::nearbyint(x), 0.0, 255.0);
    case ValueType::uint16: return std::clamp(std::nearbyint(x), 0.0, 65535.0);
    case ValueType::int16: return std::clamp(std::nearbyint(x), -32768.0, 32767.0);
    default: return double(float(x));
    }
}

}  // namespace reference
