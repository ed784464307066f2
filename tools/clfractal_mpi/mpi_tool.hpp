// The pieces of clfractal-mpi shared by its two commands (the FD curve, main.cpp; the component
// curve, components.cpp).
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "cli.hpp"
#include "clfractal/isovalue_set.hpp"

namespace mpi_tool {

/// The isovalue set of the value range over every rank, each giving its own part's [lo, hi]
/// (lo = +inf, hi = -inf for none; combined with MPI_Allreduce): `spec` (--isovalues) when
/// given, else the set of the single-process commands (IsovalueSet::for_range, `bins`, 0: 256).
clfractal::IsovalueSet global_isovalues(const std::string& spec, std::size_t bins, clfractal::ValueType type,
                                        double lo, double hi);

struct ComponentsArgs {
    std::string volume, csv, connectivity = "cube", isovalues;
    std::size_t bins = 0;
    cli::RawArgs raw;
};

/// The options of `clfractal-mpi components` (those of `clfractal components` that need no
/// whole volume).
void setup_components(CLI::App* app, ComponentsArgs& a);

/// `clfractal-mpi components` on rank `rank` of `size`; rank 0 reports.
int run_components(const ComponentsArgs& a, int rank, int size);

}  // namespace mpi_tool
