// Independent checks of `clfractal report`:
//   report_check curve VOLUME REPORT.json
//     recomputes the curve with the plain references (test/reference: the span counts of
//     levels 0 and 1 by the difference histogram, components by breadth-first search) and
//     checks that the clean bands of the JSON are exactly the maximal runs of clean
//     isovalues, that every recommended isovalue is clean (D <= clean_fd, I >= clean_share x
//     the largest) and in one of them, or, when no isovalue is clean, among the cleanest
//     quarter of the well-populated ones, with the JSON's counts, D and components, that
//     recommended is never empty when a cube is intersected, and that the noisiest
//     well-populated isovalue is the largest D among the well-populated ones.
//   report_check screenshot SHOT.png
//     decodes a browser screenshot (libpng) and checks it is not blank: many distinct colours,
//     a share of non-white pixels, and pixels of the LD colour map's blue and red ends.
//   report_check canvas FIRST.png SECOND.png [RECOMMENDED.png]
//     the first 3D view's canvas before and after a switch of isovalue: >= 0.5% red and
//     >= 0.5% blue pixels in the first (or blue in the recommended view's canvas, when
//     given), >= 5% of the pixels changed.
// Exit 0 when everything holds, 1 with one line per failure otherwise.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>

#include "clfractal/render.hpp"
#include "clfractal/volume_io.hpp"
#include "reference/mesh_reference.hpp"
#include "reference/span_reference.hpp"

using namespace clfractal;
using json = nlohmann::json;

