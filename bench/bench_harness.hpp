// The benchmark harness (docs/definitions.md §31 "Timing"), for the benchmark drivers in bench/
// and `clfractal bench`, outside the installed API: span-curve throughput on the device against
// the device's own copy bandwidth and against the OpenMP baseline, in the same run, and the
// command line and JSON header every driver shares. Compilation is timed apart; every figure is
// the best of `repeats` runs after a warm-up.
#pragma once
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "clfractal/span.hpp"

namespace clfractal {

/// Wall time in seconds of the fastest of `repeats` calls of f().
template <class F> double best_of(int repeats, F f) {
    double best = 1e300;
    for (int i = 0; i < repeats; ++i) {
        auto t0 = std::chrono::steady_clock::now();
        f();
        best = std::min(best, seconds_since(t0));
    }
    return best;
}

struct BenchCase {
    std::string label;   ///< e.g. "uint8 512^3"
    Volume volume;
};

struct BenchRow {
    std::string label;
    std::size_t isovalues = 0;
    double cubes = 0;          ///< cubes counted (levels 0 and 1)
    double bytes = 0;          ///< bytes read: one read of each level
    /// Whole calls: the device's buffers, first launches, upload (GPUs), kernels and
    /// download; the OpenMP threads, histograms and subsampled copy.
    double device_seconds = 0, openmp_seconds = 0;
    /// The device's counting alone (SpanResult::seconds: upload, kernels, download).
    double counting_seconds = 0;
    double device_gcubes() const { return cubes / device_seconds / 1e9; }
    double openmp_gcubes() const { return cubes / openmp_seconds / 1e9; }
    double device_gbs() const { return bytes / counting_seconds / 1e9; }
    double speedup() const { return openmp_seconds / device_seconds; }  ///< > 1: device faster
    bool counts_equal = false;  ///< device and OpenMP counts identical
};

struct BenchReport {
    std::string device;
    int openmp_threads = 0;
    double copy_gbs = 0;         ///< device copy bandwidth (read + write bytes / s)
    double compile_seconds = 0;  ///< compilation and first launches, once per case (PoCL caches on disk)
    std::vector<BenchRow> rows;
};

/// The default cases: noisy spheres, uint8 256^3 and 512^3 (of `size` and 2*size when
/// size != 256) and uint16 256^3 with a full 16-bit value range.
std::vector<BenchCase> default_bench_cases(std::size_t size = 256);

/// Measures every case (levels 0 and 1, cubes). `progress` receives a line per step.
BenchReport run_span_bench(Context& ctx, std::vector<BenchCase>& cases, int repeats = 3,
                           const std::function<void(const std::string&)>& progress = {});

/// Copy bandwidth of the device in GB/s (bytes read + written per second), best of 5.
double measure_copy_bandwidth(Context& ctx, std::size_t bytes = std::size_t(128) << 20);

/// The command line of a benchmark driver: every default shown in --help, and --repeats R
/// (the best of R runs after a warm-up). The driver adds its own options to `app`.
struct BenchCli {
    CLI::App app;
    int repeats;
    BenchCli(const std::string& what, int default_repeats);
    /// Parses argv: -1 to go on, else the exit status (0 after --help, 2 and one line on
    /// stderr for a bad option).
    int parse(int argc, char** argv);
};

/// The fields every benchmark's JSON report starts with: device, OpenMP threads, repeats.
nlohmann::json bench_header(Context& ctx, int repeats);

}  // namespace clfractal
