// clfractal-mpi: the fractal dimension curve of one volume counted by several MPI ranks, with
// fd's analysis (docs/definitions.md §28), and with `components` its component curve
// (components.cpp). Each rank owns a z-part of the volume (starting at a multiple of
// 2^(levels-1), sharing its last slice with the next part), counts it on its own device,
// and the int64 histograms are summed on rank 0 with MPI_Reduce: the curve equals the
// single-process `clfractal fd` exactly. The analysis's recommendations come from the summed
// curve and vertex histogram on rank 0, their components from the ranks' parts joined on
// rank 0 (components_of_parts): `--json` writes what `clfractal fd --stream --json` writes,
// apart from the facts of the run (device, times, slabs, ranks).
//
//   mpirun -np P clfractal-mpi [fd] VOLUME [--edge] [--levels L] [--isovalues A:B:S|A,B,... | --bins K]
//                              [--clean-fd D] [--clean-share F] [--csv F] [--json F]
//   mpirun -np P clfractal-mpi components VOLUME [--connectivity cube|freudenthal] [--isovalues ... | --bins K] [--csv F]
//                                       [--json F] [--plot F.png]
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include "cli.hpp"
#include "clfractal/analysis.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/span.hpp"
#include "clfractal/version.hpp"
#include "clfractal/volume_io.hpp"
#include "mpi_tool.hpp"
#include "output.hpp"

using namespace clfractal;

namespace mpi_tool {

double count_part(SliceReader& reader, const IsovalueSet& iso, SpanKind kind, int levels, std::size_t z_begin,
                  std::size_t z_end, std::vector<std::uint64_t>& counts) {
    SpanOptions opt{{kind}, levels, 0};
    opt.z_begin = z_begin;
    opt.z_end = z_end;
    SpanCounter counter(Context::shared(), iso, reader.type(), reader.dims(), opt);
    const std::size_t depth = counter.slab_slices();
    HostBytes buf(depth * reader.slice_bytes());  // aligned: a CPU device counts it in place
    // Slabs share their last slice with the next one: read it once, keep it in front.
    reader.seek(z_begin);
    std::size_t z0 = z_begin, have = 0;
    while (true) {
        const std::size_t nzs = std::min(depth, z_end - z0);
        reader.read(buf.data() + have * reader.slice_bytes(), nzs - have);
        counter.add_slab(buf.data(), z0, nzs);
        if (z0 + nzs == z_end) break;
        std::memmove(buf.data(), buf.data() + (nzs - 1) * reader.slice_bytes(), reader.slice_bytes());
        have = 1;
        z0 += nzs - 1;
    }
    const SpanResult spans = counter.finish();
    for (int l = 0; l < levels; ++l)
        std::copy(spans.curves[0].counts[l].begin(), spans.curves[0].counts[l].end(),
                  counts.begin() + std::ptrdiff_t(std::size_t(l) * iso.size()));
    return spans.seconds;
}

FdCurve summed_curve(const std::vector<std::uint64_t>& total, const IsovalueSet& iso, SpanKind kind, int levels,
                     const Dims& dims) {
    SpanResult sum;
    sum.isovalues = iso;
    SpanCurves c;
    c.kind = kind;
    for (int l = 0; l < levels; ++l) {
        c.level_dims.push_back(level_dims(dims, l));
        c.counts.emplace_back(total.begin() + std::ptrdiff_t(std::size_t(l) * iso.size()),
                              total.begin() + std::ptrdiff_t(std::size_t(l + 1) * iso.size()));
    }
    sum.curves.push_back(c);
    return fd_curve(Context::shared(), sum, kind);
}

}  // namespace mpi_tool

