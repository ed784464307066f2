// The small-components filter straight from docs/definitions.md §35, by breadth-first
// search: the reference of test/processing/small_components_test.cpp.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "clfractal/volume.hpp"

namespace reference {

/// The components of {v : member[v]} with 6 or 26 neighbours: label[v] = component number
/// (0, 1, ...) of a member, -1 elsewhere; sizes[c] = vertices of component c.
struct Labels {
    std::vector<long> label;
    std::vector<std::size_t> sizes;
};
Labels label_components(const clfractal::Dims& d, const std::vector<bool>& member, int adjacency);

struct SmallComponents {
    clfractal::Volume volume;
    std::size_t positive_before = 0, negative_before = 0, positive_removed = 0, negative_removed = 0,
                positive_after = 0, negative_after = 0;
    std::size_t changed = 0;  ///< vertices whose value differs from the input
    /// The six component counts in declaration order, for comparisons in one piece.
    std::array<std::size_t, 6> counts() const {
        return {positive_before, negative_before, positive_removed, negative_removed, positive_after, negative_after};
    }
};

/// Step (1): small `positive_adjacency`-connected components of {f >= s} to the largest value
/// below s; step (2): small 6-connected components of {f < s} of the result to the smallest
/// value at or above s.
SmallComponents small_components_filter(const clfractal::Volume& v, double s, std::size_t k, int positive_adjacency);

}  // namespace reference
