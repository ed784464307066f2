// The analysis (docs/definitions.md §33): recommendations on curves with known answers, on
// phantoms of nested materials with known boundaries, the denoising ladder, the JSON, and
// every volume of ../shared/data, each "clean" checked against D from the reference counts.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <tuple>

#include <nlohmann/json.hpp>

#include "clfractal/analysis.hpp"
#include "clfractal/clfractal.h"
#include "clfractal/components.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/noise.hpp"
#include "clfractal/small_components.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

using testutil::curve;

namespace {

// D(s) of `v` at isovalue j of `iso` from the reference counts of G and G'.
struct RefCurve {
    std::vector<std::uint64_t> i0, i1;
    double fd(std::size_t j) const { return i0[j] && i1[j] ? std::log2(double(i0[j]) / double(i1[j])) : NAN; }
};
RefCurve reference_curve(const Volume& v, const IsovalueSet& iso) {
    return {ref::cubes_histogram(v, iso), ref::cubes_histogram(ref::level(v, 1), iso)};
}

// Three nested materials: 20 outside, 100 in a shell, 180 in the core, boundaries blurred
// over a few voxels (erf of the distance to the centre), plus uniform noise +-noise, uint8.
Volume nested_materials(std::size_t n, double noise, std::uint32_t seed) {
    Volume v(Dims{n, n, n}, ValueType::uint8);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-noise, noise);
    const double c = double(n) / 2, r_outer = 0.42 * double(n), r_inner = 0.23 * double(n);
    auto* p = v.as<std::uint8_t>();
    for (std::size_t z = 0; z < n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const double r = std::sqrt((x - c + 0.3) * (x - c + 0.3) + (y - c + 0.1) * (y - c + 0.1) +
                                           (z - c - 0.2) * (z - c - 0.2));
                const double f = 20 + 40 * (1 - std::erf((r - r_outer) / 1.5)) + 40 * (1 - std::erf((r - r_inner) / 1.5));
                p[v.index(x, y, z)] = std::uint8_t(std::clamp(std::round(f + (noise > 0 ? u(rng) : 0)), 0.0, 255.0));
            }
    return v;
}

// Every entry's D, counts and verdict against the reference; returns the reference curve.
RefCurve check_entries(const Analysis& a, const Volume& v, const std::vector<Recommendation>& entries) {
    const RefCurve r = reference_curve(v, a.isovalues);
    for (const Recommendation& e : entries) {
        CAPTURE(e.isovalue);
        CHECK(e.count == r.i0[e.index]);
        CHECK(e.count_sub == r.i1[e.index]);
        const double d = r.fd(e.index);
        if (std::isnan(d)) CHECK(std::isnan(e.fd));
        else CHECK(e.fd == doctest::Approx(d).epsilon(1e-12));
        CHECK(e.verdict == verdict_of(d, a.options.advice));
        CHECK(e.first <= e.index);
        CHECK(e.index <= e.last);
    }
    return r;
}

// Whether a well-populated isovalue is clean, from the reference curve alone.
bool reference_has_clean(const RefCurve& r, const AdviceOptions& o) {
    const std::uint64_t largest = *std::max_element(r.i0.begin(), r.i0.end());
    for (std::size_t j = 0; j < r.i0.size(); ++j)
        if (double(r.i0[j]) >= std::max(1.0, o.clean_share * double(largest)) && r.fd(j) <= o.clean_fd) return true;
    return false;
}

}  // namespace

