#include "clfractal/analysis.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <type_traits>
#include <chrono>
#include <cstring>
#include <cmath>
#include <iterator>
#include <numeric>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "clfractal/error.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/small_components.hpp"
#include "device/name_table.hpp"
#include "volume/value_counts.hpp"

namespace clfractal {

namespace {

using json = nlohmann::json;

// The floor of "well-populated": clean_share x the largest I(s), at least 1 cube.
double population_floor(const FdCurve& f, double share) {
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    const std::uint64_t largest = count.empty() ? 0 : *std::max_element(count.begin(), count.end());
    return std::max(1.0, share * double(largest));
}


// The boundary strength b(k) = sum over |j - k| <= w of I(j) / max(1, sum of h(j)), with
// w = max(2, n / 32): the mean gradient of the surfaces near s_k in cubes per vertex. No
// histogram: b(k) = the windowed mean of I(j).
std::vector<double> boundary_strength(const FdCurve& f, const std::vector<std::uint64_t>& hist) {
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    const std::size_t n = count.size();
    const std::size_t w = std::max<std::size_t>(2, n / 32);
    std::vector<double> ci(n + 1, 0), ch(n + 1, 0);
    for (std::size_t k = 0; k < n; ++k) {
        ci[k + 1] = ci[k] + double(count[k]);
        ch[k + 1] = ch[k] + (hist.empty() ? 1.0 : double(hist[k]));
    }
    std::vector<double> b(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t lo = k >= w ? k - w : 0, hi = std::min(n, k + w + 1);
        b[k] = (ci[hi] - ci[lo]) / std::max(1.0, ch[hi] - ch[lo]);
    }
    return b;
}

// A run of consecutive curve indices.
struct Run {
    std::size_t first, last;
    std::uint64_t max_count;
    std::size_t width() const { return last - first + 1; }
};

// The maximal runs of indices for which `in` holds, ranked widest first, then largest surface.
template <class In> std::vector<Run> runs_of(const FdCurve& f, In in) {
    std::vector<Run> runs;
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    for (std::size_t j = 0; j < count.size();) {
        if (!in(j)) {
            ++j;
            continue;
        }
        Run r{j, j, 0};
        for (; j < count.size() && in(j); ++j) r.max_count = std::max(r.max_count, count[j]);
        r.last = j - 1;
        runs.push_back(r);
    }
    std::stable_sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) {
        return a.width() != b.width() ? a.width() > b.width() : a.max_count > b.max_count;
    });
    return runs;
}

// The material boundaries of a run. Eligible: the isovalues of the run whose surface is at
// least a hundredth of the run's largest (not the vanishing ends of a shape).
// Over the eligible isovalues in order, a boundary is a local maximum of b whose prominence
// ratio b(k) / base is at least 2, the base being the larger of the two sides' smallest b
// between k and the nearest higher b on that side or the end (the prominence of
// scipy.signal.peak_prominences, as a ratio; an end point has none). Strongest first, at most
// `most`. A run without such a maximum (b flat, as on a distance field) is represented by its
// eligible isovalue nearest to its middle.
std::vector<std::size_t> boundaries_in(const Run& r, const FdCurve& f, const std::vector<double>& b,
                                       std::size_t most) {
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    std::vector<std::size_t> at;  // the eligible isovalues
    for (std::size_t k = r.first; k <= r.last; ++k)
        if (100 * count[k] >= r.max_count) at.push_back(k);
    const std::size_t n = at.size();
    auto e = [&](std::size_t i) { return b[at[i]]; };
    std::vector<std::size_t> peaks;
    for (std::size_t i = 1; i + 1 < n; ++i) {
        if (!(e(i) > e(i - 1) && e(i) >= e(i + 1))) continue;
        double lbase = e(i), rbase = e(i);
        for (std::size_t j = i; j-- > 0 && e(j) <= e(i);) lbase = std::min(lbase, e(j));
        for (std::size_t j = i + 1; j < n && e(j) <= e(i); ++j) rbase = std::min(rbase, e(j));
        if (e(i) >= 2 * std::max(lbase, rbase)) peaks.push_back(at[i]);
    }
    std::stable_sort(peaks.begin(), peaks.end(), [&](std::size_t x, std::size_t y) { return b[x] > b[y]; });
    if (peaks.size() > most) peaks.resize(most);
    if (peaks.empty()) {
        const std::size_t middle = r.first + (r.width() - 1) / 2;
        std::size_t best = at.empty() ? middle : at.front();
        for (std::size_t k : at)
            if ((k > middle ? k - middle : middle - k) < (best > middle ? best - middle : middle - best)) best = k;
        peaks.push_back(best);
    }
    return peaks;
}

