// Plain C++ definitions for the smooth isosurface construction (docs/definitions.md §18,
// thesis Algorithms 1 and 2) and for counting isosurface components by breadth-first search,
// written for obviousness, not speed.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/smooth.hpp"
#include "clfractal/volume.hpp"

namespace ref {

struct SmoothOutcome {
    clfractal::Volume volume;
    std::uint64_t pops = 0;             ///< queue pops, duplicates included
    std::uint64_t distinct_queued = 0;  ///< distinct edges that ever entered the queue
    std::uint64_t lowered = 0;          ///< pops whose edge was still intersected
};

/// Algorithm 1 then Algorithm 2 as the thesis writes them: a std::queue of vertex pairs
/// that may hold the same edge several times, values and isovalue compared in double (the
/// isovalue rounded to float32 first for float data), `ld` the LD field (NaN = undefined).
SmoothOutcome smooth(const clfractal::Volume& v, const std::vector<double>& ld, double iso, double h,
                     clfractal::SmoothVariant variant, double tau);

/// The LD field of a float32 volume as doubles.
std::vector<double> field_values(const clfractal::Volume& ld);

/// Number of grid edges (u, w) with min < s <= max (s rounded to float32 for float data).
std::uint64_t intersected_edges(const clfractal::Volume& v, double iso);
/// Number of intersected edges with LD > h at either end.
std::uint64_t high_fractal_edges(const clfractal::Volume& v, const std::vector<double>& ld, double iso, double h);

/// Isosurface components (docs/definitions.md §19, `cube` connectivity): b0({f < s},
/// 6-connected) + b0({f >= s}, 26-connected) - 1 when both sets are non-empty, else 0; by BFS
/// labelling.
std::uint64_t components_bfs(const clfractal::Volume& v, double iso);

}  // namespace ref
