// The pieces of clfractal-mpi shared by its two commands (the FD curve, main.cpp; the component
// curve, components.cpp).
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "cli.hpp"
#include "clfractal/components.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/isovalue_set.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/span.hpp"

namespace mpi_tool {

/// The isovalue set of the value range over every rank, each giving its own part's [lo, hi]
/// (lo = +inf, hi = -inf for none; combined with MPI_Allreduce): `spec` (--isovalues) when
/// given, else the set of the single-process commands (IsovalueSet::for_range, `bins`, 0: 256).
clfractal::IsovalueSet global_isovalues(const std::string& spec, std::size_t bins, clfractal::ValueType type,
                                        double lo, double hi);

/// Counts the spans of `kind` at `levels` levels of the slices [z_begin, z_end) of `reader` (a
/// rank's z-part, z_begin a multiple of 2^(levels-1)) into `counts` (levels x iso.size(),
/// level-major); returns the counting seconds.
double count_part(clfractal::SliceReader& reader, const clfractal::IsovalueSet& iso, clfractal::SpanKind kind,
                  int levels, std::size_t z_begin, std::size_t z_end, std::vector<std::uint64_t>& counts);

/// The D(s) curve of counts summed over the ranks (as count_part lays them out) of a volume of
/// `dims`.
clfractal::FdCurve summed_curve(const std::vector<std::uint64_t>& total, const clfractal::IsovalueSet& iso,
                                clfractal::SpanKind kind, int levels, const clfractal::Dims& dims);

/// Slices parts[rank] of the file (a part shares its last slice with the next); an empty
/// volume for a rank without a part.
clfractal::Volume read_part(clfractal::SliceReader& reader, const std::vector<std::pair<std::size_t, std::size_t>>& parts,
                            int rank);

/// Before any read, on every rank: whether the ranks of each node have room for what
/// `command` needs of their z-parts of `part_bytes` each (4x a part + 256 MiB), else the same
/// InputError naming `volume` on every rank.
void require_part_memory(const std::string& volume, std::uint64_t part_bytes, int rank, const char* command);

/// The component curve at `iso` of the volume of `dims` whose z-parts `parts` the ranks hold
/// (`part`: this rank's, read_part): each rank counts its part with the links between its
/// first and last slices, rank 0 joins them (join_slab_components), exactly the curve of the
/// volume in one process. `curve` on rank 0 only; the slowest rank's counting and rank 0's
/// joining seconds.
struct PartsCurve {
    std::vector<std::int64_t> curve;
    double slowest = 0, joining = 0;
};
PartsCurve components_of_parts(const clfractal::Volume& part, const clfractal::IsovalueSet& iso,
                               clfractal::Connectivity mode, const clfractal::Dims& dims, int rank, int size,
                               const std::vector<std::pair<std::size_t, std::size_t>>& parts);

struct ComponentsArgs {
    std::string volume, csv, json, plot, connectivity = "cube", isovalues;
    std::size_t bins = 0;
    cli::RawArgs raw;
};

/// The options of `clfractal-mpi components` (those of `clfractal components` that need no
/// whole volume).
void setup_components(CLI::App* app, ComponentsArgs& a);

/// `clfractal-mpi components` on rank `rank` of `size`; rank 0 reports.
int run_components(const ComponentsArgs& a, int rank, int size);

}  // namespace mpi_tool
