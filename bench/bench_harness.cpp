#include "bench_harness.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

#include "clfractal/synthetic.hpp"
#include "device/kernel_call.hpp"
#include "baselines.hpp"

namespace clfractal {

namespace {

// A sphere over the whole 16-bit range with noise growing along x (cf. noisy-sphere).
Volume sphere16(std::size_t n) {
    Volume v(Dims{n, n, n}, ValueType::uint16, "sphere16:" + std::to_string(n));
    std::uint16_t* p = v.as<std::uint16_t>();
    const double c = double(n - 1) / 2, r = double(n) / 2;
#pragma omp parallel for
    for (long long z = 0; z < (long long)n; ++z)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                double d = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (double(z) - c) * (double(z) - c));
                std::size_t i = x + n * (y + n * std::size_t(z));
                double f = 65535 * std::clamp(1 - d / r, 0.0, 1.0) + 6000 * double(x) / double(n) * uniform_noise(7, i);
                p[i] = std::uint16_t(std::clamp(std::round(f), 0.0, 65535.0));
            }
    return v;
}

}  // namespace

std::vector<BenchCase> default_bench_cases(std::size_t size) {
    std::vector<BenchCase> cases;
    auto add = [&](const std::string& name, std::size_t n) {
        SyntheticOptions o;
        o.size = n;
        cases.push_back({"uint8 " + std::to_string(n) + "^3", make_synthetic(name, o)});
    };
    add("noisy-sphere", size);
    add("noisy-sphere", 2 * size);
    cases.push_back({"uint16 " + std::to_string(size) + "^3", sphere16(size)});
    return cases;
}

double measure_copy_bandwidth(Context& ctx, std::size_t bytes) {
    bytes = std::min(bytes, ctx.max_alloc()) / 16 * 16;
    return with_cl_errors([&] {
        Buffer<cl_uint4> a(ctx, bytes / 16), b(ctx, bytes / 16);
        a.fill(ctx.queue(), cl_uint4{{1, 2, 3, 4}});
        b.fill(ctx.queue(), cl_uint4{{0, 0, 0, 0}});
        KernelCall<cl::Buffer, cl::Buffer> copy(ctx, "copy", "copy_uint4", "");  // copy_uint4(src, dst)
        copy(cl::NDRange(a.size()), cl::NullRange, a.get(), b.get());  // first launch: counted as compilation
        ctx.queue().finish();
        double t = best_of(5, [&] {
            copy(cl::NDRange(a.size()), cl::NullRange, a.get(), b.get());
            ctx.queue().finish();
        });
        return 2.0 * double(bytes) / t / 1e9;
    });
}

BenchReport run_span_bench(Context& ctx, std::vector<BenchCase>& cases, int repeats,
                           const std::function<void(const std::string&)>& progress) {
    auto say = [&](const std::string& s) { if (progress) progress(s); };
    BenchReport rep;
    rep.device = ctx.description();
    rep.openmp_threads = omp_get_max_threads();
    say("copy bandwidth");
    rep.copy_gbs = measure_copy_bandwidth(ctx);
    SpanOptions opt{{SpanKind::cubes}, 2, 0};
    for (BenchCase& c : cases) {
        say(c.label);
        BenchRow row;
        row.label = c.label;
        IsovalueSet iso = IsovalueSet::for_volume(c.volume);
        row.isovalues = iso.size();
        for (int l = 0; l < 2; ++l) {
            Dims d = level_dims(c.volume.dims(), l);
            row.cubes += double(d.cubes());
            row.bytes += double(d.vertices() * value_size(c.volume.type()));
        }
        const double compile0 = ctx.compile_seconds();
        SpanResult dev = count_spans(ctx, c.volume, iso, opt);  // warm-up, compiles
        rep.compile_seconds += ctx.compile_seconds() - compile0;
        SpanResult cpu = count_spans_openmp(c.volume, iso, opt);
        row.counts_equal = dev.curves[0].counts == cpu.curves[0].counts;
        // Whole calls on both sides: buffers, upload, kernels, download / histograms, threads.
        row.counting_seconds = 1e300;
        row.device_seconds = best_of(repeats, [&] {
            row.counting_seconds = std::min(row.counting_seconds, count_spans(ctx, c.volume, iso, opt).seconds);
        });
        row.openmp_seconds = best_of(repeats, [&] { count_spans_openmp(c.volume, iso, opt); });
        rep.rows.push_back(row);
    }
    return rep;
}

BenchCli::BenchCli(const std::string& what, int default_repeats) : app(what), repeats(default_repeats) {
    app.option_defaults()->always_capture_default();
    app.add_option("--repeats", repeats, "best of this many runs after a warm-up");
}

int BenchCli::parse(int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << app.get_name() << ": error: " << e.what() << "\n";
        return 2;
    }
    return -1;
}

nlohmann::json bench_header(Context& ctx, int repeats) {
    return {{"device", ctx.description()}, {"openmp_threads", omp_get_max_threads()}, {"repeats", repeats}};
}

}  // namespace clfractal