Recommendation entry(const FdCurve& f, std::size_t k, const Run& r, const std::vector<double>& b,
                     const AdviceOptions& o, const char* basis) {
    Recommendation e;
    e.index = k;
    e.isovalue = f.isovalues.value(k);
    e.fd = f.fd[k];
    e.count = f.counts[0][k];
    e.count_sub = f.counts[1][k];
    e.verdict = verdict_of(e.fd, o);
    e.first = r.first;
    e.last = r.last;
    e.boundary = b[k];
    e.basis = basis;
    return e;
}

json number_json(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json recommendation_json(const FdCurve& f, const Recommendation& e, const NoiseEstimate* surface) {
    json j{{"isovalue", e.isovalue},
           {"fd", number_json(e.fd)},
           {"count", e.count},
           {"count_sub", e.count_sub},
           {"components", e.components >= 0 ? json(e.components) : json(nullptr)},
           {"verdict", verdict_name(e.verdict)},
           {"first", f.isovalues.value(e.first)},
           {"last", f.isovalues.value(e.last)},
           {"band_width", e.last - e.first + 1},
           {"boundary", e.boundary},
           {"basis", e.basis}};
    if (surface) {
        const double de = surface->edge_fd[e.index];
        j["edge_fd"] = number_json(de);
        j["noise_ratio"] = number_json(std::isnan(de) ? NAN : noise_ratio_from_edge_dimension(de));
        j["noise_ratio_trusted"] = !std::isnan(de) && de >= noise_fd_min && de <= noise_fd_max;
    }
    return j;
}

json bands_json(const FdCurve& f, const std::vector<CleanBand>& bands) {
    json a = json::array();
    for (const CleanBand& b : bands)
        a.push_back({{"first", f.isovalues.value(b.first)},
                     {"last", f.isovalues.value(b.last)},
                     {"isovalue", f.isovalues.value(b.representative)},
                     {"width", b.width()},
                     {"mean_fd", b.mean_fd},
                     {"max_fd", b.max_fd},
                     {"max_count", b.max_count}});
    return a;
}

json summary_json(const FdSummary& s) {
    return {{"mean", number_json(s.mean)},
            {"std", number_json(s.std)},
            {"weighted_mean", number_json(s.weighted_mean)},
            {"kappa", number_json(s.kappa)},
            {"defined", s.defined}};
}

json surface_json(const NoiseEstimate& e) {
    json per = json::array();
    for (std::size_t j = 0; j < e.isovalues.size(); ++j) {
        if (std::isnan(e.ratio[j])) continue;
        per.push_back({{"isovalue", e.isovalues.value(j)},
                       {"edge_fd", e.edge_fd[j]},
                       {"ratio", e.ratio[j]},
                       {"gamma", e.gamma[j]},
                       {"amplitude", e.amplitude[j]},
                       {"ratio_gaussian", number_json(e.ratio_gaussian[j])},
                       {"gamma_gaussian", number_json(e.gamma_gaussian[j])},
                       {"sigma_gaussian", number_json(e.sigma_gaussian[j])}});
    }
    return {{"question", "is the surface at s noise-dominated: r(s) = noise / gradient, Theorem 1 inverted"},
            {"amplitude", number_json(e.median_amplitude)},
            {"ratio", number_json(e.median_ratio)},
            {"ratio_gaussian", number_json(e.median_ratio_gaussian)},
            {"sigma_gaussian", number_json(e.median_sigma_gaussian)},
            {"isovalues_used", e.used},
            {"trusted_edge_fd", {noise_fd_min, noise_fd_max}},
            {"per_isovalue", per}};
}

json noise_json(const NoiseLevel* l, const NoiseEstimate* e) {
    json j = json::object();
    if (l) {
        json map = json::array();
        for (float c : l->map) map.push_back(std::isnan(c) ? json(nullptr) : json(double(c)));
        j["sigma"] = number_json(l->sigma);
        j["sigma_white"] = number_json(l->sigma_white);
        j["correlation"] = {number_json(l->correlation[0]), number_json(l->correlation[1]),
                            number_json(l->correlation[2])};
        j["sigma_strides"] = {l->sigma_strides[0], l->sigma_strides[1], l->sigma_strides[2]};
        j["texture"] = l->texture;
        j["spread"] = {{"p10", number_json(l->spread[0])}, {"p50", number_json(l->spread[1])},
                       {"p90", number_json(l->spread[2])}};
        j["variation"] = number_json(noise_variation(*l));
        j["notes"] = noise_level_notes(*l);
        j["flat_share"] = l->flat_share;
        j["block"] = l->block;
        j["blocks"] = l->blocks;
        j["blocks_usable"] = l->usable_blocks;
        j["blocks_flat"] = l->flat_blocks;
        j["seconds"] = l->seconds;
        j["map"] = {{"cell", l->map_block}, {"dims", {l->map_dims.nx, l->map_dims.ny, l->map_dims.nz}}, {"sigma", map}};
    }
    if (e) j["surface"] = surface_json(*e);
    return j;
}

// Host memory beyond the volume of the denoising ladder, at its largest step: the filtered
// copy (step 1's, which step 2 filters further), the small-components filter's second copy
// and its labelling (4 bytes a run along x, at most a run a vertex), and the LD field of the
// targeted filter in float32 (the components at its recommendations are labelled in
// O(slice)).
std::size_t ladder_bytes(const Volume& v) { return 2 * v.size_bytes() + 8 * v.vertices(); }
bool within(const AnalysisOptions& o, std::size_t bytes) { return o.memory_budget == 0 || bytes <= o.memory_budget; }
std::string mib(std::size_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// The values of x[0 .. n) and y[0 .. n) whose bytes differ, compared as unsigned integers
// U of the value's size (one load each, vectorised).
template <class U> std::size_t differing(const unsigned char* x, const unsigned char* y, std::size_t n) {
    std::size_t changed = 0;
#pragma omp parallel for reduction(+ : changed) schedule(static)
    for (long long i = 0; i < (long long)n; ++i) {
        U a, b;
        std::memcpy(&a, x + std::size_t(i) * sizeof(U), sizeof(U));
        std::memcpy(&b, y + std::size_t(i) * sizeof(U), sizeof(U));
        changed += std::size_t(a != b);
    }
    return changed;
}

// The share of vertices whose value differs (in its bytes) between two volumes of the same
// type and dims.
double changed_share(const Volume& a, const Volume& b) {
    const auto* x = static_cast<const unsigned char*>(a.data());
    const auto* y = static_cast<const unsigned char*>(b.data());
    const std::size_t n = a.vertices();
    std::size_t changed = 0;
    switch (value_size(a.type())) {
    case 1: changed = differing<std::uint8_t>(x, y, n); break;
    case 2: changed = differing<std::uint16_t>(x, y, n); break;
    case 4: changed = differing<std::uint32_t>(x, y, n); break;
    default: changed = differing<std::uint64_t>(x, y, n); break;
    }
    return n ? double(changed) / double(n) : 0.0;
}

// Components at the entries' isovalues, each labelled directly (count_components_at, on the
// host or the device by Tuning::labelling): one pass over the volume an isovalue, memory
// O(slice) on the host.
void fill_components(const std::vector<Recommendation*>& entries, const EntryCounter& count) {
    if (entries.empty()) return;
    std::vector<double> at;
    for (const Recommendation* e : entries) at.push_back(e->isovalue);
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    const std::vector<std::int64_t> c = count(at);
    if (c.size() != at.size()) throw std::logic_error("fill_components: one count an isovalue expected");
    for (Recommendation* e : entries)
        e->components = c[std::size_t(std::lower_bound(at.begin(), at.end(), e->isovalue) - at.begin())];
}

EntryCounter counter(Context& ctx, const Volume& v) {
    return [&ctx, &v](const std::vector<double>& at) { return count_components_at(ctx, v, at, Connectivity::cube); };
}

// The curve, bands, recommendations and noisiest isovalue of `v` at `iso`.
struct Advice {
    SpanResult spans;
    FdCurve curve;
    std::vector<std::uint64_t> histogram;
    std::vector<CleanBand> bands;
    std::vector<Recommendation> recommended;
    bool clean = false;
};

void check_analysis(const AnalysisOptions& o) {
    check_advice(o.advice);
    if (o.levels < 2 || o.levels > 16) throw InputError("levels " + std::to_string(o.levels) + ": must be 2..16");
}

// `histogram`: isovalue_histogram(v, iso) when the caller has it; empty: computed here.
Advice advise(Context& ctx, const Volume& v, const IsovalueSet& iso, const AnalysisOptions& o, bool edges_too,
              std::vector<std::uint64_t> histogram = {}) {
    Advice a;
    SpanOptions so{{o.kind}, o.levels, o.slab_slices};
    if (edges_too && o.kind != SpanKind::edges) so.kinds.push_back(SpanKind::edges);
    a.spans = count_spans(ctx, v, iso, so);
    a.curve = fd_curve(ctx, a.spans, o.kind);
    a.histogram = histogram.empty() ? isovalue_histogram(v, iso) : std::move(histogram);
    a.bands = clean_bands(a.curve, BandOptions{o.advice.clean_fd, o.advice.clean_share});
    a.recommended = recommend(a.curve, a.histogram, o.advice);
    a.clean = has_clean_isovalue(a.curve, o.advice);
    return a;
}

// The denoising ladder: the fractal-targeted median at the first recommendation's isovalue
// (LD > 2.5; then its result, not filtered again, through the small-components filter of
// size 20, the best for the component count in bench/denoise_benchmark.py; then LD > 2.2),
// then the median everywhere; each re-runs the advice on its result, and the ladder stops at
// the first that leaves a clean well-populated isovalue. Where the noise is correlated
// (noise_is_correlated), the median everywhere, then its result through
// the small-components filter of size 20: correlated noise makes smooth blobs whose LD stays
// under the thresholds, which the targeted steps leave (bench/denoise_benchmark.py, noise
// smoothed by 1 voxel: component error 4.8 to 63 after the targeted median and K 20, 0.8 to
// 13 after the median and K 20).
std::vector<DenoiseAttempt> denoise_ladder(Context& ctx, const Volume& v, const IsovalueSet& iso,
                                           const AnalysisOptions& o, double at, bool correlated) {
    std::vector<DenoiseAttempt> tried;
    // (threshold, K): the targeted median where LD > threshold (NaN: the median everywhere),
    // then, for K > 0, the small-components filter of size K at the same isovalue.
    const std::vector<std::pair<double, std::size_t>> steps =
        correlated ? std::vector<std::pair<double, std::size_t>>{{NAN, 0}, {NAN, 20}}
                   : std::vector<std::pair<double, std::size_t>>{{2.5, 0}, {2.5, 20}, {2.2, 0}, {NAN, 0}};
    const auto same_filter = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
    // The targeted median of the step before, kept when the next step filters it further (the
    // same threshold, then small components) instead of filtering again.
    std::optional<Volume> kept;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const auto& [h, k] = steps[i];
        const auto t0 = std::chrono::steady_clock::now();
        DenoiseAttempt d;
        d.method = "median";
        d.targeted = !std::isnan(h);
        d.filter = d.targeted ? "fractal-targeted median" : "median";
        d.isovalue = at;
        d.threshold = h;
        d.window = o.window;
        d.small_components = k;
        Volume out = kept        ? std::move(*kept)
                     : d.targeted ? targeted_filter(ctx, v, FilterSpec::median(), at, h, o.window).volume
                                  : median_filter(ctx, v);
        kept.reset();
        if (k) {
            d.filter += " and small components (K " + std::to_string(k) + ")";
            out = small_components_filter(out, at, k).volume;
        }
        d.changed_share = changed_share(v, out);
        Advice adv = advise(ctx, out, iso, o, false);
        d.clean = adv.clean;
        d.bands = std::move(adv.bands);
        d.summary = summarize(adv.curve.fd, adv.curve.counts[0], adv.curve.counts[1]);
        d.recommended = std::move(adv.recommended);
        if (o.components != ComponentsScope::none && !d.recommended.empty()) {
            std::vector<Recommendation*> es;
            for (Recommendation& e : d.recommended) es.push_back(&e);
            fill_components(es, counter(ctx, out));
        }
        d.seconds = seconds_since(t0);
        tried.push_back(std::move(d));
        if (tried.back().clean) break;
        if (i + 1 < steps.size() && !k && same_filter(steps[i + 1].first, h) && steps[i + 1].second)
            kept = std::move(out);
    }
    return tried;
}

}  // namespace