TEST_SUITE("advice") {

TEST_CASE("verdicts: clean <= 2.2 < rough < 2.5 <= noisy, undefined for NaN") {
    CHECK(verdict_of(2.2) == Verdict::clean);
    CHECK(verdict_of(2.2000001) == Verdict::rough);
    CHECK(verdict_of(2.4999) == Verdict::rough);
    CHECK(verdict_of(2.5) == Verdict::noisy);
    CHECK(verdict_of(NAN) == Verdict::undefined);
    CHECK(std::string(verdict_name(Verdict::rough)) == "rough");
}

TEST_CASE("recommend: the material boundaries inside a clean band are the peaks of I(s) / h(s)") {
    // One clean band 0..99 with a constant surface; three material plateaus in the histogram
    // (at 0, 50 and 99): the steepest surfaces lie halfway between, at 25 and 75.
    const std::size_t n = 100;
    std::vector<double> fd(n, 2.05);
    std::vector<std::uint64_t> count(n, 1000), hist(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double x = double(k);
        hist[k] = std::uint64_t(50 + 4000 * (std::exp(-x * x / 50) + std::exp(-(x - 50) * (x - 50) / 50) +
                                              std::exp(-(x - 99) * (x - 99) / 50)));
    }
    const std::vector<Recommendation> r = recommend(curve(fd, count), hist);
    REQUIRE(r.size() == 2);
    std::vector<std::size_t> at{r[0].index, r[1].index};
    std::sort(at.begin(), at.end());
    CHECK(at[0] >= 22);
    CHECK(at[0] <= 28);
    CHECK(at[1] >= 72);
    CHECK(at[1] <= 78);
    for (const Recommendation& e : r) {
        CHECK(e.verdict == Verdict::clean);
        CHECK(e.basis == "clean band");
        CHECK(e.first == 0);
        CHECK(e.last == 99);
    }
    // Without a histogram (a streamed curve) the flat band is represented by its middle.
    const std::vector<Recommendation> flat = recommend(curve(fd, count), {});
    REQUIRE(flat.size() == 1);
    CHECK(flat[0].index == 49);
}

TEST_CASE("recommend: clean bands first, widest first; a tiny surface is not well populated") {
    //          0     1     2     3     4     5     6     7     8     9
    std::vector<double> fd{2.6, 2.1, 2.1, 2.3, 2.0, 2.0, 2.0, 2.1, 2.4, 1.9};
    std::vector<std::uint64_t> count{900, 800, 700, 600, 500, 500, 500, 500, 400, 5};
    const std::vector<Recommendation> r = recommend(curve(fd, count), {});
    REQUIRE(r.size() == 2);
    CHECK(r[0].first == 4);  // the band 4..7, wider than 1..2; 9 has 5 cubes < 1% of 900 = 9
    CHECK(r[0].last == 7);
    CHECK(r[1].first == 1);
    CHECK(r[1].last == 2);
    CHECK(r[0].verdict == Verdict::clean);
    CHECK(has_clean_isovalue(curve(fd, count)));
    REQUIRE(noisiest_isovalue(curve(fd, count)).has_value());
    CHECK(*noisiest_isovalue(curve(fd, count)) == 0);
}

TEST_CASE("recommend: nothing clean gives the cleanest quarter, lowest mean D first, never empty") {
    std::vector<double> fd;
    std::vector<std::uint64_t> count;
    for (int k = 0; k < 40; ++k) {
        fd.push_back(2.3 + 0.01 * std::abs(k - 30) + (k < 8 ? 0.005 * k : 0.3));  // lowest near 0..7 and 30
        count.push_back(1000);
    }
    const FdCurve f = curve(fd, count);
    CHECK_FALSE(has_clean_isovalue(f));
    const std::vector<Recommendation> r = recommend(f, {});
    REQUIRE_FALSE(r.empty());
    std::vector<double> sorted = fd;
    std::sort(sorted.begin(), sorted.end());
    const double quarter = sorted[(sorted.size() - 1) / 4];
    double previous_mean = 0;
    for (const Recommendation& e : r) {
        CHECK(e.basis == "cleanest quarter");
        CHECK(e.fd <= quarter);
        CHECK(e.verdict == verdict_of(e.fd));
        double mean = 0;
        for (std::size_t k = e.first; k <= e.last; ++k) mean += fd[k];
        mean /= double(e.last - e.first + 1);
        CHECK(mean >= previous_mean);
        previous_mean = mean;
    }
    // D undefined everywhere: the largest surface, undefined; no cube at all: nothing.
    const std::vector<Recommendation> u = recommend(curve(std::vector<double>(5, NAN), {1, 7, 3, 0, 0}), {});
    REQUIRE(u.size() == 1);
    CHECK(u[0].index == 1);
    CHECK(u[0].verdict == Verdict::undefined);
    CHECK(recommend(curve(std::vector<double>(3, NAN), {0, 0, 0}), {}).empty());
    CHECK_THROWS_AS(recommend(f, {1, 2}), InputError);
    AdviceOptions bad;
    bad.noisy_fd = 2.0;
    CHECK_THROWS_AS(recommend(f, {}, bad), InputError);
}

TEST_CASE("isovalue histogram: vertices per isovalue bin, against a plain count") {
    for (const auto& [type, lo, hi, first, last] :
         {std::tuple{ValueType::int16, -20, 40, -5, 30}, std::tuple{ValueType::uint8, 0, 255, 3, 200},
          std::tuple{ValueType::uint16, 100, 900, 0, 500}}) {
        CAPTURE(value_type_name(type));
        const Volume v = testutil::random_volume(Dims{13, 7, 5}, type, lo, hi, 7);
        const IsovalueSet ints = IsovalueSet::integers(first, last);
        const std::vector<std::uint64_t> h = isovalue_histogram(v, ints);
        for (std::size_t k = 0; k < ints.size(); ++k) {
            std::uint64_t want = 0;
            for (std::size_t i = 0; i < v.vertices(); ++i) want += v.value(i) == ints.value(k);
            CHECK(h[k] == want);
        }
    }
    // 8- and 16-bit data counted by value: volumes of several blocks of 2^20 values and an odd
    // tail (16-bit: from 2^23 values on, the size counted by value), sets within the type, cut by
    // it, and beyond it.
    for (const auto& [type, lo, hi, first, last] :
         {std::tuple{ValueType::uint8, 0, 255, 0, 255}, std::tuple{ValueType::uint8, 20, 90, -5, 300},
          std::tuple{ValueType::int8, -128, 127, -128, 127}, std::tuple{ValueType::int8, -50, 60, -200, 10},
          std::tuple{ValueType::uint16, 0, 65535, 0, 65535}, std::tuple{ValueType::uint16, 900, 4000, 3000, 70000},
          std::tuple{ValueType::int16, -32768, 32767, -32768, 32767}, std::tuple{ValueType::int16, -300, 200, -40000, -100}}) {
        CAPTURE(value_type_name(type));
        CAPTURE(first);
        const Dims d = value_size(type) == 1 ? Dims{131, 67, 241} : Dims{259, 177, 183};
        const Volume v = testutil::random_volume(d, type, lo, hi, 9);
        std::map<double, std::uint64_t> count;
        for (std::size_t i = 0; i < v.vertices(); ++i) ++count[v.value(i)];
        const IsovalueSet ints = IsovalueSet::integers(first, last);
        const std::vector<std::uint64_t> h = isovalue_histogram(v, ints);
        REQUIRE(h.size() == ints.size());
        for (std::size_t k = 0; k < ints.size(); ++k) {
            const auto it = count.find(ints.value(k));
            CHECK(h[k] == (it == count.end() ? 0 : it->second));
        }
    }
    // A list of isovalues: the values from each to the next, on float data and on 16-bit data.
    const IsovalueSet list = IsovalueSet::floats({-3.f, -0.5f, 0.f, 2.5f, 4.f});
    for (const Volume& f : {testutil::random_volume(Dims{11, 6, 4}, ValueType::float32, -10, 10, 8),
                            testutil::random_volume(Dims{11, 6, 4}, ValueType::int16, -10, 10, 8)}) {
        CAPTURE(value_type_name(f.type()));
        const std::vector<std::uint64_t> hf = isovalue_histogram(f, list);
        for (std::size_t k = 0; k < list.size(); ++k) {
            const double hi = k + 1 < list.size() ? list.value(k + 1) : INFINITY;
            std::uint64_t want = 0;
            for (std::size_t i = 0; i < f.vertices(); ++i) want += f.value(i) >= list.value(k) && f.value(i) < hi;
            CHECK(hf[k] == want);
        }
    }
}

// `j` without its wall times (every key "seconds" or "seconds_*", at any depth).
nlohmann::json without_seconds(nlohmann::json j) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end();)
            if (it.key().rfind("seconds", 0) == 0) it = j.erase(it);
            else *it = without_seconds(*it), ++it;
    } else if (j.is_array()) {
        for (auto& e : j) e = without_seconds(e);
    }
    return j;
}

