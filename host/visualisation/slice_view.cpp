// Axial slices with an isosurface's contour and an LD field (render.hpp SliceView).
#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <cmath>
#include <string>

#include "clfractal/error.hpp"
#include "clfractal/local.hpp"
#include "clfractal/render.hpp"
#include "volume/below.hpp"

namespace clfractal {
namespace {

// The isovalue as the data's type compares it (docs/definitions.md §3): float32 data with s
// rounded to float32, every other type in double (exact for their values).
double compared_isovalue(const Volume& v, double iso) {
    return v.type() == ValueType::float32 ? double(float(iso)) : iso;
}

// Slice z of v as doubles, x fastest.
std::vector<double> slice_values(const Volume& v, std::size_t z) {
    const Dims d = v.dims();
    std::vector<double> out(d.nx * d.ny);
    visit(v, [&](const auto* p) {
        const auto* s = p + z * d.nx * d.ny;
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = double(s[i]);
    });
    return out;
}

// Grey levels from the slice's 0.5% and 99.5% quantiles, so that a few extreme values
// do not wash the picture out.
struct GreyLevels {
    double lo, span;
};

GreyLevels grey_levels(const std::vector<double>& f) {
    std::vector<double> sorted = f;
    const std::size_t q0 = sorted.size() / 200, q1 = sorted.size() - 1 - sorted.size() / 200;
    std::nth_element(sorted.begin(), sorted.begin() + q0, sorted.end());
    const double lo = sorted[q0];
    std::nth_element(sorted.begin(), sorted.begin() + q1, sorted.end());
    const double hi = sorted[q1];
    const double span = hi > lo ? hi - lo : 1;
    return {lo, span};
}

// The slice in grey, with the LD field of slice z (if any) blended in with weight alpha.
Image paint_slice(const std::vector<double>& f, const Dims& d, const Volume* ld, std::size_t z, double alpha) {
    const GreyLevels g0 = grey_levels(f);
    const double lo = g0.lo, span = g0.span;
    Image image;
    image.width = d.nx;
    image.height = d.ny;
    image.rgb.resize(3 * d.nx * d.ny);
    const float* field = ld ? ld->as<float>() + z * d.nx * d.ny : nullptr;
    for (std::size_t y = 0; y < d.ny; ++y)
        for (std::size_t x = 0; x < d.nx; ++x) {
            const std::size_t i = y * d.nx + x;
            const double g = 255 * std::clamp((f[i] - lo) / span, 0.0, 1.0);
            double rgb[3] = {g, g, g};
            if (field && !std::isnan(field[i])) {
                const Rgb c = ld_colour(field[i]);
                const double over[3] = {double(c.r), double(c.g), double(c.b)};
                for (int e = 0; e < 3; ++e) rgb[e] = (1 - alpha) * rgb[e] + alpha * over[e];
            }
            std::uint8_t* px = &image.rgb[3 * ((d.ny - 1 - y) * d.nx + x)];
            for (int e = 0; e < 3; ++e) px[e] = std::uint8_t(std::lround(rgb[e]));
        }
    return image;
}

// Marching squares. Corners 0..3 counter-clockwise from (x, y); edge e joins corner e
// and corner e + 1.
const int cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};

// The contour segments of the cell at (x, y), appended to `contour`.
void contour_cell(const std::vector<double>& f, const Dims& d, double s, double sx, double sy, std::size_t x,
                  std::size_t y, std::vector<std::array<float, 4>>& contour) {
    double val[4];
    bool neg[4];
    int negatives = 0;
    for (int c = 0; c < 4; ++c) {
        val[c] = f[(y + cy[c]) * d.nx + x + cx[c]];
        neg[c] = val[c] < s;
        negatives += neg[c];
    }
    if (negatives == 0 || negatives == 4) return;
    std::array<float, 2> at[4];
    bool crossed[4];
    for (int e = 0; e < 4; ++e) {
        const int a = e, b = (e + 1) % 4;
        crossed[e] = neg[a] != neg[b];
        if (!crossed[e]) continue;
        const double t = (s - val[a]) / (val[b] - val[a]);
        at[e] = {float((double(x) + cx[a] + t * (cx[b] - cx[a])) * sx),
                 float((double(y) + cy[a] + t * (cy[b] - cy[a])) * sy)};
    }
    if (negatives == 2 && neg[0] == neg[2]) {
        // Saddle: cut off each negative corner (its two edges).
        for (int c = 0; c < 4; ++c)
            if (neg[c]) {
                const int e0 = (c + 3) % 4, e1 = c;
                contour.push_back({at[e0][0], at[e0][1], at[e1][0], at[e1][1]});
            }
        return;
    }
    int first = -1;
    for (int e = 0; e < 4; ++e)
        if (crossed[e]) {
            if (first < 0) {
                first = e;
            } else {
                contour.push_back({at[first][0], at[first][1], at[e][0], at[e][1]});
                break;
            }
        }
}

}  // namespace