void check_advice(const AdviceOptions& o) {
    if (!std::isfinite(o.clean_fd)) throw InputError("--clean-fd: must be a finite number");
    if (!std::isfinite(o.noisy_fd) || o.noisy_fd < o.clean_fd)
        throw InputError("noisy_fd: must be a finite number >= clean_fd");
    if (!(o.clean_share >= 0 && o.clean_share <= 1)) throw InputError("--clean-share: must be in [0, 1]");
    if (o.max_recommended == 0 || o.per_band == 0) throw InputError("max_recommended and per_band: must be >= 1");
}

template <> struct detail::NameTable<Verdict> {
    static constexpr const char* what = "verdict";
    static constexpr std::pair<Verdict, const char*> names[] = {
        {Verdict::clean, "clean"}, {Verdict::rough, "rough"}, {Verdict::noisy, "noisy"}, {Verdict::undefined, "undefined"}};
};
template <> struct detail::NameTable<ComponentsScope> {
    static constexpr const char* what = "components";
    static constexpr std::pair<ComponentsScope, const char*> names[] = {
        {ComponentsScope::none, "none"}, {ComponentsScope::recommended, "recommended"}, {ComponentsScope::curve, "curve"}};
};

const char* verdict_name(Verdict v) { return variant_name(v); }
ComponentsScope parse_components_scope(const std::string& name) { return parse_variant<ComponentsScope>(name); }