TEST_CASE("prepare_analysis: the host part by plain loops; analyse with it gives analyse's answer") {
    AnalysisOptions o;
    o.noise_level = o.surface_noise = false;
    for (const ValueType type : {ValueType::int16, ValueType::uint16, ValueType::int8, ValueType::uint8, ValueType::float32}) {
        CAPTURE(value_type_name(type));
        const bool is_unsigned = type == ValueType::uint16 || type == ValueType::uint8;
        const Volume v = testutil::random_volume(Dims{19, 13, 11}, type, is_unsigned ? 3 : -40, 90, 5);
        const AnalysisInput in = prepare_analysis(v, o);
        double lo = INFINITY, hi = -INFINITY;
        for (std::size_t i = 0; i < v.vertices(); ++i) lo = std::min(lo, v.value(i)), hi = std::max(hi, v.value(i));
        CHECK(in.stats.min == lo);
        CHECK(in.stats.max == hi);
        CHECK(in.stats.nan + in.stats.inf == 0);
        const IsovalueSet want = IsovalueSet::for_range(type, lo, hi, o.bins);
        REQUIRE(in.isovalues.size() == want.size());
        for (std::size_t k = 0; k < want.size(); ++k) CHECK(in.isovalues.value(k) == want.value(k));
        REQUIRE(in.histogram.size() == want.size());
        for (std::size_t k = 0; k < want.size(); ++k) {
            const double hi_k = k + 1 < want.size() ? want.value(k + 1) : INFINITY;
            std::uint64_t n = 0;
            for (std::size_t i = 0; i < v.vertices(); ++i) n += v.value(i) >= want.value(k) && v.value(i) < hi_k;
            CHECK(in.histogram[k] == n);
        }
        CHECK(in.seconds >= 0);
        nlohmann::json a = nlohmann::json::parse(to_json(analyse(ctx(), v, o)));
        const Analysis prepared = analyse(ctx(), v, o, in);
        CHECK(prepared.seconds >= in.seconds);
        CHECK(prepared.seconds_prepare == in.seconds);
        nlohmann::json b = nlohmann::json::parse(to_json(prepared));
        CHECK(without_seconds(a) == without_seconds(b));
    }
    // The input of other values is refused, not trusted: another volume of the same shape and
    // type, and a copy of the same values.
    const Volume one = testutil::random_volume(Dims{5, 4, 3}, ValueType::uint8, 0, 9, 2);
    const Volume other = testutil::random_volume(Dims{5, 4, 3}, ValueType::uint8, 0, 9, 3);
    const Volume copy = one;
    CHECK_THROWS_AS(analyse(ctx(), other, o, prepare_analysis(one, o)), std::invalid_argument);
    CHECK_THROWS_AS(analyse(ctx(), copy, o, prepare_analysis(one, o)), std::invalid_argument);
    CHECK_NOTHROW(analyse(ctx(), one, o, prepare_analysis(one, o)));
}

