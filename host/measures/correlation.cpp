// The correlation of the component curve with the fractal dimension (components.hpp):
// Pearson's coefficient, centred on the host, its three dot products with CLBlast on the device.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "clfractal/components.hpp"
#include "device/blas_module.hpp"

namespace clfractal {

namespace {

template <class R> double pearson_clblast(Context& ctx, const std::vector<double>& x, const std::vector<double>& y) {
    const std::size_t n = x.size();
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < n; ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= double(n);
    my /= double(n);
    std::vector<R> cx(n), cy(n);
    for (std::size_t i = 0; i < n; ++i) {
        cx[i] = R(x[i] - mx);
        cy[i] = R(y[i] - my);
    }
    std::array<R, 3> dots{};
    with_cl_errors([&] {
        Buffer<R> bx(ctx, n, CL_MEM_READ_ONLY), by(ctx, n, CL_MEM_READ_ONLY), out(ctx, 3);
        bx.write(ctx.queue(), cx.data(), n);
        by.write(ctx.queue(), cy.data(), n);
        out.fill(ctx.queue(), R(0));
        const detail::BlasModule& blas = detail::blas();
        const auto dot = std::is_same_v<R, double> ? blas.dot_double : blas.dot_float;
        const std::array<std::pair<const Buffer<R>*, const Buffer<R>*>, 3> pairs{
            {{&bx, &by}, {&bx, &bx}, {&by, &by}}};
        for (std::size_t k = 0; k < 3; ++k) {
            const int status = dot(n, out.get()(), k, pairs[k].first->get()(), pairs[k].second->get()(), ctx.queue()());
            if (status != 0) throw DeviceError("CLBlast Dot failed with status " + std::to_string(status), status);
        }
        out.read(ctx.queue(), dots.data(), 3);
    });
    const double sxy = double(dots[0]), sxx = double(dots[1]), syy = double(dots[2]);
    if (!(sxx > 0) || !(syy > 0)) return std::numeric_limits<double>::quiet_NaN();
    return sxy / std::sqrt(sxx * syy);
}

}  // namespace

double pearson(Context& ctx, const std::vector<double>& x, const std::vector<double>& y) {
    if (x.size() != y.size()) throw std::logic_error("pearson: sizes differ");
    if (x.size() < 2) return std::numeric_limits<double>::quiet_NaN();
    return ctx.has_fp64() ? pearson_clblast<double>(ctx, x, y) : pearson_clblast<float>(ctx, x, y);
}

ComponentCorrelation correlate_components(Context& ctx, const std::vector<double>& fd,
                                          const std::vector<std::uint64_t>& edges,
                                          const std::vector<std::int64_t>& components, const Dims& dims) {
    if (fd.size() != edges.size() || fd.size() != components.size())
        throw std::logic_error("correlate_components: curve lengths differ");
    std::array<std::size_t, 3> n{dims.nx, dims.ny, dims.nz};
    std::sort(n.begin(), n.end());
    const double min_edges = double(n[0]) * double(n[1]) / 4;
    std::vector<double> d, c, ca;
    for (std::size_t j = 0; j < fd.size(); ++j) {
        if (std::isnan(fd[j]) || double(edges[j]) < min_edges || edges[j] == 0) continue;
        d.push_back(fd[j]);
        c.push_back(double(components[j]));
        ca.push_back(double(components[j]) / double(edges[j]));
    }
    ComponentCorrelation r;
    r.used = d.size();
    r.components = pearson(ctx, d, c);
    r.components_per_area = pearson(ctx, d, ca);
    return r;
}

}  // namespace clfractal