Verdict verdict_of(double fd, const AdviceOptions& o) {
    if (std::isnan(fd)) return Verdict::undefined;
    return fd <= o.clean_fd ? Verdict::clean : fd >= o.noisy_fd ? Verdict::noisy : Verdict::rough;
}

namespace {

// Whether the host part counts every value (detail::value_counts): 8-bit data, and 16-bit data
// from 2^23 values on; one pass then gives the value range and the isovalue histogram of any
// isovalue set. Below 2^23 16-bit values, the tables' set-up
// costs more than the second pass saves (4 Mi values: 1.3 ms against 1.1 ms for the range and
// then the histogram of its isovalues; 16 Mi: 3.1 ms against 4.6 ms; 2-core Xeon).
bool counted_by_value(const Volume& v) {
    const ValueType t = v.type();
    if (t == ValueType::uint8 || t == ValueType::int8) return true;
    return (t == ValueType::uint16 || t == ValueType::int16) && v.vertices() >= (std::size_t(1) << 23);
}

// The isovalue histogram from the count of every value: a value x counts at isovalue k when
// x - first == k (integer sets), else at the last isovalue <= x.
std::vector<std::uint64_t> histogram_of_counts(const std::vector<std::uint64_t>& counts, ValueType t,
                                               const IsovalueSet& iso) {
    const std::size_t n = iso.size();
    std::vector<std::uint64_t> hist(n, 0);
    const std::vector<double>& s = iso.list();
    for (std::size_t u = 0; u < counts.size(); ++u) {
        if (!counts[u]) continue;
        const long long x = detail::value_of_bits(u, t);
        if (iso.integer()) {
            const unsigned long long k = (unsigned long long)(x - iso.first());
            if (k < n) hist[k] += counts[u];
        } else {
            const std::size_t k = std::size_t(std::upper_bound(s.begin(), s.end(), double(x)) - s.begin());
            if (k > 0) hist[k - 1] += counts[u];
        }
    }
    return hist;
}

}  // namespace