TEST_CASE("analyse: a recommendation between each pair of nested materials, all clean by the reference") {
    for (double noise : {0.0, 3.0}) {
        CAPTURE(noise);
        const Volume v = nested_materials(48, noise, 11);
        AnalysisOptions o;
        o.noise_level = o.surface_noise = false;
        const Analysis a = analyse(ctx(), v, o);
        REQUIRE_FALSE(a.recommended.empty());
        CHECK(a.clean);
        CHECK(a.denoise.empty());
        bool outer = false, inner = false;
        for (const Recommendation& e : a.recommended) {
            CHECK(e.verdict == Verdict::clean);
            outer = outer || (e.isovalue > 30 && e.isovalue < 90);
            inner = inner || (e.isovalue > 110 && e.isovalue < 170);
        }
        CHECK(outer);
        CHECK(inner);
        check_entries(a, v, a.recommended);
        // Components: the curve's, which the components suite checks against BFS labelling.
        const ComponentCurve c = count_components(ctx(), v, a.isovalues);
        for (const Recommendation& e : a.recommended) CHECK(e.components == c.components[e.index]);
        {
            // The same when the device labels them (Tuning::labelling: what GPUs do).
            testutil::TuningGuard guard;
            ctx().tuning.labelling = LabellingPath::device;
            const Analysis ad = analyse(ctx(), v, o);
            REQUIRE(ad.recommended.size() == a.recommended.size());
            for (const Recommendation& e : ad.recommended) CHECK(e.components == c.components[e.index]);
        }
        // The noisiest entry's only with the whole curve (-1: not computed).
        REQUIRE(a.noisiest.has_value());
        CHECK(a.noisiest->components == -1);
        AnalysisOptions oc = o;
        oc.components = ComponentsScope::curve;
        oc.denoise = false;
        const Analysis ac = analyse(ctx(), v, oc);
        REQUIRE(ac.noisiest.has_value());
        CHECK(ac.noisiest->index == a.noisiest->index);
        CHECK(ac.noisiest->components == c.components[a.noisiest->index]);
        for (std::size_t i = 0; i < a.recommended.size(); ++i) CHECK(ac.recommended[i].components == a.recommended[i].components);
    }
}

