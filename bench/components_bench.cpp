// Isosurface component curve throughput (components.hpp): the two-sweep curve for every
// isovalue against per-isovalue labelling (breadth-first search of A and C, the obvious
// alternative), in the same run, on the same input.
//
//   clfractal_components_bench [--size N]... [--uint16-size N]... [--bfs-isovalues M]
//                              [--connectivity cube|freudenthal] [--repeats R] [--json F]
//
// Cases: noisy-sphere uint8 N^3 for every --size (default 128 256 512), and a uint16 N^3
// for every --uint16-size (default 256): the noisy sphere scaled by 200 plus per-vertex
// offsets 0..199, so that the curve has ~51,000 isovalues. Labelling costs O(N) per
// isovalue, so it is timed on M isovalues spread over the range (default 8) and
// extrapolated to all of them; those M counts must equal the curve's (exit 1 otherwise).
// The same M isovalues are also counted by count_components_at (runs joined plane by plane,
// on every core: what the recommendations use), timed as one call, and must equal too. And
// count_components_at at the first D (default 3) of them on each path, host and device
// (Tuning::labelling forced; one call each, its compute time: kernels, upload and download,
// no compilation), which must equal too.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "bench_harness.hpp"
#include "clfractal/components.hpp"
#include "clfractal/synthetic.hpp"
#include "components_labelling.hpp"

using namespace clfractal;