std::vector<std::uint64_t> isovalue_histogram(const Volume& v, const IsovalueSet& iso) {
    const std::size_t n = iso.size();
    std::vector<std::uint64_t> hist(n, 0);
    if (n == 0) return hist;
    // 8-bit and large 16-bit integer data: the count of each value, then the isovalues' own.
    if (counted_by_value(v)) return histogram_of_counts(detail::value_counts(v), v.type(), iso);
    const int threads = omp_get_max_threads();
    std::vector<std::vector<std::uint64_t>> part(std::size_t(threads), std::vector<std::uint64_t>(n, 0));
    visit(v, [&](const auto* data) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(data)>>;
        const std::size_t m = v.vertices();
        // Integer data with every integer isovalue: a plain count per value.
        const bool by_value = std::is_integral_v<T> && iso.integer();
        const long long first = iso.integer() ? iso.first() : 0;
        const std::vector<double>& s = iso.list();
#pragma omp parallel num_threads(threads)
        {
            std::uint64_t* __restrict h = part[std::size_t(omp_get_thread_num())].data();
            if (by_value) {
                // Four interleaved counts break the chains of increments of one bin (runs of
                // equal values), summed at the end.
                std::vector<std::uint64_t> more(3 * n, 0);
                std::uint64_t* __restrict h1 = more.data();
                std::uint64_t* __restrict h2 = h1 + n;
                std::uint64_t* __restrict h3 = h2 + n;
                const auto bin = [&](std::size_t i) { return (unsigned long long)((long long)data[i] - first); };
#pragma omp for schedule(static)
                for (std::size_t q = 0; q < m / 4; ++q) {
                    const std::size_t i = 4 * q;
                    const unsigned long long a = bin(i), b = bin(i + 1), c = bin(i + 2), d = bin(i + 3);
                    if (a < n) ++h[a];
                    if (b < n) ++h1[b];
                    if (c < n) ++h2[c];
                    if (d < n) ++h3[d];
                }
#pragma omp single
                for (std::size_t i = m / 4 * 4; i < m; ++i)
                    if (bin(i) < n) ++h[bin(i)];
                for (std::size_t k = 0; k < n; ++k) h[k] += h1[k] + h2[k] + h3[k];
            } else {
#pragma omp for schedule(static)
                for (std::size_t i = 0; i < m; ++i) {
                    const double x = double(data[i]);
                    if (iso.integer()) {
                        const double k = x - double(first);
                        if (k >= 0 && k < double(n)) ++h[std::size_t(k)];
                    } else {
                        const std::size_t k = std::size_t(std::upper_bound(s.begin(), s.end(), x) - s.begin());
                        if (k > 0) ++h[k - 1];
                    }
                }
            }
        }
    });
    for (const auto& h : part)
        for (std::size_t k = 0; k < n; ++k) hist[k] += h[k];
    return hist;
}

