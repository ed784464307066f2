// clfractal components: the number of isosurface components for every isovalue
// (docs/definitions.md §19 "Isosurface components"; thesis §3.1, Fig. 3.2).
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "clfractal/components.hpp"
#include "clfractal/memory.hpp"
#include "clfractal/slice_reader.hpp"
#include "cli.hpp"
#include "components_labelling.hpp"
#include "measures/components_slab.hpp"
#include "output.hpp"
#include "plots.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct ComponentsArgs {
    std::string volume, csv, json, plot, connectivity = "cube", isovalues;
    std::size_t bins = 0;
    std::size_t slab = 0;
    bool verify = false, stream = false;
    RawArgs raw;
};

// --csv and --json of the curve.
void write_curve_files(const ComponentsArgs& a, const Dims& d, ValueType type, Connectivity mode,
                       const IsovalueSet& iso, const std::vector<std::int64_t>& components) {
    if (!a.csv.empty()) write_file_atomic(a.csv, components_csv(iso, components));
    if (!a.json.empty()) write_file_atomic(a.json, components_json(a.volume, d, type, mode, iso, components));
}

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

// The isovalues of `iso`, in order, as count_components_at takes them.
std::vector<double> values_of(const IsovalueSet& iso) {
    std::vector<double> at(iso.size());
    for (std::size_t j = 0; j < at.size(); ++j) at[j] = iso.value(j);
    return at;
}

// The z-parts of nz slices with at most `slices` each (>= 2), each sharing its last slice with
// the next: ceil((nz - 1) / (slices - 1)), at least 1.
std::size_t part_count(std::size_t nz, std::size_t slices) {
    return slices >= nz ? 1 : (nz + slices - 3) / (slices - 1);
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
    const std::vector<std::int64_t> c = stream_components_at(reader, values_of(iso), mode);
    const double seconds = seconds_since(t0);
    print_components(std::cout, a.volume, reader.dims(), reader.type(), mode, iso, c);
    const double vertices = double(reader.dims().nx) * double(reader.dims().ny) * double(reader.dims().nz);
    std::cout << std::setprecision(4) << "time          " << seconds << " s read and labelled (streamed, "
              << reader.method() << ", " << vertices / seconds / 1e6 << " Mvoxel/s)\n";
    write_curve_files(a, reader.dims(), reader.type(), mode, iso, c);
    return 0;
}

// Memory of the slab path with z-parts of `slices` slices, each sharing its last with the
// next: one part in core as `components` takes it (4x + 256 MiB), and every part's boundary
// links, kept until the join (per sweep at most one link a boundary vertex, 12 bytes; two
// boundary slices; the bins of a shared slice; the join's copy: 104 bytes a slice vertex).
std::uint64_t slab_bytes(const Dims& d, std::size_t value_bytes, std::size_t slices) {
    const std::uint64_t slice = std::uint64_t(d.nx) * d.ny;
    return 4 * slices * slice * value_bytes + (std::uint64_t(256) << 20) + part_count(d.nz, slices) * 104 * slice;
}

// The slices of a part: `requested` (at most nz), or with 0 the most the memory available
// allows (at least 2).
std::size_t plan_slices(const Dims& d, ValueType type, std::size_t requested) {
    const std::optional<std::uint64_t> avail = available_memory();
    const std::size_t vb = value_size(type), slice = d.nx * d.ny * vb;
    std::size_t p = std::min(requested ? requested : d.nz, std::max<std::size_t>(d.nz, 2));
    if (avail && !requested) {
        const std::uint64_t room = *avail > (std::uint64_t(256) << 20) ? *avail - (std::uint64_t(256) << 20) : 0;
        p = std::clamp<std::size_t>(std::size_t(room / (4 * std::uint64_t(slice))), 2, std::max<std::size_t>(d.nz, 2));
        while (p > 2 && slab_bytes(d, vb, p) > *avail) p -= std::max<std::size_t>(1, p / 16);
    }
    return p;
}

