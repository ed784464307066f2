// clfractal bench: span-curve throughput, device against copy bandwidth and OpenMP.
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "bench_harness.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

using json = nlohmann::json;

struct BenchArgs {
    std::size_t size = 256;
    int repeats = 3;
    std::string json_path;
};

int cmd_bench(std::size_t size, int repeats, const std::string& json_path) {
    Context& ctx = Context::shared();
    progress("building inputs");
    auto cases = default_bench_cases(size);
    BenchReport r = run_span_bench(ctx, cases, repeats, [](const std::string& s) { progress("bench: " + s); });
    std::cout << "device          " << r.device << "\n"
              << "copy bandwidth  " << std::fixed << std::setprecision(2) << r.copy_gbs << " GB/s (read + write)\n"
              << "OpenMP threads  " << r.openmp_threads << "\n"
              << "kernel compile  " << r.compile_seconds << " s (apart from the figures below)\n\n"
              << "span curve, levels 0 and 1, best of " << repeats << ":\n"
              << "  volume        isovalues  device s  Gcubes/s  GB/s  roofline   OpenMP s  Gcubes/s  device/OpenMP  counts\n";
    json rows = json::array();
    for (auto& row : r.rows) {
        std::cout << "  " << std::left << std::setw(13) << row.label << std::right << std::setw(10) << row.isovalues
                  << std::setw(10) << std::setprecision(4) << row.device_seconds << std::setw(10)
                  << std::setprecision(3) << row.device_gcubes() << std::setw(6) << std::setprecision(2)
                  << row.device_gbs() << std::setw(9) << std::setprecision(1)
                  << 100 * row.device_gbs() / r.copy_gbs << "%" << std::setw(11) << std::setprecision(4)
                  << row.openmp_seconds << std::setw(10) << std::setprecision(3) << row.openmp_gcubes()
                  << std::setw(14) << std::setprecision(2) << row.speedup() << "x  "
                  << (row.counts_equal ? "equal" : "DIFFER") << "\n";
        rows.push_back({{"volume", row.label},
                        {"isovalues", row.isovalues},
                        {"cubes", row.cubes},
                        {"bytes", row.bytes},
                        {"device_seconds", row.device_seconds},
                        {"device_counting_seconds", row.counting_seconds},
                        {"device_gcubes_per_s", row.device_gcubes()},
                        {"device_gb_per_s", row.device_gbs()},
                        {"roofline_fraction", row.device_gbs() / r.copy_gbs},
                        {"openmp_seconds", row.openmp_seconds},
                        {"openmp_gcubes_per_s", row.openmp_gcubes()},
                        {"speedup_vs_openmp", row.speedup()},
                        {"counts_equal", row.counts_equal}});
    }
    std::cout << "(device s and OpenMP s: whole calls, buffers and threads included; GB/s and roofline: bytes of\n"
                 " one read per level over the device's counting time (uploads, kernels, downloads) against the\n"
                 " copy bandwidth; device/OpenMP > 1: device faster)\n";
    if (!json_path.empty()) {
        json j{{"device", r.device},
               {"copy_gb_per_s", r.copy_gbs},
               {"openmp_threads", r.openmp_threads},
               {"compile_seconds", r.compile_seconds},
               {"repeats", repeats},
               {"span", rows}};
        write_file_atomic(json_path, j.dump(1) + "\n");
    }
    // A figure above the copy bandwidth measured in the same run cannot be true: it is a
    // timing fault, reported as a failure like a count that differs.
    int status = 0;
    for (auto& row : r.rows) {
        if (!row.counts_equal) status = 1;
        if (row.device_gbs() > r.copy_gbs) {
            std::cerr << "clfractal: bench: " << row.device_gbs() << " GB/s is above the copy bandwidth " << r.copy_gbs
                      << " GB/s: the timing is wrong\n";
            status = 1;
        }
    }
    return status;
}

void setup_bench(CLI::App* c, BenchArgs& a) {
    c->add_option("--size", a.size, "N for the N^3 cases (2N^3 is run too)");
    c->add_option("--repeats", a.repeats, "best of this many runs");
    c->add_option("--json", a.json_path, "write the figures as JSON");
}

}  // namespace

Command bench_command() {
    return command<BenchArgs>("bench", "span-curve throughput: device vs copy bandwidth vs OpenMP", setup_bench,
                              [](const BenchArgs& a) { return cmd_bench(a.size, a.repeats, a.json_path); });
}

}  // namespace cli