namespace {

int failures = 0;
void fail(const std::string& what) {
    std::cout << "FAIL: " << what << "\n";
    ++failures;
}
double number(const json& x) { return x.is_null() ? NAN : x.get<double>(); }

int check_curve(const std::string& volume, const std::string& json_path) {
    std::ifstream in(json_path);
    const json j = json::parse(in);
    const Volume v = read_volume(volume);
    const IsovalueSet iso = IsovalueSet::for_volume(v, j["isovalues"]["count"].get<std::size_t>());
    if (iso.size() != j["isovalues"]["count"].get<std::size_t>()) fail("isovalue count differs");
    const std::vector<std::uint64_t> i0 = ref::cubes_histogram(v, iso), i1 = ref::cubes_histogram(ref::level(v, 1), iso);
    const double max_fd = j["advice"]["clean_fd"].get<double>(), share = j["advice"]["clean_share"].get<double>();
    const std::uint64_t largest = *std::max_element(i0.begin(), i0.end());
    const double floor_count = std::max(1.0, share * double(largest));
    std::vector<double> d(iso.size());
    std::vector<char> clean(iso.size());
    for (std::size_t k = 0; k < iso.size(); ++k) {
        d[k] = i0[k] && i1[k] ? std::log2(double(i0[k]) / double(i1[k])) : NAN;
        clean[k] = !std::isnan(d[k]) && d[k] <= max_fd && double(i0[k]) >= floor_count;
    }
    auto index_of = [&](double s) {
        for (std::size_t k = 0; k < iso.size(); ++k)
            if (iso.value(k) == s) return k;
        fail("isovalue " + std::to_string(s) + " is not one of the curve's");
        return std::size_t(0);
    };

    // The maximal runs of clean isovalues, as sets of (first, last).
    std::set<std::pair<std::size_t, std::size_t>> runs, bands;
    for (std::size_t k = 0; k < iso.size();) {
        if (!clean[k]) {
            ++k;
            continue;
        }
        const std::size_t first = k;
        while (k < iso.size() && clean[k]) ++k;
        runs.insert({first, k - 1});
    }
    for (const json& b : j["clean_bands"]) {
        const std::size_t first = index_of(b["first"].get<double>()), last = index_of(b["last"].get<double>());
        bands.insert({first, last});
        if (index_of(b["isovalue"].get<double>()) != first + (last - first) / 2)
            fail("band " + std::to_string(first) + ".." + std::to_string(last) + ": the representative is not its middle");
    }
    if (runs != bands)
        fail("clean bands: the JSON has " + std::to_string(bands.size()) + ", the reference curve " +
             std::to_string(runs.size()) + " (or they differ)");

    const json& rec = j["recommended"];
    // Never empty when a cube is intersected; clean entries whenever a clean isovalue exists,
    // else entries among the cleanest quarter of the well-populated isovalues.
    const bool any_clean = !runs.empty();
    if (j["clean"].get<bool>() != any_clean) fail("\"clean\" differs from the reference");
    if (rec.empty() != (largest == 0)) fail("recommended is empty with intersected cubes, or not empty without");
    std::vector<double> populated;
    for (std::size_t k = 0; k < iso.size(); ++k)
        if (!std::isnan(d[k]) && double(i0[k]) >= floor_count) populated.push_back(d[k]);
    std::sort(populated.begin(), populated.end());
    const double quarter = populated.empty() ? NAN : populated[(populated.size() - 1) / 4];
    std::size_t checked = 0;
    auto check_point = [&](const json& r, const std::string& what) {
        const std::size_t k = index_of(r["isovalue"].get<double>());
        if (r["count"].get<std::uint64_t>() != i0[k]) fail(what + ": count differs from the reference");
        if (r["count_sub"].get<std::uint64_t>() != i1[k]) fail(what + ": count_sub differs from the reference");
        if (!(std::abs(number(r["fd"]) - d[k]) <= 1e-12)) fail(what + ": D differs from the reference");
        const std::size_t below = ref::components(v, iso.value(k), false, ref::Adjacency::six);
        const std::size_t above = ref::components(v, iso.value(k), true, ref::Adjacency::twenty_six);
        const std::int64_t want = below && above ? std::int64_t(below + above) - 1 : 0;
        if (r["components"].get<std::int64_t>() != want)
            fail(what + ": components " + r["components"].dump() + ", breadth-first search " + std::to_string(want));
        return k;
    };
    for (std::size_t i = 0; i < rec.size(); ++i) {
        const std::string what = "recommended " + rec[i]["isovalue"].dump();
        const std::size_t k = check_point(rec[i], what);
        const bool in_band = runs.count({index_of(rec[i]["first"].get<double>()), index_of(rec[i]["last"].get<double>())});
        if (!any_clean) {
            if (!(d[k] <= quarter) || double(i0[k]) < floor_count)
                fail(what + " is not among the cleanest quarter of the well-populated isovalues");
            else
                ++checked;
        } else if (!in_band)
            fail(what + ": its band is not a maximal run of clean isovalues");
        else if (!clean[k])
            fail(what + " is not clean: D " + std::to_string(d[k]) + ", I " + std::to_string(i0[k]) + " (floor " +
                 std::to_string(floor_count) + ")");
        else
            ++checked;
    }
    // The noisiest well-populated isovalue.
    std::size_t noisiest = iso.size();
    for (std::size_t k = 0; k < iso.size(); ++k)
        if (!std::isnan(d[k]) && double(i0[k]) >= floor_count && (noisiest == iso.size() || d[k] > d[noisiest]))
            noisiest = k;
    if (noisiest == iso.size() ? !j["noisiest"].is_null()
                               : j["noisiest"].is_null() || check_point(j["noisiest"], "noisiest") != noisiest)
        fail("noisiest well-populated isovalue differs from the reference");
    std::cout << "curve: " << iso.size() << " isovalues, " << runs.size() << " clean runs, " << checked
              << " recommended isovalues " << (any_clean ? "clean" : "among the cleanest quarter") << " by the reference (largest I " << largest << ")";
    if (noisiest < iso.size()) std::cout << ", noisiest " << iso.text(noisiest) << " at D " << d[noisiest];
    std::cout << "\n";
    return failures ? 1 : 0;
}

int check_screenshot(const std::string& path) {
    const Image img = read_png(path);
    std::set<std::uint32_t> colours;
    std::size_t non_white = 0, blue = 0, red = 0;
    for (std::size_t y = 0; y < img.height; ++y)
        for (std::size_t x = 0; x < img.width; ++x) {
            const auto p = img.pixel(x, y);
            colours.insert(std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2]);
            non_white += p[0] < 240 || p[1] < 240 || p[2] < 240;
            blue += p[2] > 150 && p[0] < 90 && p[1] < 90;
            red += p[0] > 150 && p[1] < 90 && p[2] < 90;
        }
    const double n = double(img.width * img.height), share = double(non_white) / n;
    std::cout << "screenshot: " << img.width << "x" << img.height << ", " << colours.size() << " distinct colours, "
              << 100 * share << "% non-white, " << blue << " blue and " << red << " red pixels\n";
    if (colours.size() < 200) fail("fewer than 200 distinct colours: blank or unstyled");
    if (share < 0.05) fail("less than 5% of the pixels are not white: blank");
    if (blue < 500) fail("no LD-coloured picture (blue end) in the screenshot");
    return failures ? 1 : 0;
}