// Whether parts of `slices` slices fit the memory available.
bool slabs_fit(const Dims& d, ValueType type, std::size_t slices) {
    const std::optional<std::uint64_t> avail = available_memory();
    return !avail || slab_bytes(d, value_size(type), slices) <= *avail;
}

// An InputError naming the file when parts of `slices` slices do not fit.
void require_slabs(const std::string& volume, const Dims& d, ValueType type, std::size_t slices) {
    MemoryRequest r;
    r.need = slab_bytes(d, value_size(type), slices), r.file = volume, r.what = "clfractal components";
    r.basis = "z-parts of " + std::to_string(slices) + " slices: 4x a part + 256 MiB, and 104 bytes a slice vertex a part";
    r.hint = "CLFRACTAL_MEMORY_LIMIT=off runs it anyway";
    require_memory(r);
}

// The whole curve of a volume too large to sort in core: z-parts of at most `slices` slices
// (0: as many as the memory allows), each read and counted in turn (count_slab_components) and
// joined by their boundary links (join_slab_components): exactly the in-core curve.
int run_components_slabs(const ComponentsArgs& a, Connectivity mode, std::size_t slices) {
    if (a.verify) throw InputError("--verify: not with slabs (the check labels the whole volume)");
    if (!a.plot.empty()) throw InputError("--plot: not with slabs (the plot counts the whole volume's spans)");
    if (a.slab == 1) throw InputError("--slab 1: z-parts share a slice, so they need at least 2");
    SliceReader reader(a.volume, a.raw.options());
    const Dims d = reader.dims();
    slices = plan_slices(d, reader.type(), slices);
    require_slabs(a.volume, d, reader.type(), slices);
    check_bins(a.bins, reader.type());
    IsovalueSet iso;
    if (!a.isovalues.empty()) {
        iso = parse_isovalues(a.isovalues, reader.type());
    } else {
        progress("reading the value range of " + a.volume + " (" + reader.method() + ")");
        const ValueRange r = value_range(reader);
        iso = IsovalueSet::for_range(reader.type(), r.min, r.max, a.bins ? a.bins : 256);
    }
    const auto parts = split_slices(d.nz, 1, part_count(d.nz, slices));
    progress("components of " + dims_string(d) + " " + value_type_name(reader.type()) + " for " +
             std::to_string(iso.size()) + " isovalues, " + connectivity_name(mode) + " connectivity, in " +
             std::to_string(parts.size()) + " z-parts of up to " + std::to_string(slices) + " slices");
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::int64_t> sum(iso.size(), 0);
    std::vector<SlabLinks> links;
    // The file is read once, in order (value_range leaves the reader rewound): a part begins
    // with the slice the one before ended with.
    const std::size_t slice = reader.slice_bytes();
    std::vector<unsigned char> shared(slice);
    for (std::size_t r = 0; r < parts.size(); ++r) {
        Volume part(Dims{d.nx, d.ny, parts[r].second - parts[r].first}, reader.type());
        auto* bytes = static_cast<unsigned char*>(part.data());
        if (r > 0) std::memcpy(bytes, shared.data(), slice);
        reader.read(bytes + (r > 0 ? slice : 0), part.dims().nz - (r > 0 ? 1 : 0));
        std::memcpy(shared.data(), bytes + (part.dims().nz - 1) * slice, slice);
        SlabComponents c = count_slab_components(Context::shared(), part, iso, mode, r > 0, r + 1 < parts.size());
        for (std::size_t j = 0; j < sum.size(); ++j) sum[j] += c.components[j];
        links.push_back(std::move(c.links));
    }
    const std::vector<std::int64_t> curve = join_slab_components(std::move(sum), links, d.nx * d.ny);
    const double seconds = seconds_since(t0);
    print_components(std::cout, a.volume, d, reader.type(), mode, iso, curve);
    std::cout << std::setprecision(4) << "time          " << seconds << " s (wall) to read, sort and sweep "
              << parts.size() << " z-parts and join them (" << double(d.vertices()) / seconds / 1e6 << " Mvoxel/s)\n";
    write_curve_files(a, d, reader.type(), mode, iso, curve);
    return 0;
}