TEST_CASE("analyse: nothing clean, the denoising ladder finds a clean isovalue, reproducible") {
    const Volume v = make_synthetic("noisy-sphere", SyntheticOptions{48, 30.0, 1, 10, ValueType::uint8});
    AnalysisOptions o;
    o.noise_level = o.surface_noise = false;
    const Analysis a = analyse(ctx(), v, o);
    const RefCurve r = check_entries(a, v, a.recommended);
    CHECK_FALSE(reference_has_clean(r, o.advice));
    CHECK_FALSE(a.clean);
    CHECK(a.best().basis == "cleanest quarter");
    REQUIRE_FALSE(a.denoise.empty());
    const DenoiseAttempt& last = a.denoise.back();
    REQUIRE(last.clean);
    REQUIRE(last.targeted);
    for (std::size_t i = 0; i + 1 < a.denoise.size(); ++i) CHECK_FALSE(a.denoise[i].clean);
    // The filter the attempt names, run again, gives a volume whose reference curve is clean
    // where the attempt says.
    Volume t = targeted_filter(ctx(), v, FilterSpec::median(), last.isovalue, last.threshold, last.window).volume;
    if (last.small_components) t = small_components_filter(t, last.isovalue, last.small_components).volume;
    std::size_t changed = 0;
    for (std::size_t i = 0; i < v.vertices(); ++i) changed += t.value(i) != v.value(i);
    CHECK(double(changed) / double(v.vertices()) == doctest::Approx(last.changed_share).epsilon(1e-12));
    const RefCurve after = reference_curve(t, a.isovalues);
    REQUIRE_FALSE(last.recommended.empty());
    const Recommendation& e = last.recommended.front();
    CHECK(e.verdict == Verdict::clean);
    CHECK(after.fd(e.index) <= 2.2);
    CHECK(after.fd(e.index) == doctest::Approx(e.fd).epsilon(1e-12));
    const std::string cmd = last.command("in.nrrd", "out.nrrd");
    CHECK(cmd.find("clfractal filter in.nrrd --median --fractal --iso ") == 0);
    CHECK(cmd.find(" -o out.nrrd") != std::string::npos);
}

