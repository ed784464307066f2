#include "clfractal/fd.hpp"

#include "device/blas_module.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

namespace clfractal {

namespace {

template <class R>
std::vector<double> gemv_slopes(Context& ctx, const std::vector<std::vector<std::uint64_t>>& counts) {
    const std::size_t L = counts.size(), K = counts[0].size();
    // Rows: isovalues; columns: log2 count per level. The slope is Y w with
    // w_l = (l - mean(l)) / sum((l - mean(l))^2).
    std::vector<R> y(K * L, R(0));
    std::vector<char> defined(K, 1);
    for (std::size_t j = 0; j < K; ++j)
        for (std::size_t l = 0; l < L; ++l) {
            if (counts[l][j] == 0) defined[j] = 0;
            else y[j * L + l] = R(std::log2(double(counts[l][j])));
        }
    const double lbar = double(L - 1) / 2;
    double sxx = 0;
    for (std::size_t l = 0; l < L; ++l) sxx += (double(l) - lbar) * (double(l) - lbar);
    std::vector<R> w(L);
    for (std::size_t l = 0; l < L; ++l) w[l] = R((double(l) - lbar) / sxx);

    std::vector<R> slope(K);
    with_cl_errors([&] {
        Buffer<R> a(ctx, K * L, CL_MEM_READ_ONLY), x(ctx, L, CL_MEM_READ_ONLY), out(ctx, K);
        a.write(ctx.queue(), y.data(), y.size());
        x.write(ctx.queue(), w.data(), w.size());
        out.fill(ctx.queue(), R(0));  // CLBlast reads y even when beta = 0
        const detail::BlasModule& blas = detail::blas();
        const int status = (std::is_same_v<R, double> ? blas.gemv_double : blas.gemv_float)(
            K, L, a.get()(), x.get()(), out.get()(), ctx.queue()());
        if (status != 0) throw DeviceError("CLBlast Gemv failed with status " + std::to_string(status), status);
        out.read(ctx.queue(), slope.data(), K);
    });
    std::vector<double> d(K);
    for (std::size_t j = 0; j < K; ++j)
        d[j] = defined[j] ? -double(slope[j]) : std::numeric_limits<double>::quiet_NaN();
    return d;
}

}  // namespace

std::vector<double> least_squares_dimension(Context& ctx, const std::vector<std::vector<std::uint64_t>>& counts) {
    if (counts.size() < 2) throw std::logic_error("least_squares_dimension: need at least 2 levels");
    if (counts[0].empty()) return {};
    return ctx.has_fp64() ? gemv_slopes<double>(ctx, counts) : gemv_slopes<float>(ctx, counts);
}

FdCurve fd_curve(Context& ctx, const SpanResult& spans, SpanKind kind) {
    const SpanCurves& c = spans.get(kind);
    if (c.counts.size() < 2) throw InputError("--levels must be at least 2 for a fractal dimension");
    FdCurve f;
    f.kind = kind;
    f.isovalues = spans.isovalues;
    f.level_dims = c.level_dims;
    f.counts = c.counts;
    const std::size_t K = spans.isovalues.size();
    f.fd.resize(K);
    for (std::size_t j = 0; j < K; ++j) {
        std::uint64_t n0 = c.counts[0][j], n1 = c.counts[1][j];
        f.fd[j] = (n0 && n1) ? std::log2(double(n0) / double(n1)) : std::numeric_limits<double>::quiet_NaN();
    }
    if (c.counts.size() > 2) f.fd_fit = least_squares_dimension(ctx, c.counts);
    return f;
}

FdSummary summarize(const std::vector<double>& fd, const std::vector<std::uint64_t>& count,
                    const std::vector<std::uint64_t>& count_sub, std::uint64_t min_count) {
    FdSummary s;
    std::vector<std::size_t> used;
    for (std::size_t j = 0; j < fd.size(); ++j)
        if (!std::isnan(fd[j]) && count_sub[j] >= min_count) used.push_back(j);
    s.defined = used.size();
    if (used.empty()) {
        double nan = std::numeric_limits<double>::quiet_NaN();
        return FdSummary{0, nan, nan, nan, nan};
    }
    double sum = 0, wsum = 0, w = 0;
    for (std::size_t j : used) {
        sum += fd[j];
        wsum += fd[j] * double(count[j]);
        w += double(count[j]);
    }
    s.mean = sum / double(used.size());
    double var = 0;
    for (std::size_t j : used) var += (fd[j] - s.mean) * (fd[j] - s.mean);
    s.std = std::sqrt(var / double(used.size()));
    s.weighted_mean = wsum / w;
    s.kappa = s.mean / 3;
    return s;
}

}  // namespace clfractal
