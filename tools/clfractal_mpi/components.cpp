// clfractal-mpi components: the component curve of one volume (docs/definitions.md §19, §28)
// counted by MPI ranks. Rank r reads and counts its z-part [b_r, b_{r+1}] alone (sharing its
// last slice with the next part: split_slices with one level), with the links its sweeps make
// between the vertices of its first and last slices; rank 0 sums the parts' curves
// (MPI_Reduce), gathers the links (MPI_Gatherv) and joins them (join_slab_components): the
// curve equals the single-process `clfractal components` exactly, and so do its --csv, --json
// and --plot files.
#include <mpi.h>

#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <stdexcept>

#include "clfractal/advice.hpp"
#include "clfractal/components.hpp"
#include "clfractal/error.hpp"
#include "clfractal/memory.hpp"
#include "clfractal/slice_reader.hpp"
#include "measures/components_slab.hpp"
#include "mpi_tool.hpp"
#include "output.hpp"
#include "plots.hpp"

using namespace clfractal;

namespace mpi_tool {

IsovalueSet global_isovalues(const std::string& spec, std::size_t bins, ValueType type, double lo, double hi) {
    double local[2] = {-lo, hi}, global[2];
    MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (!spec.empty()) return cli::parse_isovalues(spec, type);
    return IsovalueSet::for_range(type, -global[0], global[1], bins ? bins : 256);
}

namespace {

// Rank 0 gets every rank's `mine`, one vector a rank; the others get nothing.
std::vector<std::vector<std::uint32_t>> gather(const std::vector<std::uint32_t>& mine, int rank, int size) {
    constexpr std::size_t most = std::size_t(std::numeric_limits<int>::max());
    if (mine.size() > most) throw std::runtime_error("components: more than 2^31 link words on one rank");
    const int n = int(mine.size());
    std::vector<int> counts(std::size_t(size), 0), offsets(std::size_t(size), 0);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::size_t total = 0;
    for (int r = 0; r < size; ++r) offsets[std::size_t(r)] = int(std::min(total, most)), total += counts[std::size_t(r)];
    if (rank == 0 && total > most) throw std::runtime_error("components: more than 2^31 link words in all");
    std::vector<std::uint32_t> all(rank == 0 ? total : 0);
    MPI_Gatherv(mine.data(), n, MPI_UINT32_T, all.data(), counts.data(), offsets.data(), MPI_UINT32_T, 0,
                MPI_COMM_WORLD);
    std::vector<std::vector<std::uint32_t>> out;
    if (rank == 0)
        for (int r = 0; r < size; ++r) {
            const auto begin = all.begin() + offsets[std::size_t(r)];
            out.emplace_back(begin, begin + counts[std::size_t(r)]);
        }
    return out;
}

static_assert(sizeof(BoundaryLink) == 3 * sizeof(std::uint32_t), "BoundaryLink: three words, no padding");

std::vector<std::uint32_t> words(const std::vector<BoundaryLink>& links) {
    std::vector<std::uint32_t> w(3 * links.size());
    if (!links.empty()) std::memcpy(w.data(), links.data(), w.size() * sizeof(std::uint32_t));
    return w;
}

std::vector<BoundaryLink> links_of(const std::vector<std::uint32_t>& w) {
    std::vector<BoundaryLink> links(w.size() / 3);
    if (!links.empty()) std::memcpy(links.data(), w.data(), links.size() * sizeof(BoundaryLink));
    return links;
}

}  // namespace

Volume read_part(SliceReader& reader, const std::vector<std::pair<std::size_t, std::size_t>>& parts, int rank) {
    if (std::size_t(rank) >= parts.size()) return Volume();
    const auto [z0, z1] = parts[std::size_t(rank)];
    const Dims d = reader.dims();
    Volume v(Dims{d.nx, d.ny, z1 - z0}, reader.type());
    reader.seek(z0);
    reader.read(v.data(), z1 - z0);
    return v;
}

PartsCurve components_of_parts(const Volume& part, const IsovalueSet& iso, Connectivity mode, const Dims& dims,
                               int rank, int size, const std::vector<std::pair<std::size_t, std::size_t>>& parts) {
    SlabComponents s;
    if (std::size_t(rank) < parts.size())
        s = count_slab_components(Context::shared(), part, iso, mode, rank > 0, std::size_t(rank) + 1 < parts.size());
    s.components.resize(iso.size(), 0);
    PartsCurve out;
    std::vector<std::int64_t> sum(iso.size(), 0);
    MPI_Reduce(s.components.data(), sum.data(), int(iso.size()), MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(&s.seconds, &out.slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    const auto join = gather(words(s.links.join), rank, size), split = gather(words(s.links.split), rank, size);
    const auto last = gather(s.links.last_bins, rank, size);
    if (rank != 0) return out;
    const auto start = std::chrono::steady_clock::now();
    std::vector<SlabLinks> links(parts.size());
    for (std::size_t r = 0; r < parts.size(); ++r) links[r] = {links_of(join[r]), links_of(split[r]), last[r]};
    out.curve = join_slab_components(std::move(sum), links, dims.nx * dims.ny);
    out.joining = seconds_since(start);
    return out;
}

namespace {

// The text of the first failing rank's check (empty when none failed), on every rank.
std::string first_failure(const std::string& mine, int me) {
    int failing = mine.empty() ? INT_MAX : me, first = INT_MAX;
    MPI_Allreduce(&failing, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == INT_MAX) return {};
    int length = int(mine.size());
    MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
    std::string text = me == first ? mine : std::string(std::size_t(length), ' ');
    MPI_Bcast(text.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
    return text;
}

}  // namespace

// Before any read: the ranks of each node together need what `clfractal components` needs for
// their z-parts (4x each part + 256 MiB), against what the node has. Every rank gets the same
// verdict (an InputError naming the file), so no rank is left waiting in a collective.
void require_part_memory(const std::string& volume, std::uint64_t part_bytes, int rank, const char* command) {
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
    int node_rank = 0, node_size = 1;
    MPI_Comm_rank(node, &node_rank);
    MPI_Comm_size(node, &node_size);
    const cli::MemoryNeed need{command};
    std::uint64_t mine = part_bytes ? need.bytes(part_bytes) : 0, together = 0, largest = 0;
    MPI_Allreduce(&mine, &together, 1, MPI_UINT64_T, MPI_SUM, node);
    MPI_Allreduce(&part_bytes, &largest, 1, MPI_UINT64_T, MPI_MAX, node);
    MPI_Comm_free(&node);
    std::string error;
    if (node_rank == 0) {
        MemoryRequest r;
        r.need = together;
        r.file = volume;
        r.what = need.command;
        r.basis = std::to_string(node_size) + " rank(s) on this node, each 4x its z-part (up to " +
                  byte_size_string(largest) + ") + 256 MiB";
        r.hint = "more nodes, or more ranks on nodes with room; CLFRACTAL_MEMORY_LIMIT=off runs it anyway";
        try {
            require_memory(r);
        } catch (const InputError& e) {
            error = e.what();
        }
    }
    const std::string first = first_failure(error, rank);
    if (!first.empty()) throw InputError(first);
}

int run_components(const ComponentsArgs& a, int rank, int size) {
    // Each rank opens the file and reads only the slices of its own z-part.
    SliceReader reader(a.volume, a.raw.options());
    const Dims dims = reader.dims();
    const ValueType type = reader.type();
    const Connectivity mode = parse_connectivity(a.connectivity);
    cli::check_bins(a.bins, type);
    const auto parts = split_slices(dims.nz, 1, std::size_t(size));
    const std::uint64_t part_slices =
        std::size_t(rank) < parts.size() ? parts[std::size_t(rank)].second - parts[std::size_t(rank)].first : 0;
    require_part_memory(a.volume, part_slices * dims.nx * dims.ny * value_size(type), rank, "clfractal-mpi components");
    const Volume part = read_part(reader, parts, rank);
    const ValueRange r = std::size_t(rank) < parts.size() ? value_range(part) : ValueRange{INFINITY, -INFINITY};
    const IsovalueSet iso = global_isovalues(a.isovalues, a.bins, type, r.min, r.max);
    const PartsCurve c = components_of_parts(part, iso, mode, dims, rank, size, parts);
    // --plot: the cube counts of levels 0 and 1 under the curve, as clfractal components draws
    // them, from z-parts counted by the ranks (starting at even slices) and summed on rank 0.
    std::optional<FdCurve> spans;
    if (!a.plot.empty()) {
        const auto span_parts = split_slices(dims.nz, 2, std::size_t(size));
        std::vector<std::uint64_t> counts(2 * iso.size(), 0), total(counts.size(), 0);
        if (std::size_t(rank) < span_parts.size())
            count_part(reader, iso, SpanKind::cubes, 2, span_parts[std::size_t(rank)].first,
                       span_parts[std::size_t(rank)].second, counts);
        MPI_Reduce(counts.data(), total.data(), int(counts.size()), MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
        if (rank == 0) spans = summed_curve(total, iso, SpanKind::cubes, 2, dims);
    }
    if (rank != 0) return 0;
    const std::vector<std::int64_t>& curve = c.curve;
    const double slowest = c.slowest, joining = c.joining;
    cli::print_components(std::cout, a.volume, dims, type, mode, iso, curve);
    std::cout << "ranks         " << size << " (" << parts.size()
              << " with a z-part), device of rank 0: " << Context::shared().description() << "\n"
              << std::setprecision(4) << "time          " << slowest << " s counting (slowest rank) + " << joining
              << " s joining on rank 0 (" << double(dims.vertices()) / (slowest + joining) / 1e6 << " Mvoxel/s)\n";
    if (!a.csv.empty()) write_file_atomic(a.csv, cli::components_csv(iso, curve));
    if (!a.json.empty()) write_file_atomic(a.json, cli::components_json(a.volume, dims, type, mode, iso, curve));
    if (spans) {
        const std::string title = cli::components_plot_title(a.volume, mode);
        cli::write_components_plot(*spans, clean_bands(*spans), curve, false, title, a.plot);
    }
    return 0;
}

void setup_components(CLI::App* c, ComponentsArgs& a) {
    cli::add_volume_argument(c, a.volume);
    c->add_option("--connectivity", a.connectivity,
                  "cube: {f<s} 6- and {f>=s} 26-connected (marching cubes); freudenthal: both 14-connected");
    cli::add_isovalues_option(c, a.isovalues);
    cli::add_bins_option(c, a.bins);
    c->add_option("--csv", a.csv, "write isovalue,components (as clfractal components --csv)");
    c->add_option("--json", a.json, "write the curve as JSON (as clfractal components --json)");
    c->add_option("--plot", a.plot, "draw the curve (log scale) to a PNG with gnuplot (as clfractal components --plot)");
    a.raw.add(c);
}

}  // namespace mpi_tool
