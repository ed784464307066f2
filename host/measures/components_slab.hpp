// Isosurface components of a volume cut into z-slabs that share one slice each
// (clfractal-mpi components; docs/definitions.md §19, §28). Private to the library.
//
// A slab's own curve is components(s) = b0(A ∩ S) + b0(C ∩ S) - 1, for every s (0 when A or
// C misses it). What the slab's sweeps add to join it with its neighbours are their links
// between boundary vertices (its first and last slices): whenever two components that both
// hold boundary vertices merge, a link between one boundary vertex of each, at the bin of the
// vertex being swept. The links of a sweep form a forest whose trees are exactly the
// boundary vertices of the slab's components, for every prefix of the sweep.
#pragma once
#include <cstdint>
#include <vector>

#include "clfractal/components.hpp"

namespace clfractal {

/// Two boundary vertices of a slab that one of its sweeps joins when it reaches a vertex of
/// bin `bin` (the first isovalue index j with f < s_j; K when none). Boundary vertex ids: the
/// first slice x + nx y, the last slice nx ny + x + nx y.
struct BoundaryLink {
    std::uint32_t a, b, bin;
};

/// What joins a slab to its neighbours.
struct SlabLinks {
    std::vector<BoundaryLink> join, split;  ///< the links of the increasing and decreasing sweeps
    std::vector<std::uint32_t> last_bins;   ///< the bins of the last slice's vertices (when it is shared)
};

struct SlabComponents {
    std::vector<std::int64_t> components;  ///< the slab's own curve, as count_components gives it
    SlabLinks links;
    double seconds = 0;  ///< as ComponentCurve::seconds
};

/// InputError unless every isovalue is finite (count_components_at, on the host or the device).
void check_isovalues(const std::vector<double>& isovalues);

/// The curve of `slab` and its links; `first` / `last`: the first / last slice is shared with
/// the slab before / after (a slab of one slice cannot share both).
SlabComponents count_slab_components(Context& ctx, const Volume& slab, const IsovalueSet& iso, Connectivity mode,
                                     bool first, bool last);

/// The curve of the whole volume from the sum of its slabs' curves and their links in z order,
/// slab r + 1 starting at the last slice of slab r (each counted by count_slab_components with
/// first = r > 0, last = r < R - 1), `slice_vertices` = nx ny: exactly count_components of the
/// whole volume.
std::vector<std::int64_t> join_slab_components(std::vector<std::int64_t> curve_sum, const std::vector<SlabLinks>& slabs,
                                               std::size_t slice_vertices);

/// Consecutive slabs joined one after another in z order, held as one slab: the sum of their
/// curves, what their seams add to it, and the links of the run between its own first and
/// last slices (those of its first and last slab), so that a run joins the next slab or run
/// as a slab does. Each seam takes the links of both sides in bin order through a union-find
/// over three slices (the shared one contracted: each of its vertices joins its two copies at
/// its bin, a union every time) and keeps a link wherever two components holding vertices of
/// the run's own boundary slices merge. Memory O(slice), whatever the number of slabs.
class SlabRun {
public:
    SlabRun(std::size_t isovalues, std::size_t slice_vertices);
    /// Appends the next slab: its curve and links (count_slab_components with `first` and
    /// `last`). The first slab appended gives the run its `first`; each later one must share
    /// its first slice with the run's last (first = true, the run's last = true).
    void append(const std::vector<std::int64_t>& curve, SlabLinks links, bool first, bool last);
    /// Appends the next run, as a slab.
    void append(SlabRun&& next);
    bool empty() const { return empty_; }
    /// The curve of the slabs so far as one slab (count_slab_components of their union).
    std::vector<std::int64_t> curve() const;
    /// Their links as one slab's.
    SlabLinks& links() { return links_; }

private:
    std::size_t K_, nxy_;
    bool empty_ = true, first_ = false, last_ = false;
    std::vector<std::int64_t> sum_;            // the slabs' curves summed, one an isovalue
    std::vector<std::int64_t> join_, split_;   // per bin (K + 1): links - unions - shared vertices
    std::int64_t seams_ = 0;
    SlabLinks links_;
};

}  // namespace clfractal
