// Fractal dimension curves (docs/definitions.md §8 "Fractal dimension", §9 "Multi-level fit",
// §10 "Curve summary"; thesis eq. 2.5, eq. 3.1, §2.3).
//
//   box span dimension   D(s) = log2( I_G(s) / I_G'(s) )    (eq. 2.5, cubes)
//   edge span dimension  D(s) = log2( E_G(s) / E_G'(s) )    (eq. 3.1, edges)
//
// undefined (NaN) where either count is 0. With levels 0..L-1 (L > 2) the multi-level
// estimate is D(s) = -slope of the least-squares line through (l, log2 I_l(s)), undefined
// where any level's count is 0; L = 2 gives eq. 2.5.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/span.hpp"

namespace clfractal {

struct FdCurve {
    SpanKind kind = SpanKind::cubes;
    IsovalueSet isovalues;
    std::vector<Dims> level_dims;
    std::vector<std::vector<std::uint64_t>> counts;  ///< [level][isovalue]
    std::vector<double> fd;                          ///< eq. 2.5 / 3.1 from levels 0 and 1
    std::vector<double> fd_fit;                      ///< least-squares over all levels (L > 2)
    int levels() const { return int(counts.size()); }
};

/// Builds the curve from span counts of at least 2 levels. The least-squares fit over
/// all levels runs on the device with CLBlast (one GEMV for every isovalue) when L > 2.
FdCurve fd_curve(Context& ctx, const SpanResult& spans, SpanKind kind);

/// -slope of the least-squares line through (l, log2 counts[l][j]) for every j, as one
/// CLBlast GEMV on the device; NaN where any count is 0.
std::vector<double> least_squares_dimension(Context& ctx, const std::vector<std::vector<std::uint64_t>>& counts);

/// Summary of a curve over the isovalues where D is defined (and, if min_count > 0,
/// where the subsampled count I_G'(s) >= min_count).
struct FdSummary {
    std::size_t defined = 0;      ///< isovalues that enter the summary
    double mean = 0;              ///< mean of D(s)
    double std = 0;               ///< population standard deviation of D(s)
    double weighted_mean = 0;     ///< mean of D(s) weighted by the full-grid count I_G(s)
    double kappa = 0;             ///< growth exponent mean / 3 (I ~ N^kappa)
};
/// NaN fields when nothing is defined.
FdSummary summarize(const std::vector<double>& fd, const std::vector<std::uint64_t>& count,
                    const std::vector<std::uint64_t>& count_sub, std::uint64_t min_count = 0);

}  // namespace clfractal
