#include "clfractal/advice.hpp"

#include <omp.h>

#include <algorithm>
#include <type_traits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "clfractal/noise.hpp"

namespace clfractal {

std::vector<CleanBand> clean_bands(const FdCurve& f, const BandOptions& o) {
    if (!std::isfinite(o.max_fd)) throw InputError("--clean-fd: must be a finite number");
    if (!(o.min_share >= 0 && o.min_share <= 1)) throw InputError("--clean-share: must be in [0, 1]");
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    const std::uint64_t largest = count.empty() ? 0 : *std::max_element(count.begin(), count.end());
    const double floor_count = std::max(1.0, o.min_share * double(largest));
    auto clean = [&](std::size_t j) { return !std::isnan(f.fd[j]) && f.fd[j] <= o.max_fd && double(count[j]) >= floor_count; };

    std::vector<CleanBand> bands;
    for (std::size_t j = 0; j < f.fd.size();) {
        if (!clean(j)) {
            ++j;
            continue;
        }
        CleanBand b;
        b.first = j;
        double sum = 0;
        b.max_fd = -INFINITY;
        for (; j < f.fd.size() && clean(j); ++j) {
            sum += f.fd[j];
            b.max_fd = std::max(b.max_fd, f.fd[j]);
            b.max_count = std::max(b.max_count, count[j]);
        }
        b.last = j - 1;
        b.representative = b.first + (b.last - b.first) / 2;
        b.mean_fd = sum / double(b.width());
        bands.push_back(b);
    }
    std::stable_sort(bands.begin(), bands.end(), [](const CleanBand& a, const CleanBand& b) {
        return a.width() != b.width() ? a.width() > b.width() : a.max_count > b.max_count;
    });
    return bands;
}

namespace {

// A(g) of the Gaussian edge model (advice.hpp), for tau > 0.
double gaussian_average_span(double g, double tau) {
    const double pi = 3.14159265358979323846;
    const double f = 0.5 * (g * g + tau * tau) * std::erf(g / (tau * std::sqrt(2.0))) +
                     tau * g / std::sqrt(2 * pi) * std::exp(-g * g / (2 * tau * tau));
    return f / g;
}

// The r in [0, inf) at which the increasing `dimension` reaches d (2 < d < 3): bracket, then
// bisect to double precision.
template <class F> double invert_dimension(const F& dimension, double d) {
    if (std::isnan(d)) return d;
    if (d <= 2) return 0;
    if (d >= 3) return INFINITY;
    double lo = 0, hi = 1;
    while (dimension(hi) < d) {
        lo = hi;
        hi *= 2;
        if (hi > 1e12) return INFINITY;  // d within rounding of 3
    }
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (dimension(mid) < d ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace

double gaussian_edge_dimension(double r) {
    if (!(r >= 0)) throw std::invalid_argument("gaussian_edge_dimension: r must be >= 0");
    if (r == 0) return 2;
    const double tau = r * std::sqrt(2.0);
    return std::log2(8 * gaussian_average_span(1, tau) / gaussian_average_span(2, tau));
}

double noise_ratio_from_edge_dimension(double d) {
    return invert_dimension([](double r) { return expected_edge_dimension(r); }, d);
}

double gaussian_noise_ratio_from_edge_dimension(double d) {
    return invert_dimension([](double r) { return gaussian_edge_dimension(r); }, d);
}

double mean_edge_span_gaussian(double r) {
    if (r == 0) return 0.5;
    return gaussian_average_span(1, r * std::sqrt(2.0));
}

double mean_edge_span(double r) {
    // Simpson over delta in [0, 1]; the integrand is smooth but for a kink at delta = 2r.
    const int n = 512;
    double s = 0;
    for (int i = 0; i <= n; ++i) {
        const double w = i == 0 || i == n ? 1 : (i % 2 ? 4 : 2);
        s += w * edge_span_measure(double(i) / n, NoiseKind::uniform, r);
    }
    return s / (3.0 * n);
}

namespace {

// The first isovalue index with s > x: a < s <= b holds for the indices [first(a), first(b)).
struct FirstAbove {
    const IsovalueSet& iso;
    const std::vector<double>& values;
    std::size_t operator()(double x) const {
        const std::size_t k = values.size();
        if (iso.integer()) {
            const double j = std::floor(x) - double(iso.first()) + 1;
            return std::size_t(std::clamp(j, 0.0, double(k)));
        }
        return std::size_t(std::upper_bound(values.begin(), values.end(), x) - values.begin());
    }
};

// Per thread, the difference arrays of the span sums and counts (k + 1 entries each).
template <class T>
void accumulate_edge_spans(const T* p, const Dims& d, const FirstAbove& first_above,
                           std::vector<std::vector<double>>& sums, std::vector<std::vector<std::int64_t>>& counts) {
#pragma omp parallel for schedule(static)
    for (long long z = 0; z < (long long)d.nz; ++z) {
        const int t = omp_get_thread_num();
        std::vector<double>& sum = sums[std::size_t(t)];
        std::vector<std::int64_t>& count = counts[std::size_t(t)];
        for (std::size_t y = 0; y < d.ny; ++y)
            for (std::size_t x = 0; x < d.nx; ++x) {
                const std::size_t i = x + d.nx * (y + d.ny * std::size_t(z));
                const double f = double(p[i]);
                const double g[3] = {x + 1 < d.nx ? double(p[i + 1]) : f, y + 1 < d.ny ? double(p[i + d.nx]) : f,
                                     std::size_t(z) + 1 < d.nz ? double(p[i + d.nx * d.ny]) : f};
                for (double h : g) {
                    const double a = std::min(f, h), b = std::max(f, h);
                    if (!(a < b)) continue;  // a flat edge (or none) is never intersected
                    const std::size_t lo = first_above(a), hi = first_above(b);
                    if (lo == hi) continue;
                    sum[lo] += b - a;
                    sum[hi] -= b - a;
                    ++count[lo];
                    --count[hi];
                }
            }
    }
}

// The same for integer data on a set of unit steps: first_above(x) = x - first + 1, clamped,
// and the spans integers, summed exactly in 64 bits (as the doubles of the general case sum
// them: every partial sum is an integer below 2^53).
template <class T>
void accumulate_integer_spans(const T* p, const Dims& d, std::int64_t first, std::int64_t k,
                              std::vector<std::vector<std::int64_t>>& diffs) {
#pragma omp parallel for schedule(static)
    for (long long z = 0; z < (long long)d.nz; ++z) {
        // Entry 2j: the span sums' difference at j, 2j + 1: the counts' (one cache line for both).
        std::int64_t* __restrict diff = diffs[std::size_t(omp_get_thread_num())].data();
        const auto add = [&](std::int64_t f, std::int64_t h) {
            const std::int64_t a = std::min(f, h), b = std::max(f, h);
            const std::int64_t lo = std::clamp<std::int64_t>(a - first + 1, 0, k),
                               hi = std::clamp<std::int64_t>(b - first + 1, 0, k);
            // No branch: where lo == hi (a flat edge, or no isovalue in (a, b]) the two cancel.
            diff[2 * lo] += b - a, diff[2 * lo + 1] += 1;
            diff[2 * hi] -= b - a, diff[2 * hi + 1] -= 1;
        };
        const std::size_t plane = d.nx * d.ny;
        for (std::size_t y = 0; y < d.ny; ++y) {
            const T* row = p + std::size_t(z) * plane + y * d.nx;
            for (std::size_t x = 0; x + 1 < d.nx; ++x) add(row[x], row[x + 1]);
            if (y + 1 < d.ny)
                for (std::size_t x = 0; x < d.nx; ++x) add(row[x], row[x + d.nx]);
            if (std::size_t(z) + 1 < d.nz)
                for (std::size_t x = 0; x < d.nx; ++x) add(row[x], row[x + plane]);
        }
    }
}

}  // namespace

EdgeSpanSums intersected_edge_spans(const Volume& v, const IsovalueSet& iso) {
    const std::size_t k = iso.size();
    std::vector<double> values(k);
    for (std::size_t j = 0; j < k; ++j) values[j] = iso.value(j);
    const FirstAbove first_above{iso, values};
    const int threads = omp_get_max_threads();
    if (is_integer(v.type()) && value_size(v.type()) <= 2 && iso.integer()) {
        std::vector<std::vector<std::int64_t>> diffs(std::size_t(threads), std::vector<std::int64_t>(2 * (k + 1), 0));
        visit(v, [&](const auto* p) {
            if constexpr (std::is_integral_v<std::remove_cv_t<std::remove_pointer_t<decltype(p)>>>)
                accumulate_integer_spans(p, v.dims(), iso.first(), std::int64_t(k), diffs);
        });
        EdgeSpanSums r{std::vector<double>(k, 0.0), std::vector<std::uint64_t>(k, 0)};
        std::int64_t run_sum = 0, run_count = 0;
        for (std::size_t j = 0; j < k; ++j) {
            for (int t = 0; t < threads; ++t) {
                run_sum += diffs[std::size_t(t)][2 * j];
                run_count += diffs[std::size_t(t)][2 * j + 1];
            }
            r.sum[j] = double(run_sum);
            r.count[j] = std::uint64_t(run_count);
        }
        return r;
    }
    std::vector<std::vector<double>> sums(std::size_t(threads), std::vector<double>(k + 1, 0.0));
    std::vector<std::vector<std::int64_t>> counts(std::size_t(threads), std::vector<std::int64_t>(k + 1, 0));
    visit(v, [&](const auto* p) { accumulate_edge_spans(p, v.dims(), first_above, sums, counts); });
    EdgeSpanSums r{std::vector<double>(k, 0.0), std::vector<std::uint64_t>(k, 0)};
    double run_sum = 0;
    std::int64_t run_count = 0;
    for (std::size_t j = 0; j < k; ++j) {
        for (int t = 0; t < threads; ++t) {
            run_sum += sums[std::size_t(t)][j];
            run_count += counts[std::size_t(t)][j];
        }
        r.sum[j] = run_sum;
        r.count[j] = std::uint64_t(run_count);
    }
    return r;
}

namespace {

double median(std::vector<double> x) {
    if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t m = x.size() / 2;
    std::nth_element(x.begin(), x.begin() + m, x.end());
    if (x.size() % 2) return x[m];
    return 0.5 * (x[m] + *std::max_element(x.begin(), x.begin() + m));
}

}  // namespace

namespace {

void check_share(double min_share) {
    if (!(min_share >= 0 && min_share <= 1)) throw InputError("the noise estimate's count share must be in [0, 1]");
}

// Theorem 1 inverted at isovalue j of e (uniform and Gaussian), from its edge dimension d.
void invert_at(NoiseEstimate& e, std::size_t j, double d) {
    const double r = noise_ratio_from_edge_dimension(d);
    const double gamma = e.mean_span[j] * mean_edge_span(r) / (1.0 / 3 + 2 * r * r / 3);
    e.ratio[j] = r;
    e.gamma[j] = gamma;
    e.amplitude[j] = r * gamma;
    const double rg = gaussian_noise_ratio_from_edge_dimension(d);
    const double gamma_g = e.mean_span[j] * mean_edge_span_gaussian(rg) / (1.0 / 3 + 2 * rg * rg);
    e.ratio_gaussian[j] = rg;
    e.gamma_gaussian[j] = gamma_g;
    e.sigma_gaussian[j] = rg * gamma_g;
}

// The estimate from the edge counts of levels 0 and 1 and the host values of `v`.
NoiseEstimate noise_from(Context& ctx, const Volume& v, const SpanResult& spans, const IsovalueSet& iso,
                         double min_share) {
    const FdCurve f = fd_curve(ctx, spans, SpanKind::edges);
    const EdgeSpanSums sums = intersected_edge_spans(v, iso);
    const std::size_t k = iso.size();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    NoiseEstimate e;
    e.isovalues = iso;
    e.edge_fd = f.fd;
    e.edges = f.counts[0];
    for (auto* field : {&e.mean_span, &e.ratio, &e.gamma, &e.amplitude, &e.ratio_gaussian, &e.gamma_gaussian,
                        &e.sigma_gaussian})
        field->assign(k, nan);
    const std::uint64_t largest = *std::max_element(f.counts[1].begin(), f.counts[1].end());
    const double floor_count = std::max(1.0, min_share * double(largest));
    std::vector<double> ratios, amplitudes, ratios_g, sigmas_g;
    for (std::size_t j = 0; j < k; ++j) {
        if (sums.count[j]) e.mean_span[j] = sums.sum[j] / double(sums.count[j]);
        const double d = f.fd[j];
        if (std::isnan(d) || d < noise_fd_min || d > noise_fd_max || double(f.counts[1][j]) < floor_count) continue;
        invert_at(e, j, d);
        ratios.push_back(e.ratio[j]);
        amplitudes.push_back(e.amplitude[j]);
        ratios_g.push_back(e.ratio_gaussian[j]);
        sigmas_g.push_back(e.sigma_gaussian[j]);
    }
    e.used = ratios.size();
    e.median_ratio = median(ratios);
    e.median_amplitude = median(amplitudes);
    e.median_ratio_gaussian = median(ratios_g);
    e.median_sigma_gaussian = median(sigmas_g);
    return e;
}

const SpanOptions noise_spans{{SpanKind::edges}, 2, 0};

}  // namespace

NoiseEstimate estimate_noise(Context& ctx, const Volume& v, const IsovalueSet& iso, double min_share) {
    check_share(min_share);
    return noise_from(ctx, v, count_spans(ctx, v, iso, noise_spans), iso, min_share);
}

NoiseEstimate estimate_noise(const DeviceVolume& v, const IsovalueSet& iso, double min_share) {
    check_share(min_share);
    return noise_from(v.context(), v.download(), count_spans(v, iso, noise_spans), iso, min_share);
}

}  // namespace clfractal
