// The answer to "which isovalue gives a clean surface, how noisy is my scan, and what do I do
// about it", computed once in the library (docs/definitions.md §33 "Recommendations and the analysis"):
// the fractal dimension curve, its clean bands, ranked recommendations that are never empty,
// the noisiest well-populated isovalue, the noise level, Theorem 1 inverted per isovalue, the
// 4D dimension, and, when nothing is clean, the denoising that makes it clean. `clfractal fd`,
// `report`, `--iso auto`, the C ABI (clf_analyse) and Python render this one result.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/advice.hpp"
#include "clfractal/components.hpp"
#include "clfractal/device.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/noise_level.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// How clean the surface of one isovalue is: clean when D(s) <= clean_fd (the colour map's
/// blue end, 2.2), noisy when D(s) >= noisy_fd (its red end, 2.5), rough between, and
/// undefined where D(s) is (the subsampled grid meets no cube).
enum class Verdict { clean, rough, noisy, undefined };
/// "clean", "rough", "noisy", "undefined".
const char* verdict_name(Verdict v);

struct AdviceOptions {
    double clean_fd = 2.2;      ///< clean: D(s) <= clean_fd
    double noisy_fd = 2.5;      ///< noisy: D(s) >= noisy_fd
    double clean_share = 0.01;  ///< well-populated: I(s) >= clean_share x the largest I(s)
    std::size_t max_recommended = 6;  ///< at most this many entries
    std::size_t per_band = 3;         ///< at most this many material boundaries per band
};

Verdict verdict_of(double fd, const AdviceOptions& o = {});

/// Throws InputError when `o` is out of range: clean_fd not finite, noisy_fd not finite or
/// below clean_fd, clean_share outside [0, 1], max_recommended or per_band 0. Every function
/// that takes AdviceOptions checks them first.
void check_advice(const AdviceOptions& o);

/// One recommended isovalue (index into the curve) with the band it stands for.
struct Recommendation {
    std::size_t index = 0;
    double isovalue = 0;
    double fd = std::numeric_limits<double>::quiet_NaN();
    std::uint64_t count = 0, count_sub = 0;  ///< I(s) on G and G'
    std::int64_t components = -1;            ///< isosurface components at s; -1: not computed
    Verdict verdict = Verdict::undefined;
    std::size_t first = 0, last = 0;  ///< the band (curve indices, inclusive)
    /// The boundary strength at s: the smoothed ratio of intersected cubes to vertices whose
    /// value lies at s (the mean gradient of the surface, larger at a material boundary).
    double boundary = 0;
    /// Why: "clean band" (a run of clean well-populated isovalues) or "cleanest quarter"
    /// (nothing is clean: a run of well-populated isovalues among the cleanest quarter).
    std::string basis;
};

/// Vertices per isovalue bin: h[k] counts the vertices with s_k <= f < s_(k+1) (integer
/// sets: f == s_k; the last bin is open above). One pass on the host.
std::vector<std::uint64_t> isovalue_histogram(const Volume& v, const IsovalueSet& iso);

/// The ranked recommendations of a curve (docs/definitions.md §33): never empty when any
/// cube is intersected. `histogram` (isovalue_histogram of the volume; may be empty, then
/// the boundary strength is I(s) itself) locates material boundaries inside the bands.
/// Components are left at -1.
std::vector<Recommendation> recommend(const FdCurve& f, const std::vector<std::uint64_t>& histogram,
                                      const AdviceOptions& o = {});

/// The well-populated isovalue with the largest D(s); nullopt when none has a defined D.
std::optional<std::size_t> noisiest_isovalue(const FdCurve& f, double clean_share = 0.01);

/// True when a well-populated isovalue has D(s) <= clean_fd.
bool has_clean_isovalue(const FdCurve& f, const AdviceOptions& o = {});

/// One denoising tried when no well-populated isovalue is clean: the filter, what it changed,
/// and the advice re-run on its result.
struct DenoiseAttempt {
    std::string filter;                 ///< e.g. "fractal-targeted median"
    std::string method;                 ///< "median" (the 3x3x3 median)
    bool targeted = false;              ///< only where LD(v) > threshold
    double isovalue = 0;                ///< the LD field's isovalue (targeted)
    double threshold = std::numeric_limits<double>::quiet_NaN();
    int window = 8;
    std::size_t small_components = 0;   ///< then the small-components filter of this size (0: none)
    double changed_share = 0;           ///< vertices whose value changed / all vertices
    bool clean = false;                 ///< a well-populated isovalue is clean afterwards
    std::vector<CleanBand> bands;       ///< the clean bands of the result
    std::vector<Recommendation> recommended;  ///< the advice on the result
    FdSummary summary;                  ///< of the result's curve
    /// Wall time of the filter and the re-run (with small components after a targeted median
    /// at the same threshold: the small-components filter of that attempt's result).
    double seconds = 0;
    /// The command line(s) that write the filtered volume ("VOLUME" stands for the input).
    std::string command(const std::string& volume = "VOLUME", const std::string& output = "OUT.nrrd") const;
};

enum class ComponentsScope {
    none,         ///< no components
    recommended,  ///< components at the recommended isovalues only (the noisiest's: with `curve`)
    curve         ///< the whole component curve
};

/// "none", "recommended" or "curve"; InputError naming every choice for another name.
ComponentsScope parse_components_scope(const std::string& name);