namespace {

struct Args {
    std::string volume, csv, json_path, isovalues;
    bool edge = false;
    int levels = 2;
    std::size_t bins = 0;
    std::uint64_t min_count = 0;
    double clean_fd = 2.2, clean_share = 0.01;
    cli::RawArgs raw;
};

// The options of the fd curve: on the tool itself (clfractal-mpi VOLUME) and on `fd`.
CLI::Option* setup_fd(CLI::App* app, Args& a) {
    CLI::Option* volume = cli::add_volume_argument(app, a.volume);
    app->add_flag("--edge", a.edge, "edge span dimension (eq. 3.1) instead of box (eq. 2.5)");
    app->add_option("--levels", a.levels, "pyramid levels (2 = eq. 2.5)");
    cli::add_isovalues_option(app, a.isovalues);
    app->add_option("--bins", a.bins, "number of uniform isovalues for float data (0: 256)");
    app->add_option("--min-count", a.min_count, "summary only where the subsampled count is >= M");
    app->add_option("--clean-fd", a.clean_fd, "clean bands: D(s) at most this");
    app->add_option("--clean-share", a.clean_share, "clean bands: I(s) at least this share of the largest");
    app->add_option("--csv", a.csv, "write isovalue,count,count_sub,fd (as clfractal fd --csv)");
    app->add_option("--json", a.json_path,
                    "write the analysis as JSON (as clfractal fd --stream --json: curve, bands, recommendations "
                    "with their components)");
    a.raw.add(app);
    return volume;
}

// The isovalue set needs the global value range: each rank takes its part's (one pass
// over its slices, a batch at a time), reduced with MPI_Allreduce.
IsovalueSet part_isovalues(const Args& a, SliceReader& reader, std::size_t z_begin, std::size_t z_end) {
    const Dims dims = reader.dims();
    const ValueType type = reader.type();
    double lo = INFINITY, hi = -INFINITY;
    const std::size_t batch = std::max<std::size_t>(1, (std::size_t(64) << 20) / reader.slice_bytes());
    if (z_begin < z_end) {
        reader.seek(z_begin);
        for (std::size_t z = z_begin; z < z_end;) {
            const std::size_t n = std::min(batch, z_end - z);
            Volume slab(Dims{dims.nx, dims.ny, n}, type);
            reader.read(slab.data(), n);
            const ValueRange r = value_range(slab);
            lo = std::min(lo, r.min);
            hi = std::max(hi, r.max);
            z += n;
        }
    }
    return mpi_tool::global_isovalues(a.isovalues, a.bins, type, lo, hi);
}

// Rank 0 reports the analysis of the summed curve.
void report(const Args& a, const Analysis& an, const FdSummary& s, double slowest, double components_seconds,
            int size, const std::vector<std::pair<std::size_t, std::size_t>>& parts) {
    Context& ctx = Context::shared();
    std::cout << std::fixed << std::setprecision(4) << "volume      " << a.volume << "  " << dims_string(an.dims) << " "
              << value_type_name(an.type) << "\n"
              << "ranks       " << size << " (" << parts.size() << " with a z-part), device of rank 0: "
              << ctx.description() << "\n"
              << "dimension   fractal " << (a.edge ? "edge" : "box") << " span dimension, levels 0.."
              << a.levels - 1 << "\n"
              << "isovalues   " << an.isovalues.size() << " (" << cli::iso_string(an.isovalues, 0) << " .. "
              << cli::iso_string(an.isovalues, an.isovalues.size() - 1) << "), defined at " << s.defined << "\n";
    if (s.defined) {
        std::cout << "mean FD     " << s.mean << "  std " << s.std << "  count-weighted mean " << s.weighted_mean
                  << "\n"
                  << "growth      I ~ N^" << s.kappa << "\n";
        cli::print_bands(std::cout, an.curve, an.bands, a.clean_fd, a.clean_share);
    }
    cli::print_advice(std::cout, an, a.volume);
    std::cout << std::defaultfloat << "time        " << slowest << " s counting (slowest rank), "
              << components_seconds << " s components of the recommendations\n";

    if (!a.csv.empty()) write_file_atomic(a.csv, cli::fd_csv(an.curve));
    if (!a.json_path.empty()) {
        nlohmann::json j = cli::fd_analysis_json(an, s, cli::FdJsonFacts{a.volume, a.edge, a.levels, a.min_count});
        // The facts of this run.
        j["device"] = ctx.description();
        j["ranks"] = size;
        j["parts"] = parts;
        j["seconds_compute"] = slowest;
        write_file_atomic(a.json_path, j.dump(1) + "\n");
    }
}

// The set of the isovalues `at` (from `iso`, increasing) for count_slab_components: integer
// sets their range, lists the values themselves.
IsovalueSet subset(const IsovalueSet& iso, const std::vector<double>& at) {
    if (iso.integer()) return IsovalueSet::integers(std::int64_t(at.front()), std::int64_t(at.back()));
    return iso.float64() ? IsovalueSet::doubles(at) : IsovalueSet::floats(std::vector<float>(at.begin(), at.end()));
}

int run(const Args& a, int rank, int size) {
    const auto t0 = std::chrono::steady_clock::now();
    // Each rank opens the file and reads only the slices of its own z-part (raw and NRRD
    // raw data through memory maps; gzip data is decompressed up to the part).
    SliceReader reader(a.volume, a.raw.options());
    const Dims dims = reader.dims();
    const ValueType type = reader.type();
    if (a.levels < 2 || a.levels > 16) throw InputError("--levels " + std::to_string(a.levels) + ": must be 2..16");
    cli::check_bins(a.bins, type);
    AnalysisOptions o;
    o.advice.clean_fd = a.clean_fd;
    o.advice.clean_share = a.clean_share;
    check_advice(o.advice);
    const auto parts = split_slices(dims.nz, a.levels, std::size_t(size));
    const bool has_part = std::size_t(rank) < parts.size();
    const std::size_t z_begin = has_part ? parts[rank].first : 0, z_end = has_part ? parts[rank].second : 0;
    // The recommendations' components sweep each part whole, as clfractal-mpi components: where
    // a node lacks the room, the curve and its analysis still come (every rank hears the same).
    std::string no_room;
    try {
        mpi_tool::require_part_memory(a.volume, (z_end - z_begin) * dims.nx * dims.ny * value_size(type), rank,
                                      "clfractal-mpi fd's components");
    } catch (const InputError& e) {
        no_room = e.what();
    }
    const IsovalueSet iso = part_isovalues(a, reader, z_begin, z_end);

    const SpanKind kind = a.edge ? SpanKind::edges : SpanKind::cubes;
    std::vector<std::uint64_t> counts(std::size_t(a.levels) * iso.size(), 0);
    const double seconds = has_part ? mpi_tool::count_part(reader, iso, kind, a.levels, z_begin, z_end, counts) : 0;
    std::vector<std::uint64_t> total(counts.size());
    MPI_Reduce(counts.data(), total.data(), int(counts.size()), MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    double slowest = 0;
    MPI_Reduce(&seconds, &slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);

    // The vertices at each isovalue (boundary strength): each vertex once, a shared slice
    // with the part that follows; read in batches of 64 MiB.
    std::vector<std::uint64_t> hist(iso.size(), 0), hist_total(iso.size(), 0);
    if (has_part) {
        const std::size_t own_end = std::size_t(rank) + 1 < parts.size() ? z_end - 1 : z_end;
        const std::size_t batch = std::max<std::size_t>(1, (std::size_t(64) << 20) / reader.slice_bytes());
        reader.seek(z_begin);
        for (std::size_t z = z_begin; z < own_end;) {
            const std::size_t n = std::min(batch, own_end - z);
            Volume slab(Dims{dims.nx, dims.ny, n}, type);
            reader.read(slab.data(), n);
            const std::vector<std::uint64_t> h = isovalue_histogram(slab, iso);
            for (std::size_t k = 0; k < h.size(); ++k) hist[k] += h[k];
            z += n;
        }
    }
    MPI_Reduce(hist.data(), hist_total.data(), int(iso.size()), MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);

    // Rank 0 analyses the curve; the recommendations' isovalues go to every rank.
    Analysis an;
    std::vector<double> at;
    if (rank == 0) {
        o.kind = kind;
        o.levels = a.levels;
        o.bins = a.bins ? a.bins : 256;
        an = analyse_curve(mpi_tool::summed_curve(total, iso, kind, a.levels, dims), o, std::move(hist_total));
        an.dims = dims;
        an.type = type;
        for (const Recommendation& e : an.recommended) at.push_back(e.isovalue);
        std::sort(at.begin(), at.end());
        at.erase(std::unique(at.begin(), at.end()), at.end());
    }
    int n_at = int(at.size());
    MPI_Bcast(&n_at, 1, MPI_INT, 0, MPI_COMM_WORLD);
    at.resize(std::size_t(n_at));
    MPI_Bcast(at.data(), n_at, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    const auto labelling = std::chrono::steady_clock::now();
    std::vector<std::int64_t> at_counts;
    if (n_at > 0 && no_room.empty()) {
        const Volume part = mpi_tool::read_part(reader, parts, rank);
        const IsovalueSet sub = subset(iso, at);
        const mpi_tool::PartsCurve c =
            mpi_tool::components_of_parts(part, sub, Connectivity::cube, dims, rank, size, parts);
        if (rank == 0)
            for (double s : at) {
                std::size_t j = 0;
                while (j + 1 < sub.size() && sub.value(j) < s) ++j;
                if (sub.value(j) != s) throw std::logic_error("clfractal-mpi fd: a recommendation outside its set");
                at_counts.push_back(c.curve[j]);
            }
    }
    if (rank != 0) return 0;
    if (no_room.empty())
        fill_entry_components(an, [&](const std::vector<double>& x) {
            if (x != at) throw std::logic_error("clfractal-mpi fd: the recommendations' isovalues changed");
            return at_counts;
        });
    else if (n_at > 0)
        an.skipped.push_back("components: " + no_room);
    an.seconds_components = seconds_since(labelling);
    an.seconds = seconds_since(t0);
    // The ladder filters the whole volume in one process's memory.
    if (!an.clean && !an.recommended.empty()) an.skipped.push_back(cli::denoise_not_streamed());
    const FdSummary s = summarize(an.curve.fd, an.curve.counts[0], an.curve.counts[1], a.min_count);
    report(a, an, s, slowest, an.seconds_components, size, parts);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    cli::quiet = true;

    CLI::App app{"clfractal-mpi: the fractal dimension curve (or with `components` the component curve) of a "
                 "volume, z-parts counted by MPI ranks"};
    Args a, fa;
    app.option_defaults()->always_capture_default();
    // VOLUME is required unless a subcommand takes it (checked after parsing).
    CLI::Option* volume = setup_fd(&app, a)->required(false);
    CLI::App* fd = app.add_subcommand("fd", "the fractal dimension curve and its analysis (as clfractal fd --stream; "
                                            "the same as clfractal-mpi VOLUME)");
    setup_fd(fd, fa);
    mpi_tool::ComponentsArgs ca;
    CLI::App* components = app.add_subcommand(
        "components", "the number of isosurface components for every isovalue (as clfractal components)");
    mpi_tool::setup_components(components, ca);
    app.require_subcommand(0, 1);
    app.set_version_flag("--version", std::string("clfractal-mpi ") + clfractal::version());

    int code = 0;
    try {
        app.parse(argc, argv);
        if (components->parsed()) code = mpi_tool::run_components(ca, rank, size);
        else if (fd->parsed()) code = run(fa, rank, size);
        else if (volume->count() == 0) throw CLI::RequiredError(volume->get_name());
        else code = run(a, rank, size);
    } catch (const CLI::CallForHelp& e) {
        if (rank == 0) app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        if (rank == 0) app.exit(e);
    } catch (const CLI::ParseError& e) {
        if (rank == 0) std::cerr << "clfractal-mpi: error: " << e.what() << " (see clfractal-mpi --help)\n";
        code = 2;
    } catch (const InputError& e) {
        if (rank == 0) std::cerr << "clfractal-mpi: error: " << e.what() << "\n";
        code = 2;
    } catch (const DeviceError& e) {
        std::cerr << "clfractal-mpi: error (rank " << rank << "): " << e.what() << "\n";
        code = e.out_of_memory() ? 2 : 1;
    } catch (const std::exception& e) {
        std::cerr << "clfractal-mpi: error (rank " << rank << "): " << e.what() << "\n";
        code = 1;
    }
    // A rank that failed after the others entered a collective would leave them waiting:
    // abort the job with the failure's exit code.
    if (code != 0 && code != 2) MPI_Abort(MPI_COMM_WORLD, code);
    release_blas_caches();
    MPI_Finalize();
    return code;
}
