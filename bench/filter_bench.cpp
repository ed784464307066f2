// Filter throughput (docs/definitions.md §31 "Timing"): median, Gaussian and the
// fractal-targeted median on the device, timed in one run; bench/filter_bench.py runs this and
// the peers (scipy.ndimage, pyclesperanto on the same OpenCL device) side by side and compares
// the outputs.
//
//   clfractal_filter_bench [--size N] [--sigma S] [--iso S] [--threshold H] [--repeats R]
//                          [--volume PATH]... [--out DIR]
//
// Cases: noisy-sphere N^3 as uint8 and as float32 (noise 8), and each --volume (median only).
// Prints one JSON object; with --out, writes every input and output as raw files (x fastest,
// native endianness) named in the JSON, so that a peer can time the same input and check its
// output against ours.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "bench_harness.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"

using namespace clfractal;
using json = nlohmann::json;

namespace {

void write_raw(const Volume& v, const std::string& path) {
    std::ofstream f(path, std::ios::binary);
    f.write(static_cast<const char*>(v.data()), std::streamsize(v.size_bytes()));
    if (!f) throw std::runtime_error("cannot write " + path);
}

json volume_json(const Volume& v, const std::string& path) {
    return {{"path", path}, {"dims", {v.dims().nx, v.dims().ny, v.dims().nz}}, {"type", value_type_name(v.type())}};
}

}  // namespace

int main(int argc, char** argv) {
    BenchCli cli{"filter throughput: median, Gaussian, fractal-targeted median", 3};
    CLI::App& app = cli.app;
    const int& repeats = cli.repeats;
    std::size_t size = 256;
    double sigma = 1, iso = 128, threshold = 2.5;
    int window = 8;
    std::vector<std::string> volumes;
    std::string out;
    app.add_option("--size", size, "N of the N^3 synthetic cases");
    app.add_option("--sigma", sigma, "Gaussian sigma");
    app.add_option("--iso", iso, "isovalue of the targeted filter (float case: the same)");
    app.add_option("--threshold", threshold, "LD threshold h of the targeted filter");
    app.add_option("--window", window, "LD window");
    app.add_option("--volume", volumes, "a real volume: median timed and written (repeatable)");
    app.add_option("--out", out, "directory for inputs and outputs (raw)");
    if (const int rc = cli.parse(argc, argv); rc >= 0) return rc;

    try {
        Context& ctx = Context::shared();
        json report = bench_header(ctx, repeats);
        report.update({{"sigma", sigma}, {"gaussian_radius", FilterSpec::gaussian(sigma).radius()}, {"iso", iso},
                       {"threshold", threshold}, {"window", window}});
        const double compile0 = ctx.compile_seconds();
        if (!out.empty()) std::filesystem::create_directories(out);
        json rows = json::array();

        auto run_case = [&](const std::string& label, const Volume& v, bool full) {
            std::cerr << "filter_bench: " << label << "\n";
            json row{{"case", label}, {"voxels", v.vertices()}};
            const double bytes = 2.0 * double(v.size_bytes());  // one read and one write
            Volume med = median_filter(ctx, v);  // warm-up: compilation and first launches
            const double t_med = best_of(repeats, [&] { median_filter(ctx, v); });
            row["median_seconds"] = t_med;
            row["median_gvoxels_per_s"] = double(v.vertices()) / t_med / 1e9;
            row["median_gb_per_s"] = bytes / t_med / 1e9;
            std::string stem;
            if (!out.empty()) {
                stem = out + "/" + std::to_string(rows.size());
                write_raw(v, stem + "_in.raw");
                write_raw(med, stem + "_median.raw");
                row["input"] = volume_json(v, stem + "_in.raw");
                row["median"] = stem + "_median.raw";
            }
            if (full) {
                Volume g = gaussian_filter(ctx, v, sigma);
                const double t_g = best_of(repeats, [&] { gaussian_filter(ctx, v, sigma); });
                row["gaussian_seconds"] = t_g;
                row["gaussian_gvoxels_per_s"] = double(v.vertices()) / t_g / 1e9;
                // Targeted median: the LD field and the masked filter, against the full median.
                TargetedResult r = targeted_filter(ctx, v, FilterSpec::median(), iso, threshold, window);
                double ld_s = 1e300, filt_s = 1e300;
                const double t_t = best_of(repeats, [&] {
                    TargetedResult x = targeted_filter(ctx, v, FilterSpec::median(), iso, threshold, window);
                    ld_s = std::min(ld_s, x.ld_seconds);
                    filt_s = std::min(filt_s, x.filter_seconds);
                });
                // The masked filter alone, given the field (what a caller with LD at hand pays).
                const Volume ld = local_fractal_dimension(ctx, v, iso, window);
                masked_filter(ctx, v, FilterSpec::median(), ld, threshold);
                const double t_m = best_of(repeats, [&] { masked_filter(ctx, v, FilterSpec::median(), ld, threshold); });
                row["targeted_median_seconds"] = t_t;
                row["targeted_ld_seconds"] = ld_s;
                row["targeted_filter_seconds"] = filt_s;
                row["masked_median_seconds"] = t_m;
                row["targeted_selected_share"] = r.selected_share;
                row["targeted_changed_share"] = r.changed_share;
                row["targeted_over_full"] = t_t / t_med;
                row["masked_over_full"] = t_m / t_med;
                if (!out.empty()) {
                    write_raw(g, stem + "_gaussian.raw");
                    row["gaussian"] = stem + "_gaussian.raw";
                }
            }
            rows.push_back(row);
        };

        for (ValueType t : {ValueType::uint8, ValueType::float32}) {
            SyntheticOptions o;
            o.size = size;
            o.noise = 8;
            o.type = t;
            const Volume v = make_synthetic("noisy-sphere", o);
            run_case(std::string(value_type_name(t)) + " noisy-sphere " + std::to_string(size) + "^3", v, true);
        }
        for (const std::string& path : volumes) {
            const Volume v = read_volume(path);
            run_case(std::filesystem::path(path).filename().string(), v, false);
        }
        report["compile_seconds"] = ctx.compile_seconds() - compile0;
        report["cases"] = rows;
        std::cout << report.dump(1) << "\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "filter_bench: " << e.what() << "\n";
        return 1;
    }
}
