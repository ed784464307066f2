// Slice streaming against the in-core run (docs/definitions.md §28), in the same process: a
// generated N^3 uint8 volume (noisy sphere, made slice by slice) is counted (cubes and edges,
// levels 0..L-1) by SpanStream fed one slice at a time, and by count_spans on the whole volume.
// Prints time, throughput and the process's peak resident memory after each phase, and the
// stream/in-core time ratio; exits 1 if the counts differ. With --mode both, the same for the
// isosurface components at three isovalues: ComponentsAtStream fed one slice at a time
// against count_components_at on the whole volume.
//
//   clfractal_stream_bench [--size N] [--levels L] [--mode both|stream|incore] [--repeats R]
//   clfractal_stream_bench --size N --write FILE.raw     (the same volume to disk, slice by slice)
//
// The stream phase runs first so that its peak memory is not the in-core volume's. For the
// memory bound of a file read from disk: --write a file, then
//   /usr/bin/time -v clfractal fd FILE_NxNxN_uint8.raw --stream
#include <CLI/CLI.hpp>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <vector>

#include "bench_harness.hpp"
#include "clfractal/components.hpp"
#include "clfractal/span.hpp"
#include "clfractal/stream.hpp"

using namespace clfractal;

namespace {

double peak_rss_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // KiB on Linux
}

// Slice z of the noisy sphere: 255 inside radius 0.35 N falling off linearly, plus a
// counter-based noise of +-12 that grows towards +x (so some isovalues are noisier).
void make_slice(std::size_t n, std::size_t z, std::uint8_t* out) {
    const double c = 0.5 * double(n - 1), r0 = 0.35 * double(n);
    for (std::size_t y = 0; y < n; ++y)
        for (std::size_t x = 0; x < n; ++x) {
            const double dx = double(x) - c, dy = double(y) - c, dz = double(z) - c;
            const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
            std::uint64_t h = (x + n * (y + n * z)) * 0x9E3779B97F4A7C15ull;
            h ^= h >> 29;
            h *= 0xBF58476D1CE4E5B9ull;
            h ^= h >> 32;
            const double noise = (double(h % 1001) / 500.0 - 1.0) * 12.0 * double(x) / double(n);
            const double v = 128.0 + 4.0 * (r0 - r) + noise;
            out[x + n * y] = std::uint8_t(std::lround(std::fmin(255.0, std::fmax(0.0, v))));
        }
}

using clock_type = std::chrono::steady_clock;

// Components at three isovalues: ComponentsAtStream fed one slice at a time against
// count_components_at on the whole volume (best of `repeats` each, slice generation not
// timed); returns whether the counts are identical.
bool components_phase(std::size_t n, int repeats) {
    const std::vector<double> at = {64, 128, 192};
    const std::size_t plane = n * n;
    std::vector<std::uint8_t> slice(plane);
    std::vector<std::int64_t> streamed, whole;
    double stream_s = 0, incore_s = 0;
    for (int r = 0; r < repeats; ++r) {
        ComponentsAtStream stream(n, n, ValueType::uint8, at);
        double push = 0;
        for (std::size_t z = 0; z < n; ++z) {
            make_slice(n, z, slice.data());
            const auto t = clock_type::now();
            stream.push_slices(slice.data(), 1);
            push += seconds_since(t);
        }
        streamed = stream.counts();
        if (r == 0 || push < stream_s) stream_s = push;
    }
    std::printf("components    stream of slices: %.3f s (3 isovalues, %.2f Gvoxel/s a pass); peak RSS %.0f MiB\n",
                stream_s, 3.0 * double(plane * n) / stream_s / 1e9, peak_rss_mib());
    Volume v(Dims{n, n, n}, ValueType::uint8);
    for (std::size_t z = 0; z < n; ++z) make_slice(n, z, v.as<std::uint8_t>() + z * plane);
    for (int r = 0; r < repeats; ++r) {
        const auto t = clock_type::now();
        whole = count_components_at(v, at);
        const double s = seconds_since(t);
        if (r == 0 || s < incore_s) incore_s = s;
    }
    std::printf("components    in core: %.3f s; stream / in-core time = %.2f; counts %lld %lld %lld, %s\n", incore_s,
                stream_s / incore_s, (long long)whole[0], (long long)whole[1], (long long)whole[2],
                streamed == whole ? "identical" : "DIFFERENT");
    return streamed == whole;
}

}  // namespace