struct AnalysisOptions {
    AdviceOptions advice;
    SpanKind kind = SpanKind::cubes;  ///< the curve: box (cubes) or edge span dimension
    int levels = 2;                   ///< pyramid levels of the curve (2..16)
    std::size_t slab_slices = 0;      ///< largest z-slab of the span count (0: from memory)
    bool edge_counts = false;         ///< also count edge spans into `spans` (E(s))
    std::optional<IsovalueSet> isovalues;  ///< the default set of the volume's range if unset
    std::size_t bins = 256;           ///< uniform isovalues of float and wide data
    ComponentsScope components = ComponentsScope::recommended;
    bool noise_level = true;          ///< noise.sigma with its map
    bool surface_noise = true;        ///< Theorem 1 inverted per isovalue
    bool fd4 = false;                 ///< the 4D dimension
    bool denoise = true;              ///< when nothing is clean: try the denoising ladder
    int window = 8;                   ///< LD window of the targeted filter
    /// Host memory in bytes the analysis may use beyond the volume for the denoising ladder
    /// (twice the volume's bytes + 8 a vertex); above it the ladder is skipped and said in
    /// `skipped`. 0: no limit.
    std::size_t memory_budget = 0;
};

struct Analysis {
    AnalysisOptions options;
    Dims dims{};
    ValueType type = ValueType::uint8;
    double vmin = 0, vmax = 0;
    IsovalueSet isovalues;
    SpanResult spans;       ///< the counts of the curve's kind (and edges for r(s))
    FdCurve curve;
    FdSummary summary;
    std::vector<std::uint64_t> histogram;   ///< isovalue_histogram
    std::vector<CleanBand> bands;           ///< clean bands, ranked
    bool clean = false;                     ///< a well-populated isovalue is clean
    std::vector<Recommendation> recommended;
    std::optional<Recommendation> noisiest;
    std::optional<ComponentCurve> components;   ///< ComponentsScope::curve
    std::optional<NoiseLevel> noise_level;
    std::optional<NoiseEstimate> surface_noise;
    std::optional<Fd4Result> fd4;
    std::vector<DenoiseAttempt> denoise;    ///< tried in order until one is clean; empty if clean
    std::vector<std::string> skipped;       ///< steps left out by the memory budget, and why
    double seconds = 0;                     ///< wall time of analyse() (and of its prepare_analysis)
    double seconds_prepare = 0;             ///< of which prepare_analysis (0: the counting gave its part)
    double seconds_components = 0;          ///< of which the component labelling (entries or curve)
    /// The first entry of `recommended`: the isovalue to use (`recommended` must not be empty).
    const Recommendation& best() const { return recommended.front(); }
};

/// What analyse() computes on the host before it needs the device: the value statistics, the
/// isovalue set and the isovalue histogram, in one pass counting every value for 8-bit data
/// and 16-bit data of 2^23 values or more, else one pass for the statistics and one for the
/// histogram. A program that
/// creates its context on another thread (Context::start_shared) computes it meanwhile and
/// hands it to analyse(); its `stats` also tell it whether the volume holds NaN or Inf.
struct AnalysisInput {
    ValueStats stats;                      ///< value_stats of the volume
    IsovalueSet isovalues;                 ///< AnalysisOptions::isovalues, or the default set of the range
    std::vector<std::uint64_t> histogram;  ///< isovalue_histogram at `isovalues`
    double seconds = 0;                    ///< wall time of prepare_analysis()
    const void* data = nullptr;            ///< the volume's values it was prepared from (analyse checks)
};
/// The host part of analyse(v, o), for analyse(ctx, v, o, input). Throws InputError for an
/// isovalue set that does not match the volume's type.
AnalysisInput prepare_analysis(const Volume& v, const AnalysisOptions& o = {});

/// Everything above for `v`. Throws InputError for options out of range (clean_fd not
/// finite, clean_share outside [0, 1], levels outside 2..16, an isovalue set that does not
/// match the volume's type). `recommended` is empty only when no cube is intersected at any
/// isovalue (a constant volume, a grid with fewer than 2 vertices on an axis).
Analysis analyse(Context& ctx, const Volume& v, const AnalysisOptions& o = {});
/// The same with the host part already computed: `input` must be prepare_analysis(v, o) for
/// this volume and these options (std::invalid_argument when it was prepared from other
/// values). Analysis::seconds includes input.seconds.
Analysis analyse(Context& ctx, const Volume& v, const AnalysisOptions& o, AnalysisInput input);

/// Counts components(s) at isovalues given sorted, each once; one count each.
using EntryCounter = std::function<std::vector<std::int64_t>(const std::vector<double>&)>;
/// Sets the components of the recommended entries of `a`, calling `count` once
/// with their isovalues: count_components_at on the volume (what analyse does), or a pass
/// over a file slice by slice (ComponentsAtStream; what `fd --stream` does after analyse_curve).
void fill_entry_components(Analysis& a, const EntryCounter& count);

/// The analysis of a curve alone (a streamed volume): bands, recommendations and the noisiest
/// isovalue, with the boundary strength from `histogram` (isovalue_histogram of the volume at
/// the curve's isovalues, summed slice batch by slice batch; empty: h = 1); no components (see
/// fill_entry_components), noise or denoising.
Analysis analyse_curve(const FdCurve& f, const AnalysisOptions& o = {}, std::vector<std::uint64_t> histogram = {});

/// The isovalue --iso auto uses: the first recommendation's (InputError when there is none).
double auto_isovalue(Context& ctx, const Volume& v, Recommendation* chosen = nullptr);

/// The analysis as JSON text: the schema `fd --json` and `report --json` share
/// (docs/definitions.md §33): isovalues, fd summary, clean_bands, clean, recommended,
/// noisiest, noise (sigma, map, surface), d4/fd4, denoise, curve (with verdicts).
std::string to_json(const Analysis& a, int indent = 1);

}  // namespace clfractal
