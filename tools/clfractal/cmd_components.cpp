// clfractal components: the number of isosurface components for every isovalue
// (docs/definitions.md §19 "Isosurface components"; thesis §3.1, Fig. 3.2).
#include <algorithm>
#include <cmath>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "clfractal/components.hpp"
#include "cli.hpp"
#include "components_labelling.hpp"
#include "output.hpp"
#include "plots.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct ComponentsArgs {
    std::string volume, csv, plot, connectivity = "cube", isovalues;
    std::size_t bins = 0;
    bool verify = false, stream = false;
    RawArgs raw;
};

// --verify: every isovalue against per-isovalue labelling; returns how many differ.
int verify_components(const Volume& v, const IsovalueSet& iso, Connectivity mode, const ComponentCurve& c) {
    int bad = 0;
    // Every isovalue against per-isovalue labelling of A and C (O(N) per isovalue). Where
    // no vertex value lies in [s_{j-1}, s_j), A and C are the very sets of isovalue j - 1:
    // the labelling would repeat itself, so the curve must simply repeat its value.
    std::vector<char> changes(iso.size(), 0);
    visit(v, [&](const auto* p) {
        for (std::size_t i = 0; i < v.vertices(); ++i) {
            const double x = double(p[i]);
            std::size_t j = 0;
            if (iso.integer()) {
                const double b = x - double(iso.first()) + 1;  // first isovalue > x
                if (b < 0 || b >= double(iso.size())) continue;
                j = std::size_t(b);
            } else {
                const auto& f = iso.list();  // exact in double for every list type
                j = std::size_t(std::upper_bound(f.begin(), f.end(), x) - f.begin());
                if (j >= f.size()) continue;
            }
            changes[j] = 1;
        }
    });
    changes[0] = 1;
    std::size_t labelled = 0;
    std::int64_t want = 0;
    for (std::size_t j = 0; j < iso.size(); ++j) {
        if (changes[j]) {
            want = count_components_by_labelling(v, iso.value(j), mode);
            ++labelled;
        }
        if (want != c.components[j]) {
            if (bad < 10)
                std::cerr << "clfractal: mismatch at isovalue " << iso_string(iso, j) << ": sweep "
                          << c.components[j] << ", labelling " << want << "\n";
            ++bad;
        }
    }
    std::cout << "verify        " << (bad ? std::to_string(bad) + " isovalues DIFFER from" : "every isovalue equals")
              << " per-isovalue labelling (" << labelled << " distinct sets labelled)\n";
    return bad;
}

// --stream: a few isovalues labelled as the file is read slice by slice (ComponentsAtStream),
// for volumes larger than memory; the whole curve needs the volume in memory.
int run_components_stream(const ComponentsArgs& a, Connectivity mode) {
    if (a.verify) throw InputError("--verify: not with --stream (the check sweeps the whole volume)");
    if (!a.plot.empty()) throw InputError("--plot: not with --stream (the plot draws the whole curve)");
    if (a.isovalues.empty())
        throw InputError("--stream: give the isovalues (--isovalues A,B,... or A:B:STEP, at most " +
                         std::to_string(few_isovalues) + "); the whole curve needs the volume in memory");
    SliceReader reader(a.volume, a.raw.options());
    const IsovalueSet iso = parse_isovalues(a.isovalues, reader.type());
    if (iso.size() > few_isovalues)
        throw InputError("--stream: " + std::to_string(iso.size()) + " isovalues; at most " +
                         std::to_string(few_isovalues) + " are labelled slice by slice");
    progress("components of " + dims_string(reader.dims()) + " " + value_type_name(reader.type()) + " at " +
             std::to_string(iso.size()) + " isovalues, " + connectivity_name(mode) + " connectivity, slice by slice (" +
             reader.method() + ")");
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<double> at(iso.size());
    for (std::size_t j = 0; j < at.size(); ++j) at[j] = iso.value(j);
    const std::vector<std::int64_t> c = stream_components_at(reader, at, mode);
    const double seconds = seconds_since(t0);
    print_components(std::cout, a.volume, reader.dims(), reader.type(), mode, iso, c);
    const double vertices = double(reader.dims().nx) * double(reader.dims().ny) * double(reader.dims().nz);
    std::cout << std::setprecision(4) << "time          " << seconds << " s read and labelled (streamed, "
              << reader.method() << ", " << vertices / seconds / 1e6 << " Mvoxel/s)\n";
    if (!a.csv.empty()) write_file_atomic(a.csv, components_csv(iso, c));
    return 0;
}