TEST_CASE("analyse: correlated noise takes the median everywhere, then small components, not the targeted median") {
    // A sphere's distance field (48^3, about 10 grey values a voxel across its surfaces) plus
    // white Gaussian noise of standard deviation 2 and Gaussian noise smoothed by a Gaussian of
    // 0.6 voxels rescaled to 30: no isovalue clean, and the noise level reads the noise as
    // correlated (sigma over 1.5 sigma_white). The white ladder would start with the targeted
    // median.
    const double white = 2.0, correlated = 30.0;
    SyntheticOptions so;
    so.size = 48;
    so.type = ValueType::float32;
    const Volume sphere = make_synthetic("sphere", so);
    NoiseOptions no;
    no.kind = NoiseKind::gaussian;
    no.amplitude = 1;
    no.seed = 21;
    const Volume zero(sphere.dims(), ValueType::float32);
    const Volume smoothed = gaussian_filter(ctx(), add_noise(ctx(), zero, no), 0.6);
    no.seed = 22;
    const Volume fine = add_noise(ctx(), zero, no);
    double sum2 = 0;
    for (std::size_t i = 0; i < smoothed.vertices(); ++i) sum2 += smoothed.value(i) * smoothed.value(i);
    const double scale = correlated / std::sqrt(sum2 / double(smoothed.vertices()));
    Volume v(sphere.dims(), ValueType::float32);
    for (std::size_t i = 0; i < v.vertices(); ++i)
        v.as<float>()[i] = float(sphere.value(i) + scale * smoothed.value(i) + white * fine.value(i));
    AnalysisOptions o;
    o.surface_noise = false;
    const Analysis a = analyse(ctx(), v, o);
    REQUIRE(a.noise_level);
    CHECK(noise_is_correlated(*a.noise_level));
    REQUIRE_FALSE(a.clean);
    REQUIRE_FALSE(a.denoise.empty());
    CHECK(a.denoise.size() <= 2);
    const DenoiseAttempt& first = a.denoise.front();
    CHECK_FALSE(first.targeted);
    CHECK(first.small_components == 0);
    CHECK(first.filter == "median");
    // Each attempt's volume, made again from what it names: its changed share and its
    // recommendations' dimensions by the reference.
    Volume t = median_filter(ctx(), v);
    for (const DenoiseAttempt& d : a.denoise) {
        CAPTURE(d.filter);
        CHECK_FALSE(d.targeted);
        if (d.small_components) {
            CHECK(d.small_components == 20);
            t = small_components_filter(t, d.isovalue, d.small_components).volume;
        }
        std::size_t changed = 0;
        for (std::size_t i = 0; i < v.vertices(); ++i) changed += t.value(i) != v.value(i);
        CHECK(double(changed) / double(v.vertices()) == doctest::Approx(d.changed_share).epsilon(1e-12));
        const RefCurve after = reference_curve(t, a.isovalues);
        for (const Recommendation& e : d.recommended) CHECK(after.fd(e.index) == doctest::Approx(e.fd).epsilon(1e-12));
    }
    if (a.denoise.size() == 2) CHECK(a.denoise[1].filter == "median and small components (K 20)");
}

TEST_CASE("analysis JSON: the schema's keys, the entries equal the structs") {
    const Volume v = nested_materials(32, 2.0, 3);
    AnalysisOptions o;
    o.fd4 = true;
    const Analysis a = analyse(ctx(), v, o);
    const nlohmann::json j = nlohmann::json::parse(to_json(a));
    for (const char* key : {"isovalues", "advice", "fd", "clean_bands", "clean", "recommended", "noisiest", "noise",
                            "fd4", "denoise", "curve", "seconds_analysis", "seconds_prepare", "seconds_components"})
        CHECK_MESSAGE(j.contains(key), key);
    // The parts of the analysis's wall time: its own host pass and the labelling, within it.
    CHECK(j["seconds_prepare"].get<double>() > 0);
    CHECK(j["seconds_components"].get<double>() > 0);
    CHECK(j["seconds_prepare"].get<double>() + j["seconds_components"].get<double>() <=
          j["seconds_analysis"].get<double>());
    CHECK(j["noise"].contains("sigma"));
    CHECK(j["noise"]["surface"].contains("ratio"));
    REQUIRE(j["recommended"].size() == a.recommended.size());
    for (std::size_t i = 0; i < a.recommended.size(); ++i) {
        const nlohmann::json& e = j["recommended"][i];
        CHECK(e["isovalue"].get<double>() == a.recommended[i].isovalue);
        CHECK(e["count"].get<std::uint64_t>() == a.recommended[i].count);
        CHECK(e["components"].get<std::int64_t>() == a.recommended[i].components);
        CHECK(e["verdict"].get<std::string>() == verdict_name(a.recommended[i].verdict));
    }
    CHECK(j["curve"].size() == a.isovalues.size());
    if (std::isnan(a.noise_level->sigma)) CHECK(j["noise"]["sigma"].is_null());
    else CHECK(j["noise"]["sigma"].get<double>() == a.noise_level->sigma);
}

