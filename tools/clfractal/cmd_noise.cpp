// clfractal noise: measured edge and box dimension against the noise formula (thesis
// §3.2.1, Figs. 3.5-3.7; docs/definitions.md §21 "Noise formula").
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "clfractal/noise.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;
using json = nlohmann::json;

namespace {

struct NoiseArgs {
    std::size_t size = 128;
    int points = 10;
    std::string shape = "points", mu, isovalues, noise = "uniform", volume, json_path, plot;
    double iso = std::nan(""), gamma = std::nan("");
    std::uint64_t seed = 1;
    std::size_t box_samples = std::size_t(1) << 20;
    cli::RawArgs raw;
};

std::string fixed(double x, int digits) {
    if (std::isnan(x)) return "n/a";
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << x;
    return s.str();
}

void write_plot(const std::vector<NoisePoint>& pts, NoiseKind kind, const std::string& title, const std::string& path) {
    // Index 0: the measured points; index 1: the models on 41 values of r (the box model
    // from 2^15 Monte Carlo samples each, standard deviation about 0.001).
    std::ostringstream data;
    double rmax = 0;
    for (const NoisePoint& p : pts) {
        rmax = std::max(rmax, p.r);
        data << p.r << " " << cli::fd_string(p.measured_edge_fd) << " " << cli::fd_string(p.measured_box_fd) << "\n";
    }
    data << "\n\n";
    for (int k = 0; k <= 40 && rmax > 0; ++k) {
        const double r = rmax * k / 40;
        const double edge = kind == NoiseKind::uniform ? expected_edge_dimension(r) : expected_edge_dimension(r, kind);
        data << r << " " << edge << " " << expected_box_dimension(r, kind, std::size_t(1) << 15) << "\n";
    }
    std::ostringstream s;
    s << "set terminal pngcairo size 900,600 font 'sans,11'\n"
      << "set xlabel 'r = " << (kind == NoiseKind::uniform ? "mu" : "sigma") << " / gamma'\n"
      << "set ylabel 'fractal dimension'\nset yrange [1.9:3.05]\nset xrange [0:" << std::max(rmax, 0.01) << "]\n"
      << "set grid\nset key bottom right\nset title " << gnuplot_string(title) << " noenhanced\n"
      << "plot '$DATA' index 1 using 1:2 with lines lw 2 lc rgb '#222222' title '"
      << (kind == NoiseKind::uniform ? "formula (Theorem 1)" : "edge model, Gaussian noise (numerical integration)")
      << "', \\\n"
      << "  '$DATA' index 1 using 1:3 with lines lw 1 dt 2 lc rgb '#a83232' title 'box model (8 vertices, Monte Carlo)', \\\n"
      << "  '$DATA' index 0 using 1:2 with points pt 7 ps 1.2 lc rgb '#1f5fa8' title 'measured edge span dimension', \\\n"
      << "  '$DATA' index 0 using 1:3 with points pt 5 ps 1.0 lc rgb '#c8641e' title 'measured box span dimension'\n";
    plot_png(s.str(), data.str(), path);
}

// The combinations of options that make no sense, before any work.
void check_noise_options(const NoiseArgs& a) {
    const bool real = !a.volume.empty();
    if (!real && !std::isnan(a.iso)) throw InputError("--iso: only with --volume");
    if (!real && !std::isnan(a.gamma)) throw InputError("--gamma: only with --volume (synthetic data has gamma 1)");
    if (real && std::isnan(a.iso)) throw InputError("--volume: needs --iso S");
    if (!real && (a.size < 8 || a.size > 1024)) throw InputError("--size " + std::to_string(a.size) + ": must be 8..1024");
    if (a.points < 1 || a.points > 10000) throw InputError("--points " + std::to_string(a.points) + ": must be 1..10000");
    if (!std::isnan(a.gamma) && !(a.gamma > 0 && std::isfinite(a.gamma)))
        throw InputError("--gamma: must be a finite number > 0");
    if (a.box_samples < 1) throw InputError("--box-samples: must be at least 1");
}

// The clean volume, its gradient gamma, the isovalues and the noise amplitudes.
struct NoiseInput {
    Volume clean;
    double gamma = 1;
    bool estimated = false;
    std::string data_name;
    std::vector<float> iso;
    std::vector<double> amplitudes;
};

NoiseInput noise_input(const NoiseArgs& a) {
    const bool real = !a.volume.empty();
    NoiseInput in;
    if (real) {
        if (!std::isfinite(a.iso) && !cli::is_auto_isovalue(a.iso)) throw InputError("--iso: must be a finite number");
        in.clean = cli::read_volume_within(a.volume, a.raw.options(), {"clfractal noise"});
        if (cli::is_auto_isovalue(a.iso)) throw InputError("--iso auto: not with noise --volume; give --iso S");
        cli::warn_isovalue_outside(in.clean, a.iso);
        in.gamma = a.gamma;
        if (std::isnan(in.gamma)) {
            in.gamma = estimate_gamma(in.clean, a.iso);
            in.estimated = true;
        }
        in.data_name = a.volume;
        in.iso = {float(a.iso)};
    } else {
        in.clean = noise_experiment_volume(a.shape, a.size, a.points, a.seed);
        in.data_name = a.shape == "points" ? "distance to " + std::to_string(a.points) + " random points, N = " + std::to_string(a.size)
                                           : "distance to a circle of radius N/4 (tori), N = " + std::to_string(a.size);
        in.iso = default_noise_isovalues(a.shape, a.size);
    }
    if (!a.isovalues.empty()) {
        in.iso.clear();
        for (double s : cli::parse_list("--isovalues", a.isovalues)) in.iso.push_back(float(s));
    }
    std::sort(in.iso.begin(), in.iso.end());
    in.iso.erase(std::unique(in.iso.begin(), in.iso.end()), in.iso.end());
    if (!a.mu.empty()) {
        in.amplitudes = cli::parse_list("--mu", a.mu);
        for (double m : in.amplitudes)
            if (m < 0) throw InputError("--mu " + a.mu + ": amplitudes must be >= 0");
    } else {
        for (int k = 0; k <= 16; ++k) in.amplitudes.push_back(in.gamma * 0.25 * k);  // r = 0, 0.25, ..., 4
    }
    return in;
}

void print_noise_header(const NoiseArgs& a, const NoiseInput& in, NoiseKind kind, Context& ctx) {
    std::ostringstream isos;
    for (std::size_t j = 0; j < in.iso.size(); ++j) isos << (j ? " " : "") << in.iso[j];
    std::cout << "data        " << in.data_name << " (" << dims_string(in.clean.dims()) << " "
              << value_type_name(in.clean.type()) << ")\n"
              << "noise       " << noise_kind_name(kind) << (kind == NoiseKind::uniform ? " [-mu, mu]" : ", standard deviation mu")
              << ", seed " << a.seed << ", added in float32\n"
              << "isovalues   " << isos.str() << " (dimensions averaged over them)\n"
              << "gamma       " << in.gamma << (in.estimated ? "  (estimated: 2 x mean span of the edges whose minimum lies within gamma of the isovalue)" : "") << "\n"
              << "device      " << ctx.description() << "\n"
              << "formula     " << (kind == NoiseKind::uniform ? "Theorem 1 (eqs. 3.2-3.4)" : "edge model with Gaussian noise, numerical integration")
              << "; box model: 8-vertex cube, Monte Carlo (" << a.box_samples << " samples)\n\n"
              << "      mu       r   edge FD   formula     diff    box FD  box model     diff\n";
}

// The table of measured against modelled dimensions; returns the largest differences.
std::pair<double, double> print_noise_table(const std::vector<NoisePoint>& pts) {
    double worst = 0, worst_box = 0;
    for (const NoisePoint& p : pts) {
        const double diff = p.measured_edge_fd - p.formula, diff_box = p.measured_box_fd - p.model_box;
        if (!std::isnan(diff)) worst = std::max(worst, std::abs(diff));
        if (!std::isnan(diff_box)) worst_box = std::max(worst_box, std::abs(diff_box));
        std::cout << std::setw(8) << fixed(p.amplitude, 3) << std::setw(8) << fixed(p.r, 3) << std::setw(10)
                  << fixed(p.measured_edge_fd, 4) << std::setw(10) << fixed(p.formula, 4) << std::setw(9)
                  << fixed(diff, 4) << std::setw(10) << fixed(p.measured_box_fd, 4) << std::setw(11)
                  << fixed(p.model_box, 4) << std::setw(9) << fixed(diff_box, 4) << "\n";
    }
    std::cout << "\nmax |edge FD - formula| " << fixed(worst, 4) << "\nmax |box FD - box model| " << fixed(worst_box, 4)
              << "\n";
    return {worst, worst_box};
}

json noise_report_json(const NoiseArgs& a, const NoiseInput& in, NoiseKind kind, const std::vector<NoisePoint>& pts,
                       double worst, double worst_box, Context& ctx) {
    json rows = json::array();
    for (const NoisePoint& p : pts) {
        json per = json::array();
        for (std::size_t j = 0; j < in.iso.size(); ++j)
            per.push_back({{"isovalue", in.iso[j]}, {"edge_fd", cli::fd_json(p.edge_fd[j])}, {"box_fd", cli::fd_json(p.box_fd[j])}});
        rows.push_back({{"mu", p.amplitude},
                        {"r", p.r},
                        {"measured_edge_fd", cli::fd_json(p.measured_edge_fd)},
                        {"measured_box_fd", cli::fd_json(p.measured_box_fd)},
                        {"formula", p.formula},
                        {"model_box_fd", p.model_box},
                        {"isovalues", per}});
    }
    json j{{"points", rows},
           {"data", in.data_name},
           {"dims", {in.clean.dims().nx, in.clean.dims().ny, in.clean.dims().nz}},
           {"noise", noise_kind_name(kind)},
           {"seed", a.seed},
           {"gamma", in.gamma},
           {"gamma_estimated", in.estimated},
           {"isovalues", in.iso},
           {"box_samples", a.box_samples},
           {"max_abs_edge_error", worst},
           {"max_abs_box_error", worst_box},
           {"device", ctx.description()}};
    return j;
}

int run_noise(const NoiseArgs& a) {
    const NoiseKind kind = parse_noise_kind(a.noise);
    check_noise_options(a);
    const bool real = !a.volume.empty();
    const NoiseInput in = noise_input(a);

    Context& ctx = Context::shared();
    cli::progress(std::string(noise_kind_name(kind)) + " noise, " + std::to_string(in.amplitudes.size()) +
                  " amplitudes, on " + ctx.description());
    const std::vector<NoisePoint> pts =
        noise_experiment(ctx, in.clean, in.iso, in.amplitudes, kind, in.gamma, a.seed, a.box_samples,
                         [](const std::string& s) { cli::progress(s); });
    print_noise_header(a, in, kind, ctx);
    const auto [worst, worst_box] = print_noise_table(pts);
    if (!a.json_path.empty())
        write_file_atomic(a.json_path, noise_report_json(a, in, kind, pts, worst, worst_box, ctx).dump(1) + "\n");
    if (!a.plot.empty())
        write_plot(pts, kind,
                   (real ? std::filesystem::path(a.volume).filename().string() + " at isovalue " + fixed(a.iso, 2) +
                               ", gamma " + fixed(in.gamma, 2)
                         : in.data_name) +
                       ", " + noise_kind_name(kind) + " noise",
                   a.plot);
    return 0;
}

void setup_noise(CLI::App* c, NoiseArgs& a) {
    c->add_option("--size", a.size, "N of the synthetic N^3 grid");
    c->add_option("--points", a.points, "P random points of the 'points' shape");
    c->add_option("--shape", a.shape, "points (distance to P points) or circle (tori)")
        ->check(CLI::IsMember({"points", "circle"}));
    c->add_option("--mu", a.mu, "noise amplitudes A,B,... or A:B:STEP (default 0:4:0.25 times gamma)");
    c->add_option("--isovalues", a.isovalues, "isovalues A,B,... or A:B:STEP (default: 10,12,...,20 (points) or 8,10,...,16 (circle) times N/128; with --volume: S)");
    c->add_option("--noise", a.noise, "uniform [-mu, mu] or gaussian (mu = standard deviation)");
    c->add_option("--seed", a.seed, "seed of the noise and the points");
    c->add_option("--volume", a.volume, "add noise to this volume instead (Figs. 3.6/3.7)");
    cli::add_iso_option(c, a.iso, "with --volume: the isovalue S");
    c->add_option("--gamma", a.gamma, "with --volume: the gradient gamma (default: estimated from the edge spans near S)");
    c->add_option("--box-samples", a.box_samples, "Monte Carlo samples of the box model");
    c->add_option("--json", a.json_path, "write the points as JSON");
    c->add_option("--plot", a.plot, "draw measured vs formula to a PNG with gnuplot");
    a.raw.add(c);
}

}  // namespace

cli::Command cli::noise_command() {
    return command<NoiseArgs>("noise", "measured edge/box dimension vs the noise formula (thesis Fig. 3.5)", setup_noise,
                              run_noise);
}