int run_components(const ComponentsArgs& a) {
    const Connectivity mode = parse_connectivity(a.connectivity);
    if (a.stream) return run_components_stream(a, mode);
    Volume v = read_volume_within(a.volume, a.raw.options(),
                                  {"clfractal components", 4.0,
                                   "clfractal components --stream --isovalues A,B,... labels a few isovalues within "
                                   "512 MiB"});
    if (a.bins && is_integer(v.type()) && !is_wide(v.type()))
        throw InputError("--bins: 8/16-bit integer data uses every integer isovalue; use --isovalues A:B:1 to select");
    IsovalueSet iso = !a.isovalues.empty() ? parse_isovalues(a.isovalues, v.type())
                                           : IsovalueSet::for_volume(v, a.bins ? a.bins : 256);
    Context& ctx = Context::shared();
    progress("components of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " for " +
             std::to_string(iso.size()) + " isovalues, " + connectivity_name(mode) + " connectivity");
    ComponentCurve c;
    if (iso.size() <= few_isovalues) {
        // A few isovalues: each labelled directly (count_components_at), no sort of the volume.
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<double> at(iso.size());
        for (std::size_t j = 0; j < at.size(); ++j) at[j] = iso.value(j);
        c.isovalues = iso;
        c.components = count_components_at(v, at, mode);
        c.seconds = seconds_since(t0);
    } else {
        c = count_components(ctx, v, iso, mode);
    }

    print_components(std::cout, a.volume, v.dims(), v.type(), mode, iso, c.components);
    std::cout << std::setprecision(4) << "time          " << c.seconds << " s ("
              << double(v.vertices()) / c.seconds / 1e6 << " Mvoxel/s)\n";
    const int bad = a.verify ? verify_components(v, iso, mode, c) : 0;
    if (!a.csv.empty()) write_file_atomic(a.csv, components_csv(iso, c.components));
    if (!a.plot.empty()) {
        // The annotations come from the box-dimension curve: the cube count underlay, the
        // greyed few-cube isovalues and the clean bands (two levels, cheap beside the sweep).
        const FdCurve f = fd_curve(ctx, count_spans(ctx, v, iso), SpanKind::cubes);
        write_components_plot(f, clean_bands(f), c.components, false,
                              std::filesystem::path(a.volume).filename().string() + ": isosurface components (" +
                                  connectivity_name(mode) + ")",
                              a.plot);
    }
    return bad ? 1 : 0;
}

void setup_components(CLI::App* c, ComponentsArgs& a) {
    add_volume_argument(c, a.volume);
    c->add_option("--connectivity", a.connectivity,
                  "cube: {f<s} 6- and {f>=s} 26-connected (marching cubes); freudenthal: both 14-connected");
    add_isovalues_option(c, a.isovalues);
    add_bins_option(c, a.bins);
    c->add_option("--csv", a.csv, "write isovalue,components");
    c->add_option("--plot", a.plot, "draw the curve (log scale) to a PNG with gnuplot");
    c->add_flag("--verify", a.verify, "check every isovalue against per-isovalue labelling (slow); exit 1 on a mismatch");
    c->add_flag("--stream", a.stream,
                "read the file slice by slice and label up to 32 --isovalues (memory: a few slices; same numbers)");
    a.raw.add(c);
}

}  // namespace

Command components_command() {
    return command<ComponentsArgs>("components", "number of isosurface components for every isovalue", setup_components,
                                   run_components);
}

}  // namespace cli