TEST_CASE("the C ABI gives the C++ analysis: the same recommendations and JSON entries") {
    const Volume v = make_synthetic("noisy-sphere", SyntheticOptions{40, 20.0, 2, 10, ValueType::uint8});
    AnalysisOptions o;
    const Analysis a = analyse(ctx(), v, o);
    clf_context* c = nullptr;
    REQUIRE(clf_context_create(nullptr, &c) == CLF_OK);
    clf_volume* cv = nullptr;
    REQUIRE(clf_volume_create(v.data(), 40, 40, 40, CLF_UINT8, &cv) == CLF_OK);
    clf_analysis* ca = nullptr;
    REQUIRE(clf_analyse(c, cv, nullptr, &ca) == CLF_OK);
    REQUIRE(clf_analysis_recommended(ca) == a.recommended.size());
    for (std::size_t i = 0; i < a.recommended.size(); ++i) {
        clf_recommendation e;
        REQUIRE(clf_analysis_recommendation(ca, i, &e) == CLF_OK);
        CHECK(e.isovalue == a.recommended[i].isovalue);
        CHECK(e.count == a.recommended[i].count);
        CHECK(e.count_sub == a.recommended[i].count_sub);
        CHECK(e.components == a.recommended[i].components);
        CHECK(e.verdict == int(a.recommended[i].verdict));
        CHECK((std::isnan(e.fd) ? std::isnan(a.recommended[i].fd) : e.fd == a.recommended[i].fd));
    }
    clf_recommendation out;
    CHECK(clf_analysis_recommendation(ca, a.recommended.size(), &out) == CLF_ERROR_INPUT);
    CHECK(clf_analysis_clean(ca) == int(a.clean));
    CHECK(clf_analysis_noise_sigma(ca) == a.noise_level->sigma);
    clf_noise_level nl;
    REQUIRE(clf_analysis_noise_level(ca, &nl) == CLF_OK);
    const auto same = [](double x, double y) { return std::isnan(y) ? std::isnan(x) : x == y; };
    CHECK(same(nl.sigma, a.noise_level->sigma));
    CHECK(same(nl.sigma_white, a.noise_level->sigma_white));
    CHECK(nl.flat_share == a.noise_level->flat_share);
    for (int k = 0; k < 3; ++k) {
        CHECK(same(nl.correlation[k], a.noise_level->correlation[k]));
        CHECK(same(nl.spread[k], a.noise_level->spread[k]));
    }
    CHECK(clf_analysis_noise_level(ca, nullptr) == CLF_ERROR_INPUT);
    const nlohmann::json jc = nlohmann::json::parse(clf_analysis_json(ca));
    const nlohmann::json jx = nlohmann::json::parse(to_json(a));
    CHECK(jc["recommended"] == jx["recommended"]);
    CHECK(jc["denoise"]["attempts"].size() == jx["denoise"]["attempts"].size());
    clf_analysis_destroy(ca);
    CHECK(clf_analyse(c, nullptr, nullptr, &ca) == CLF_ERROR_INPUT);
    clf_volume_destroy(cv);
    clf_context_destroy(c);
}

}  // TEST_SUITE("advice")

TEST_SUITE("realdata") {

TEST_CASE("analyse on every volume of ../shared/data: never empty, first clean when one is, by the reference") {
    const std::filesystem::path dir = CLFRACTAL_SHARED_DATA;
    if (!std::filesystem::exists(dir / "MANIFEST.tsv")) {
        MESSAGE("skipped: no " << dir.string());
        return;
    }
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".raw") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    REQUIRE_FALSE(files.empty());
    for (const auto& file : files) {
        CAPTURE(file.filename().string());
        const Volume v = read_volume(file.string());
        AnalysisOptions o;
        o.components = ComponentsScope::none;
        o.noise_level = o.surface_noise = o.denoise = false;
        const Analysis a = analyse(ctx(), v, o);
        REQUIRE_FALSE(a.recommended.empty());
        const RefCurve r = check_entries(a, v, a.recommended);
        const bool clean = reference_has_clean(r, o.advice);
        CHECK(a.clean == clean);
        const std::uint64_t largest = *std::max_element(r.i0.begin(), r.i0.end());
        for (const Recommendation& e : a.recommended) {
            CHECK(double(e.count) >= o.advice.clean_share * double(largest));
            if (clean) CHECK(r.fd(e.index) <= o.advice.clean_fd);
        }
        if (clean) CHECK(a.best().verdict == Verdict::clean);
    }
}

}  // TEST_SUITE("realdata")