// The share of pixels of the LD colour map's blue and red ends.
std::array<double, 2> blue_red(const Image& img) {
    std::size_t blue = 0, red = 0;
    for (std::size_t y = 0; y < img.height; ++y)
        for (std::size_t x = 0; x < img.width; ++x) {
            const auto p = img.pixel(x, y);
            blue += p[2] > 100 && p[2] > 2 * p[0] && p[2] > 2 * p[1];
            red += p[0] > 100 && p[0] > 2 * p[1] && p[0] > 2 * p[2];
        }
    const double n = double(img.width * img.height);
    return {double(blue) / n, double(red) / n};
}

// The first 3D view's canvas ("where the noise is") at its first isovalue (the noisiest
// well-populated one) and after the switch to the second: the LD colour map's red and blue ends
// each on >= 0.5% of the first, >= 5% of the pixels changed. With the second view's canvas (the
// recommended surface), blue may be there instead: a noisiest surface may be red all over.
int check_canvas(const std::string& first, const std::string& second, const std::string& reference) {
    const Image a = read_png(first), b = read_png(second);
    if (a.width != b.width || a.height != b.height) {
        fail("the canvas screenshots differ in size");
        return 1;
    }
    std::size_t changed = 0;
    for (std::size_t y = 0; y < a.height; ++y)
        for (std::size_t x = 0; x < a.width; ++x) {
            const auto p = a.pixel(x, y), q = b.pixel(x, y);
            changed += std::abs(int(p[0]) - int(q[0])) + std::abs(int(p[1]) - int(q[1])) + std::abs(int(p[2]) - int(q[2])) > 24;
        }
    const auto c0 = blue_red(a), c1 = blue_red(b);
    const double share = double(changed) / double(a.width * a.height);
    std::cout << "canvas " << a.width << "x" << a.height << ": first " << 100 * c0[0] << "% blue, " << 100 * c0[1]
              << "% red; second " << 100 * c1[0] << "% blue, " << 100 * c1[1] << "% red; " << 100 * share
              << "% changed by the switch";
    double blue = c0[0];
    if (!reference.empty()) {
        const auto cr = blue_red(read_png(reference));
        std::cout << "; the recommended view " << 100 * cr[0] << "% blue, " << 100 * cr[1] << "% red";
        blue = std::max(blue, cr[0]);
    }
    std::cout << "\n";
    if (blue < 0.005) fail(reference.empty() ? "less than 0.5% blue pixels in the first canvas"
                                             : "less than 0.5% blue pixels in the first and the recommended canvas");
    if (c0[1] < 0.005) fail("less than 0.5% red pixels in the first canvas");
    if (share < 0.05) fail("the switch changed less than 5% of the canvas");
    return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const std::string mode = argc > 1 ? argv[1] : "";
        if (mode == "curve" && argc == 4) return check_curve(argv[2], argv[3]);
        if (mode == "screenshot" && argc == 3) return check_screenshot(argv[2]);
        if (mode == "canvas" && (argc == 4 || argc == 5)) return check_canvas(argv[2], argv[3], argc == 5 ? argv[4] : "");
        std::cerr << "usage: report_check curve VOLUME REPORT.json | screenshot SHOT.png | canvas FIRST.png SECOND.png [RECOMMENDED.png]\n";
        return 2;
    } catch (const std::exception& e) {
        std::cout << "FAIL: " << e.what() << "\n";
        return 1;
    }
}
