// clfractal fd4 and local4: the 4D fractal dimension of a volume and its local field
// (include/clfractal/fd4.hpp; docs/definitions.md §24 "4D fractal dimension", thesis 6.4).
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>

#include "clfractal/fd4.hpp"
#include "clfractal/local.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace {

struct Fd4Args {
    std::string volume, json, output;
    double q = 0;
    int window = 8;
    cli::RawArgs raw;
};

int run_fd4(const Fd4Args& a) {
    Volume v = cli::read_volume_within(a.volume, a.raw.options(), {"clfractal fd4"});
    Context& ctx = Context::shared();
    cli::progress("4D fractal dimension of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " on " +
                  ctx.description());
    const Fd4Result r = fractal_dimension_4d(ctx, v, a.q);
    const Dims d = v.dims();
    std::cout << "volume      " << a.volume << "  " << dims_string(d) << " " << value_type_name(v.type()) << "\n"
              << std::setprecision(9) << "bins        width q = " << r.q << " from vmin = " << r.vmin
              << " (G' uses 2q)\n"
              << "I4(G, q)    " << r.i4 << "\n"
              << "I4(G', 2q)  " << r.i4_sub << "\n"
              << std::fixed << std::setprecision(4) << "D4          "
              << (std::isnan(r.d4) ? std::string("n/a (a grid without cubes)") : std::to_string(r.d4))
              << "   (3: smooth field, towards 4: noise)\n"
              << std::defaultfloat << "time        " << r.seconds << " s, kernels compiled in "
              << ctx.compile_seconds() << " s\n";
    if (!a.json.empty()) {
        nlohmann::json j;
        j["volume"] = a.volume;
        j["dims"] = {d.nx, d.ny, d.nz};
        j["type"] = value_type_name(v.type());
        j["q"] = r.q;
        j["vmin"] = r.vmin;
        j["i4_l0"] = r.i4;
        j["i4_l1"] = r.i4_sub;
        j["d4"] = cli::fd_json(r.d4);
        write_file_atomic(a.json, j.dump(2) + "\n");
    }
    return 0;
}

int run_local4(const Fd4Args& a) {
    Volume v = cli::read_volume_within(a.volume, a.raw.options(), {"clfractal local4"});
    Context& ctx = Context::shared();
    const double q = a.q ? a.q : default_bin_width(v);
    cli::progress("local 4D fractal dimension of " + dims_string(v.dims()) + " " + value_type_name(v.type()) +
                  ", window " + std::to_string(a.window) + ", on " + ctx.description());
    const auto t0 = std::chrono::steady_clock::now();
    Volume ld4 = local_fractal_dimension_4d(ctx, v, q, a.window);
    const double seconds = seconds_since(t0);
    write_volume(ld4, a.output, &v);
    const LocalSummary s = summarize_local(ld4);
    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n"
              << "device      " << ctx.description() << "\n"
              << std::setprecision(9) << "bins        width q = " << q << ", window " << a.window << "\n"
              << std::fixed << std::setprecision(2) << "defined     " << s.defined << " of " << s.vertices
              << " vertices (" << 100.0 * double(s.defined) / double(s.vertices) << "%)\n";
    if (s.defined) {
        // LD4 lives one dimension up: 3 is smooth, 4 is noise.
        const float* p = ld4.as<float>();
        std::size_t above = 0;
        for (std::size_t i = 0; i < ld4.vertices(); ++i) above += p[i] > 3.5f;
        std::cout << "LD4 > 3.5   " << 100.0 * double(above) / double(s.defined) << "% of them\n"
                  << std::setprecision(4) << "mean LD4    " << s.mean << "   (3: smooth, towards 4: noise)\n";
    } else {
        std::cout << "mean LD4    n/a (no window holds a cube)\n";
    }
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << seconds << " s, kernels compiled in "
              << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << " (float32, NaN where LD4 is undefined)\n";
    return 0;
}

}  // namespace

namespace cli {

CLI::Option* add_q_option(CLI::App* app, double& q) {
    return app
        ->add_option("--q", q, "bin width of the value axis (default: 1 for integer data, (vmax - vmin)/256 for float)")
        ->check(CLI::Validator(
            [](std::string& s) -> std::string {
                try {
                    std::size_t used = 0;
                    const double q = std::stod(s, &used);
                    if (used == s.size() && std::isfinite(q) && q > 0) return {};
                } catch (const std::exception&) {
                }
                return "--q " + s + ": the bin width must be a finite number > 0";
            },
            "Q > 0"));
}

Command fd4_command() {
    const auto setup = [](CLI::App* c, Fd4Args& a) {
        add_volume_argument(c, a.volume);
        add_q_option(c, a.q);
        c->add_option("--json", a.json, "write volume, dims, type, q, i4_l0, i4_l1, d4 as JSON");
        a.raw.add(c);
    };
    return command<Fd4Args>("fd4", "4D fractal dimension D4 of the graph of f (one number, no isovalue)", setup, run_fd4);
}

Command local4_command() {
    const auto setup = [](CLI::App* l, Fd4Args& b) {
        add_volume_argument(l, b.volume);
        add_q_option(l, b.q);
        add_window_option(l, b.window, "window k");
        add_output_option(l, b.output, "output .nrrd, .nii or .nii.gz (float32)");
        b.raw.add(l);
    };
    return command<Fd4Args>("local4", "local 4D fractal dimension field LD4 (no isovalue), as NRRD/NIfTI", setup,
                            run_local4);
}

}  // namespace cli