SliceView render_slice(const Volume& v, std::size_t z, double iso, const Volume* ld, double alpha) {
    const Dims d = v.dims();
    if (z >= d.nz) throw InputError("slice " + std::to_string(z) + ": the volume has " + std::to_string(d.nz) + " slices");
    if (ld && (ld->type() != ValueType::float32 || !(ld->dims() == d)))
        throw InputError("slice: the LD field must be float32 with the volume's dimensions");
    const std::vector<double> f = slice_values(v, z);
    const double s = compared_isovalue(v, iso);

    SliceView out;
    out.image = paint_slice(f, d, ld, z, alpha);
    const double sx = v.spacing[0], sy = v.spacing[1];
    for (std::size_t y = 0; y + 1 < d.ny; ++y)
        for (std::size_t x = 0; x + 1 < d.nx; ++x) contour_cell(f, d, s, sx, sy, x, y, out.contour);
    return out;
}

std::size_t busiest_slice(const Volume& v, double iso) {
    const Dims d = v.dims();
    std::vector<std::size_t> crossings(d.nz, 0);
    visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        const auto cut = detail::below<T>(v.type(), iso);
        if (!cut) return;  // every value on one side: nothing crossed
        // Row `q` below s, one byte a value (the comparison a copy, which the bytes cannot alias).
        const auto below = [c = *cut, nx = d.nx](const T* __restrict q, std::uint8_t* __restrict out) {
            for (std::size_t x = 0; x < nx; ++x) out[x] = c(q[x]);
        };
#pragma omp parallel
        {
            std::vector<std::uint8_t> row_of(d.nx), next_of(d.nx);
#pragma omp for schedule(static)
            for (long long z = 0; z < (long long)d.nz; ++z) {
                const auto* q = p + std::size_t(z) * d.nx * d.ny;
                std::uint8_t* row = row_of.data();
                std::uint8_t* next = next_of.data();
                std::size_t n = 0;
                below(q, row);
                for (std::size_t y = 0; y < d.ny; ++y) {
                    unsigned changes = 0;  // at most 2 nx a row
                    for (std::size_t x = 0; x + 1 < d.nx; ++x) changes += row[x] != row[x + 1];
                    if (y + 1 < d.ny) {
                        below(q + (y + 1) * d.nx, next);
                        for (std::size_t x = 0; x < d.nx; ++x) changes += row[x] != next[x];
                    }
                    n += changes;
                    std::swap(row, next);
                }
                crossings[std::size_t(z)] = n;
            }
        }
    });
    std::size_t best = d.nz / 2;
    for (std::size_t z = 0; z < d.nz; ++z) {
        const auto dist = [&](std::size_t k) { return k > d.nz / 2 ? k - d.nz / 2 : d.nz / 2 - k; };
        if (crossings[z] > crossings[best] || (crossings[z] == crossings[best] && dist(z) < dist(best))) best = z;
    }
    return best;
}

}  // namespace clfractal