bool has_clean_isovalue(const FdCurve& f, const AdviceOptions& o) {
    const double floor_count = population_floor(f, o.clean_share);
    for (std::size_t k = 0; k < f.fd.size(); ++k)
        if (!std::isnan(f.fd[k]) && f.fd[k] <= o.clean_fd && double(f.counts[0][k]) >= floor_count) return true;
    return false;
}

std::optional<std::size_t> noisiest_isovalue(const FdCurve& f, double clean_share) {
    const double floor_count = population_floor(f, clean_share);
    std::optional<std::size_t> noisiest;
    for (std::size_t k = 0; k < f.fd.size(); ++k)
        if (!std::isnan(f.fd[k]) && double(f.counts[0][k]) >= floor_count && (!noisiest || f.fd[k] > f.fd[*noisiest]))
            noisiest = k;
    return noisiest;
}

std::vector<Recommendation> recommend(const FdCurve& f, const std::vector<std::uint64_t>& histogram,
                                      const AdviceOptions& o) {
    check_advice(o);
    const std::vector<std::uint64_t>& count = f.counts.at(0);
    if (!histogram.empty() && histogram.size() != count.size())
        throw InputError("recommend: the histogram has " + std::to_string(histogram.size()) + " bins for " +
                         std::to_string(count.size()) + " isovalues");
    const std::vector<double> b = boundary_strength(f, histogram);
    const double floor_count = population_floor(f, o.clean_share);
    auto populated = [&](std::size_t k) { return !std::isnan(f.fd[k]) && double(count[k]) >= floor_count; };

    std::vector<Run> runs = runs_of(f, [&](std::size_t k) { return populated(k) && f.fd[k] <= o.clean_fd; });
    const char* basis = "clean band";
    if (runs.empty()) {
        // Nothing clean: the runs among the cleanest quarter of the well-populated isovalues.
        std::vector<double> d;
        for (std::size_t k = 0; k < count.size(); ++k)
            if (populated(k)) d.push_back(f.fd[k]);
        if (!d.empty()) {
            std::sort(d.begin(), d.end());
            const double q = d[(d.size() - 1) / 4];
            runs = runs_of(f, [&](std::size_t k) { return populated(k) && f.fd[k] <= q; });
            // The cleanest run first: the lowest mean D, then the widest.
            auto mean_fd = [&](const Run& r) {
                double sum = 0;
                for (std::size_t k = r.first; k <= r.last; ++k) sum += f.fd[k];
                return sum / double(r.width());
            };
            std::stable_sort(runs.begin(), runs.end(), [&](const Run& x, const Run& y) { return mean_fd(x) < mean_fd(y); });
            if (runs.size() > 3) runs.resize(3);
            basis = "cleanest quarter";
        }
    }
    std::vector<Recommendation> out;
    for (const Run& r : runs) {
        for (std::size_t k : boundaries_in(r, f, b, o.per_band)) {
            if (out.size() == o.max_recommended) return out;
            out.push_back(entry(f, k, r, b, o, basis));
        }
    }
    if (out.empty()) {
        // No defined D anywhere (a grid too small for G'): the largest surface, undefined.
        const auto top = std::max_element(count.begin(), count.end());
        if (top != count.end() && *top > 0) {
            const std::size_t k = std::size_t(top - count.begin());
            out.push_back(entry(f, k, Run{k, k, *top}, b, o, "largest surface"));
        }
    }
    return out;
}

namespace {
// A number that reads back to the same double: 9 significant digits when they do, else 17.
std::string exact(double x) {
    for (int digits : {9, 17}) {
        std::ostringstream o;
        o.precision(digits);
        o << x;
        if (std::stod(o.str()) == x || digits == 17) return o.str();
    }
    return {};
}
}  // namespace

std::string DenoiseAttempt::command(const std::string& volume, const std::string& output) const {
    std::ostringstream s;
    const std::string first = small_components ? output + ".median.nrrd" : output;
    s << "clfractal filter " << volume << " --median";
    if (targeted) s << " --fractal --iso " << exact(isovalue) << " --threshold " << threshold << " --window " << window;
    s << " -o " << first;
    if (small_components)
        s << " && clfractal filter " << first << " --small-components " << small_components << " --iso " << exact(isovalue)
          << " -o " << output;
    return s.str();
}