namespace {

Volume uint16_case(std::size_t n) {
    SyntheticOptions o;
    o.size = n;
    o.noise = 20;
    Volume s = make_synthetic("noisy-sphere", o);
    Volume v(s.dims(), ValueType::uint16, "noisy-sphere x200 + offsets, uint16");
    const std::uint8_t* p = s.as<std::uint8_t>();
    std::uint16_t* q = v.as<std::uint16_t>();
    for (std::size_t i = 0; i < v.vertices(); ++i)
        q[i] = std::uint16_t(200 * p[i] + std::uint16_t((uniform_noise(7, i) + 1) * 99.999));
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    BenchCli cli{"component curve: two union-find sweeps vs per-isovalue labelling", 1};
    CLI::App& app = cli.app;
    const int& repeats = cli.repeats;
    std::vector<std::size_t> sizes, sizes16;
    int samples = 8, device_samples = 3;
    std::string connectivity = "cube", json_path;
    app.add_option("--size", sizes, "uint8 noisy-sphere N^3 (repeatable; none of both: 128 256 512)");
    app.add_option("--uint16-size", sizes16, "uint16 N^3 (repeatable; none of both: 256)");
    app.add_option("--bfs-isovalues", samples, "isovalues timed with labelling");
    app.add_option("--path-isovalues", device_samples, "isovalues labelled on each path, host and device");
    app.add_option("--connectivity", connectivity, "cube or freudenthal");
    app.add_option("--json", json_path, "also write the figures as JSON");
    if (const int rc = cli.parse(argc, argv); rc >= 0) return rc;
    if (sizes.empty() && sizes16.empty()) sizes = {128, 256, 512}, sizes16 = {256};
    const Connectivity mode = parse_connectivity(connectivity);
    Context& ctx = Context::shared();
    std::cout << "device          " << ctx.description() << "\n"
              << "connectivity    " << connectivity_name(mode) << "\n"
              << "  volume                    isovalues   sweep s  Mvoxel/s   labelling s/iso  labelling all (est.)"
                 "  sweep/labelling  runs s/iso  BFS/runs  host s (D)  device s (D)  device/host  counts\n";
    nlohmann::json rows = nlohmann::json::array();
    bool all_equal = true;
    std::vector<std::pair<Volume, std::string>> cases;
    for (std::size_t n : sizes) {
        SyntheticOptions o;
        o.size = n;
        o.noise = 20;
        cases.emplace_back(make_synthetic("noisy-sphere", o), "uint8 " + std::to_string(n) + "^3");
    }
    for (std::size_t n : sizes16) cases.emplace_back(uint16_case(n), "uint16 " + std::to_string(n) + "^3");
    // Compile the histogram kernels outside the timings.
    for (auto& c : cases) count_components(ctx, Volume({2, 2, 2}, c.first.type()), IsovalueSet::integers(0, 1), mode);

    for (auto& [v, label] : cases) {
        const IsovalueSet iso = IsovalueSet::for_volume(v);
        double sweep = 1e300;
        ComponentCurve c;
        for (int r = 0; r < std::max(1, repeats); ++r) {
            c = count_components(ctx, v, iso, mode);
            sweep = std::min(sweep, c.seconds);
        }
        const std::size_t m = std::min<std::size_t>(std::max(1, samples), iso.size());
        double bfs = 0;
        bool equal = true;
        for (std::size_t k = 0; k < m; ++k) {
            const std::size_t j = (2 * k + 1) * iso.size() / (2 * m);
            const auto t = std::chrono::steady_clock::now();
            const std::int64_t b = count_components_by_labelling(v, iso.value(j), mode);
            bfs += seconds_since(t);
            equal = equal && b == c.components[j];
        }
        std::vector<double> at;
        for (std::size_t k = 0; k < m; ++k) at.push_back(iso.value((2 * k + 1) * iso.size() / (2 * m)));
        double runs = 1e300;
        for (int r = 0; r < std::max(1, repeats); ++r) {
            const auto t = std::chrono::steady_clock::now();
            const std::vector<std::int64_t> d = count_components_at(v, at, mode);
            runs = std::min(runs, seconds_since(t) / double(m));
            for (std::size_t k = 0; k < m; ++k) equal = equal && d[k] == c.components[(2 * k + 1) * iso.size() / (2 * m)];
        }
        // Host and device labelling at the first D of the same isovalues, the device's
        // programs compiled first (a 2^3 volume of the type).
        const std::vector<double> few(at.begin(), at.begin() + std::ptrdiff_t(std::min<std::size_t>(
                                                               std::size_t(std::max(1, device_samples)), at.size())));
        double path_seconds[2] = {1e300, 1e300};
        const Tuning saved = ctx.tuning;
        for (LabellingPath path : {LabellingPath::host, LabellingPath::device}) {
            ctx.tuning.labelling = path;
            count_components_at(ctx, Volume({2, 2, 2}, v.type()), few, mode);
            for (int r = 0; r < std::max(1, repeats); ++r) {
                const ComputeTimer t(ctx);
                const std::vector<std::int64_t> d = count_components_at(ctx, v, few, mode);
                path_seconds[int(path)] = std::min(path_seconds[int(path)], t.seconds());
                for (std::size_t k = 0; k < few.size(); ++k)
                    equal = equal && d[k] == c.components[(2 * k + 1) * iso.size() / (2 * m)];
            }
        }
        ctx.tuning = saved;
        const double per_iso = bfs / double(m), all = per_iso * double(iso.size());
        const double mvox = double(v.vertices()) / sweep / 1e6;
        all_equal = all_equal && equal;
        std::cout << "  " << std::left << std::setw(26) << label << std::right << std::setw(9) << iso.size()
                  << std::fixed << std::setprecision(3) << std::setw(10) << sweep << std::setprecision(1)
                  << std::setw(10) << mvox << std::setprecision(4) << std::setw(18) << per_iso << std::setprecision(1)
                  << std::setw(20) << all << " s" << std::setw(16) << all / sweep << "x" << std::setprecision(4)
                  << std::setw(13) << runs << std::setprecision(1) << std::setw(9) << per_iso / runs << "x"
                  << std::setprecision(4) << std::setw(12) << path_seconds[0] << std::setw(14) << path_seconds[1]
                  << std::setprecision(2) << std::setw(12) << path_seconds[1] / path_seconds[0] << "x  "
                  << (equal ? "equal" : "DIFFER") << std::defaultfloat << "\n";
        rows.push_back({{"volume", label},
                        {"vertices", v.vertices()},
                        {"isovalues", iso.size()},
                        {"sweep_seconds", sweep},
                        {"sweep_mvoxel_per_s", mvox},
                        {"labelling_isovalues_timed", m},
                        {"labelling_seconds_per_isovalue", per_iso},
                        {"labelling_seconds_all_estimated", all},
                        {"ratio_labelling_over_sweep", all / sweep},
                        {"runs_seconds_per_isovalue", runs},
                        {"ratio_bfs_over_runs", per_iso / runs},
                        {"path_isovalues", few.size()},
                        {"host_labelling_seconds", path_seconds[0]},
                        {"device_labelling_seconds", path_seconds[1]},
                        {"counts_equal", equal}});
    }
    std::cout << "(sweep: sort + both union-find sweeps + prefix sum, every isovalue; labelling: BFS of {f < s} and\n"
                 " {f >= s} per isovalue, timed on "
              << samples << " isovalues and extrapolated to all of them; ratio > 1: the sweep is faster;\n"
                 " runs: count_components_at on the same isovalues, runs along x joined plane by plane on every core;\n"
                 " host s (D), device s (D): count_components_at at the first "
              << device_samples << " of them in one call on each path, compute time without compilation)\n";
    if (!json_path.empty()) {
        nlohmann::json j = bench_header(ctx, repeats);
        j.update({{"connectivity", connectivity_name(mode)}, {"cases", rows}});
        std::ofstream(json_path) << j.dump(1) << "\n";
    }
    return all_equal ? 0 : 1;
}