int main(int argc, char** argv) {
    BenchCli cli{"slice streaming vs in-core span counting", 1};
    CLI::App& app = cli.app;
    const int& repeats = cli.repeats;
    std::size_t n = 512;
    int levels = 2;
    std::string mode = "both", write;
    app.add_option("--size", n, "N of the generated N^3 uint8 volume");
    app.add_option("--levels", levels, "pyramid levels");
    app.add_option("--mode", mode, "both | stream | incore")->check(CLI::IsMember({"both", "stream", "incore"}));
    app.add_option("--write", write, "write the volume to this raw file instead of counting");
    if (const int rc = cli.parse(argc, argv); rc >= 0) return rc;
    if (n < 2) {
        std::cerr << "--size must be at least 2\n";
        return 2;
    }

    try {
        const std::size_t plane = n * n;
        std::vector<std::uint8_t> slice(plane);
        if (!write.empty()) {
            std::ofstream out(write, std::ios::binary);
            for (std::size_t z = 0; z < n; ++z) {
                make_slice(n, z, slice.data());
                out.write(reinterpret_cast<const char*>(slice.data()), std::streamsize(plane));
            }
            if (!out) throw std::runtime_error("cannot write " + write);
            std::printf("wrote %s (%zux%zux%zu uint8)\n", write.c_str(), n, n, n);
            return 0;
        }

        Context& ctx = Context::shared();
        const IsovalueSet iso = IsovalueSet::integers(0, 255);
        std::printf("device        %s\nvolume        %zu^3 uint8 (noisy sphere), 256 isovalues, cubes and edges, "
                    "levels 0..%d\n",
                    ctx.description().c_str(), n, levels - 1);
        SpanResult streamed, whole;
        double stream_s = 0, stream_gen_s = 0, incore_s = 0;
        if (mode != "incore") {
            for (int r = 0; r < repeats; ++r) {
                SpanStream stream(ctx, n, n, ValueType::uint8, iso, levels);
                double push = 0, gen = 0;
                for (std::size_t z = 0; z < n; ++z) {
                    auto t = clock_type::now();
                    make_slice(n, z, slice.data());
                    gen += seconds_since(t);
                    t = clock_type::now();
                    stream.push_slice(slice.data());
                    push += seconds_since(t);
                }
                auto t = clock_type::now();
                streamed = stream.counts();
                push += seconds_since(t);
                if (r == 0 || push < stream_s) stream_s = push, stream_gen_s = gen;
                if (r == 0)
                    std::printf("batch         %zu slices per launch (%.1f MiB of input)\n", stream.batch_slices(),
                                double(stream.batch_slices() * plane) / (1 << 20));
            }
            std::printf("stream        %.3f s (%.2f Gvoxel/s), slices generated in %.3f s; peak RSS %.0f MiB\n",
                        stream_s, double(plane * n) / stream_s / 1e9, stream_gen_s, peak_rss_mib());
        }
        if (mode != "stream") {
            Volume v(Dims{n, n, n}, ValueType::uint8);
            for (std::size_t z = 0; z < n; ++z) make_slice(n, z, v.as<std::uint8_t>() + z * plane);
            const SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, levels, 0};
            for (int r = 0; r < repeats; ++r) {
                const auto t = clock_type::now();
                whole = count_spans(ctx, v, iso, opt);
                const double s = seconds_since(t);
                if (r == 0 || s < incore_s) incore_s = s;
            }
            std::printf("in-core       %.3f s (%.2f Gvoxel/s), %zu slab(s); peak RSS %.0f MiB\n", incore_s,
                        double(plane * n) / incore_s / 1e9, whole.slabs, peak_rss_mib());
        }
        std::printf("compile       %.3f s (kernels, first launches; not in the times above)\n", ctx.compile_seconds());
        if (mode == "both") {
            bool same = true;
            for (std::size_t k = 0; k < 2; ++k) same &= streamed.curves[k].counts == whole.curves[k].counts;
            std::printf("ratio         stream / in-core time = %.2f\ncounts        %s\n", stream_s / incore_s,
                        same ? "identical" : "DIFFERENT");
            if (!same) return 1;
            if (!components_phase(n, repeats)) return 1;
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "clfractal_stream_bench: error: %s\n", e.what());
        return 2;
    }
}