void fill_entry_components(Analysis& a, const EntryCounter& count) {
    std::vector<Recommendation*> es;
    for (Recommendation& e : a.recommended) es.push_back(&e);
    fill_components(es, count);
}

Analysis analyse_curve(const FdCurve& f, const AnalysisOptions& o, std::vector<std::uint64_t> histogram) {
    check_advice(o.advice);
    Analysis a;
    a.options = o;
    a.isovalues = f.isovalues;
    a.curve = f;
    a.histogram = std::move(histogram);
    a.summary = summarize(f.fd, f.counts.at(0), f.counts.at(1));
    a.bands = clean_bands(f, BandOptions{o.advice.clean_fd, o.advice.clean_share});
    a.recommended = recommend(f, a.histogram, o.advice);
    a.clean = has_clean_isovalue(f, o.advice);
    if (const auto k = noisiest_isovalue(f, o.advice.clean_share))
        a.noisiest = entry(f, *k, Run{*k, *k, f.counts[0][*k]}, boundary_strength(f, a.histogram), o.advice,
                           "noisiest");
    return a;
}

AnalysisInput prepare_analysis(const Volume& v, const AnalysisOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    AnalysisInput in;
    if (o.isovalues && !o.isovalues->matches(v.type()))
        throw InputError("analyse: the isovalue set does not match " + std::string(value_type_name(v.type())) + " data");
    // 8-bit and large 16-bit data: one pass counts every value, which gives the range and the
    // histogram.
    std::vector<std::uint64_t> counts;
    if (counted_by_value(v)) counts = detail::value_counts(v);
    in.stats = counts.empty() ? value_stats(v) : detail::stats_of_counts(counts, v.type());
    in.isovalues = o.isovalues ? *o.isovalues : IsovalueSet::for_range(v.type(), in.stats.min, in.stats.max, o.bins ? o.bins : 256);
    in.histogram = counts.empty() ? isovalue_histogram(v, in.isovalues) : histogram_of_counts(counts, v.type(), in.isovalues);
    in.seconds = seconds_since(t0);
    in.data = v.data();
    return in;
}

Analysis analyse(Context& ctx, const Volume& v, const AnalysisOptions& o) {
    check_analysis(o);
    return analyse(ctx, v, o, prepare_analysis(v, o));
}

Analysis analyse(Context& ctx, const Volume& v, const AnalysisOptions& o, AnalysisInput input) {
    const auto t0 = std::chrono::steady_clock::now();
    check_analysis(o);
    if (input.data != v.data() || !input.isovalues.matches(v.type()) || input.histogram.size() != input.isovalues.size())
        throw std::invalid_argument("analyse: the prepared input is not that of this volume");
    Analysis a;
    a.options = o;
    a.dims = v.dims();
    a.type = v.type();
    a.vmin = input.stats.min;
    a.vmax = input.stats.max;
    a.isovalues = std::move(input.isovalues);

    Advice adv = advise(ctx, v, a.isovalues, o, o.edge_counts, std::move(input.histogram));
    a.spans = std::move(adv.spans);
    a.curve = std::move(adv.curve);
    a.histogram = std::move(adv.histogram);
    a.bands = std::move(adv.bands);
    a.recommended = std::move(adv.recommended);
    a.clean = adv.clean;
    a.summary = summarize(a.curve.fd, a.curve.counts[0], a.curve.counts[1]);
    if (const auto k = noisiest_isovalue(a.curve, o.advice.clean_share))
        a.noisiest = entry(a.curve, *k, Run{*k, *k, a.curve.counts[0][*k]}, boundary_strength(a.curve, a.histogram),
                           o.advice, "noisiest");

    const auto labelling = std::chrono::steady_clock::now();
    if (o.components == ComponentsScope::curve) {
        a.components = count_components(ctx, v, a.isovalues, Connectivity::cube);
        for (Recommendation& e : a.recommended) e.components = a.components->components[e.index];
        if (a.noisiest) a.noisiest->components = a.components->components[a.noisiest->index];
    } else if (o.components == ComponentsScope::recommended) {
        fill_entry_components(a, counter(ctx, v));
    }
    a.seconds_components = seconds_since(labelling);
    if (o.noise_level) a.noise_level = estimate_noise_level(ctx, v);
    if (o.surface_noise) a.surface_noise = estimate_noise(ctx, v, a.isovalues, o.advice.clean_share);
    if (o.fd4) a.fd4 = fractal_dimension_4d(ctx, v);
    if (o.denoise && !a.clean && !a.recommended.empty()) {
        if (within(o, ladder_bytes(v)))
            a.denoise = denoise_ladder(ctx, v, a.isovalues, o, a.best().isovalue,
                                       a.noise_level && noise_is_correlated(*a.noise_level));
        else
            a.skipped.push_back("denoise: the filtered copy and its LD field need " + mib(ladder_bytes(v)) +
                                " beyond the volume, above the memory budget of " + mib(o.memory_budget) +
                                " (report runs it)");
    }
    a.seconds_prepare = input.seconds;
    a.seconds = input.seconds + seconds_since(t0);
    return a;
}