// The slices of the z-parts to count when the header states a shape for which the in-core
// sweep (4x the volume + 256 MiB) does not fit but parts do; 0 otherwise (in core, or refused
// by the in-core check with one line).
std::size_t parts_instead(const ComponentsArgs& a) {
    const std::optional<VolumeShape> shape = peek_volume(a.volume, a.raw.options());
    const std::optional<std::uint64_t> avail = available_memory();
    if (!shape || !avail || MemoryNeed{"clfractal components"}.bytes(shape->bytes()) <= *avail) return 0;
    const std::size_t slices = plan_slices(shape->dims, shape->type, 0);
    return slabs_fit(shape->dims, shape->type, slices) ? slices : 0;
}

int run_components(const ComponentsArgs& a) {
    const Connectivity mode = parse_connectivity(a.connectivity);
    if (a.stream) return run_components_stream(a, mode);
    if (a.slab) return run_components_slabs(a, mode, a.slab);
    if (const std::size_t slices = parts_instead(a)) {
        progress(a.volume + ": the in-core sweep does not fit the memory available; counting in z-parts");
        return run_components_slabs(a, mode, slices);
    }
    Volume v = read_volume_within(a.volume, a.raw.options(),
                                  {"clfractal components", 4.0,
                                   "clfractal components --stream --isovalues A,B,... labels a few isovalues within "
                                   "512 MiB"});
    check_bins(a.bins, v.type());
    IsovalueSet iso = !a.isovalues.empty() ? parse_isovalues(a.isovalues, v.type())
                                           : IsovalueSet::for_volume(v, a.bins ? a.bins : 256);
    Context& ctx = Context::shared();
    progress("components of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " for " +
             std::to_string(iso.size()) + " isovalues, " + connectivity_name(mode) + " connectivity");
    ComponentCurve c;
    if (iso.size() <= few_isovalues) {
        // A few isovalues: each labelled directly (count_components_at, on the host or the
        // device by the device's tuning), no sort of the volume.
        const ComputeTimer timer(ctx);
        c.isovalues = iso;
        c.components = count_components_at(ctx, v, values_of(iso), mode);
        c.seconds = timer.seconds();
    } else {
        c = count_components(ctx, v, iso, mode);
    }

    print_components(std::cout, a.volume, v.dims(), v.type(), mode, iso, c.components);
    std::cout << std::setprecision(4) << "time          " << c.seconds << " s ("
              << double(v.vertices()) / c.seconds / 1e6 << " Mvoxel/s)\n";
    const int bad = a.verify ? verify_components(v, iso, mode, c) : 0;
    write_curve_files(a, v.dims(), v.type(), mode, iso, c.components);
    if (!a.plot.empty()) {
        // The annotations come from the box-dimension curve: the cube count underlay, the
        // greyed few-cube isovalues and the clean bands (two levels, cheap beside the sweep).
        const FdCurve f = fd_curve(ctx, count_spans(ctx, v, iso), SpanKind::cubes);
        write_components_plot(f, clean_bands(f), c.components, false, components_plot_title(a.volume, mode), a.plot);
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
    c->add_option("--json", a.json, "write the curve as JSON (volume, dims, type, connectivity, isovalues, components)");
    c->add_option("--plot", a.plot, "draw the curve (log scale) to a PNG with gnuplot");
    c->add_flag("--verify", a.verify, "check every isovalue against per-isovalue labelling (slow); exit 1 on a mismatch");
    c->add_option("--slab", a.slab,
                  "count z-parts of at most this many slices in turn, joined exactly (0: in core, or parts "
                  "when the volume does not fit the memory)");
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
