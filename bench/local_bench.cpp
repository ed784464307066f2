// Local fractal dimension throughput (docs/definitions.md §31 "Timing"): the device field
// against the OpenMP implementation of the same algorithm and the device's copy bandwidth, in
// the same run. bench/local_bench.py runs this and the numpy peer (bench/local_numpy.py) side
// by side.
//
//   clfractal_local_bench [--size N]... [--window K] [--repeats R] [--out DIR]
//
// Cases: noisy-sphere (uint8) at s = 128 and torus (float32) at s = N/16, for each N. Prints
// one JSON object; with --out, also writes each case's volume and device field as NRRD so
// that a peer can time the same input and check its output against ours.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "bench_harness.hpp"
#include "clfractal/local.hpp"
#include "clfractal/sat.hpp"
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "baselines.hpp"

using namespace clfractal;

namespace {

// Largest |a - b| over the vertices where both are defined; -1 when the NaN patterns differ.
double max_difference(const Volume& a, const Volume& b) {
    const float* p = a.as<float>();
    const float* q = b.as<float>();
    double err = 0;
    for (std::size_t i = 0; i < a.vertices(); ++i) {
        if (std::isnan(p[i]) != std::isnan(q[i])) return -1;
        if (!std::isnan(p[i])) err = std::max(err, std::fabs(double(p[i]) - double(q[i])));
    }
    return err;
}

}  // namespace

int main(int argc, char** argv) {
    BenchCli cli{"local fractal dimension throughput: device vs OpenMP", 3};
    CLI::App& app = cli.app;
    const int& repeats = cli.repeats;
    std::vector<std::size_t> sizes{256};
    int window = 8;
    std::string out;
    app.add_option("--size", sizes, "N of the N^3 cases (repeatable)");
    app.add_option("--window", window, "window k");
    app.add_option("--out", out, "directory for the case volumes and device fields (NRRD)");
    if (const int rc = cli.parse(argc, argv); rc >= 0) return rc;

    try {
        Context& ctx = Context::shared();
        nlohmann::json report = bench_header(ctx, repeats);
        report.update({{"window", window}, {"copy_gb_per_s", measure_copy_bandwidth(ctx)}});
        const double compile0 = ctx.compile_seconds();
        nlohmann::json rows = nlohmann::json::array();
        nlohmann::json scans = nlohmann::json::array();
        for (std::size_t n : sizes) {
            SyntheticOptions o;
            o.size = n;
            {
                // The summed-area table alone (32-bit, in place on the device): three axis
                // scans, each reading and writing the table once.
                const Dims d{n, n, n};
                Buffer<cl_uint> table(ctx, d.vertices());
                table.fill(ctx.queue(), 1);
                summed_area_table(ctx, table, d);  // warm-up
                ctx.queue().finish();
                const double t = best_of(repeats, [&] {
                    summed_area_table(ctx, table, d);
                    ctx.queue().finish();
                });
                const double bytes = 3.0 * 2.0 * double(table.bytes());
                scans.push_back({{"size", n}, {"seconds", t}, {"gb_per_s", bytes / t / 1e9}});
            }
            struct Case {
                std::string name;
                double iso;
            };
            for (const Case& c : {Case{"noisy-sphere", 128.0}, Case{"torus", double(n) / 16}}) {
                std::cerr << "local_bench: " << c.name << " " << n << "^3\n";
                const Volume v = make_synthetic(c.name, o);
                const std::string label = std::string(value_type_name(v.type())) + " " + c.name + " " +
                                          std::to_string(n) + "^3";
                // Warm-up: compiles and first launches.
                const Volume ld = local_fractal_dimension(ctx, v, c.iso, window);
                const Volume cpu = local_fractal_dimension_openmp(v, c.iso, window);
                const double host_call = best_of(repeats, [&] { local_fractal_dimension(ctx, v, c.iso, window); });
                // The field of a volume already on the device, left there (what later stages use).
                const DeviceVolume values(ctx, v);
                const double resident = best_of(repeats, [&] {
                    local_fractal_dimension(values, c.iso, window);
                    ctx.queue().finish();
                });
                const double openmp = best_of(repeats, [&] { local_fractal_dimension_openmp(v, c.iso, window); });
                const double voxels = double(v.vertices());
                // Least traffic of the whole call: read the volume once, write the field once.
                const double bytes = double(v.size_bytes() + ld.size_bytes());
                const double diff = max_difference(ld, cpu);
                nlohmann::json row{{"case", label},
                                   {"voxels", voxels},
                                   {"iso", c.iso},
                                   {"defined", summarize_local(ld).defined},
                                   {"device_seconds", host_call},
                                   {"device_gvoxels_per_s", voxels / host_call / 1e9},
                                   {"device_gb_per_s", bytes / host_call / 1e9},
                                   {"resident_seconds", resident},
                                   {"resident_gvoxels_per_s", voxels / resident / 1e9},
                                   {"openmp_seconds", openmp},
                                   {"openmp_gvoxels_per_s", voxels / openmp / 1e9},
                                   {"speedup_vs_openmp", openmp / host_call},
                                   {"openmp_max_difference", diff},
                                   {"openmp_agrees", diff >= 0 && diff <= 1e-6}};
                if (!out.empty()) {
                    std::filesystem::create_directories(out);
                    const std::string stem = out + "/" + c.name + "_" + std::to_string(n);
                    write_nrrd(v, stem + ".nrrd");
                    write_nrrd(ld, stem + "_ld.nrrd");
                    row["volume"] = stem + ".nrrd";
                    row["field"] = stem + "_ld.nrrd";
                }
                rows.push_back(row);
            }
        }
        report["compile_seconds"] = ctx.compile_seconds() - compile0;
        report["cases"] = rows;
        report["sat_scans"] = scans;
        std::cout << report.dump(1) << "\n";
        for (auto& r : rows)
            if (!r["openmp_agrees"].get<bool>()) return 1;
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "local_bench: " << e.what() << "\n";
        return 1;
    }
}