double auto_isovalue(Context& ctx, const Volume& v, Recommendation* chosen) {
    AnalysisOptions o;
    o.components = ComponentsScope::none;
    o.noise_level = o.surface_noise = o.fd4 = o.denoise = false;
    const Analysis a = analyse(ctx, v, o);
    if (a.recommended.empty())
        throw InputError("--iso auto: " + v.name + " has no surface at any isovalue (no cube is intersected); give --iso S");
    if (chosen) *chosen = a.best();
    return a.best().isovalue;
}

std::string to_json(const Analysis& a, int indent) {
    const FdCurve& f = a.curve;
    const IsovalueSet& iso = a.isovalues;
    const NoiseEstimate* surface = a.surface_noise ? &*a.surface_noise : nullptr;
    json j;
    j["isovalues"] = {{"count", iso.size()},
                      {"first", iso.size() ? json(iso.value(0)) : json(nullptr)},
                      {"last", iso.size() ? json(iso.value(iso.size() - 1)) : json(nullptr)}};
    j["advice"] = {{"clean_fd", a.options.advice.clean_fd},
                   {"noisy_fd", a.options.advice.noisy_fd},
                   {"clean_share", a.options.advice.clean_share}};
    j["fd"] = summary_json(a.summary);
    j["clean_bands"] = bands_json(f, a.bands);
    j["clean"] = a.clean;
    j["recommended"] = json::array();
    for (const Recommendation& e : a.recommended) j["recommended"].push_back(recommendation_json(f, e, surface));
    j["noisiest"] = a.noisiest ? recommendation_json(f, *a.noisiest, surface) : json(nullptr);
    if (a.noise_level || surface) j["noise"] = noise_json(a.noise_level ? &*a.noise_level : nullptr, surface);
    if (a.fd4)
        j["fd4"] = {{"q", a.fd4->q},
                    {"vmin", a.fd4->vmin},
                    {"i4_l0", a.fd4->i4},
                    {"i4_l1", a.fd4->i4_sub},
                    {"d4", number_json(a.fd4->d4)}};
    json tried = json::array();
    for (const DenoiseAttempt& d : a.denoise) {
        json rec = json::array();
        for (const Recommendation& e : d.recommended) rec.push_back(recommendation_json(f, e, nullptr));
        tried.push_back({{"filter", d.filter},
                         {"targeted", d.targeted},
                         {"isovalue", d.targeted ? json(d.isovalue) : json(nullptr)},
                         {"threshold", number_json(d.threshold)},
                         {"window", d.window},
                         {"small_components", d.small_components},
                         {"changed_share", d.changed_share},
                         {"clean", d.clean},
                         {"fd", summary_json(d.summary)},
                         {"clean_bands", bands_json(f, d.bands)},
                         {"recommended", rec},
                         {"seconds", d.seconds},
                         {"command", d.command()}});
    }
    j["denoise"] = {{"needed", !a.clean && !a.recommended.empty()}, {"attempts", tried}};
    j["skipped"] = a.skipped;
    json curve = json::array();
    for (std::size_t k = 0; k < iso.size(); ++k) {
        json row;
        row["isovalue"] = iso.value(k);
        json counts = json::array();
        for (int l = 0; l < f.levels(); ++l) counts.push_back(f.counts[std::size_t(l)][k]);
        row["counts"] = counts;
        row["fd"] = number_json(f.fd[k]);
        if (f.levels() > 2) row["fd_fit"] = number_json(f.fd_fit[k]);
        row["verdict"] = verdict_name(verdict_of(f.fd[k], a.options.advice));
        if (!a.histogram.empty()) row["vertices"] = a.histogram[k];
        if (a.components) row["components"] = a.components->components[k];
        curve.push_back(row);
    }
    j["curve"] = curve;
    j["seconds_analysis"] = a.seconds;
    j["seconds_prepare"] = a.seconds_prepare;
    j["seconds_components"] = a.seconds_components;
    return j.dump(indent);
}

}  // namespace clfractal
