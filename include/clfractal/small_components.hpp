// Small-components filter (docs/definitions.md §35 "Small-components filter"; Zhao & Wenger
// 2025, "Filtering of Small Components for Isosurface Generation", in the project's cube
// convention).
//
// For isovalue s (taken in the data's type: integer data ceil(s), float32 data float(s),
// float64 data s, as IsovalueSet::single) and size K:
//   (1) every component of the positive set {f >= s} with at most K vertices gets the
//       largest value of the type below s (integers ceil(s) - 1, floats the next float
//       below s);
//   (2) then, on the result of (1), every component of the negative set {f < s} with at most
//       K vertices gets the smallest value of the type at or above s (integers ceil(s),
//       floats s in the data's type).
// All other vertices keep their values. Connectivity `cube` (the default, marching cubes
// with separated negative vertices): the positive set is 26-connected, the negative set
// 6-connected. `six`: both 6-connected (the paper's own variant).
//
// Guarantee (both connectivities): when the grid has more than K vertices, no component of
// either set of the result has K or fewer vertices. When it has K or fewer, every vertex
// ends at the value of step (2): one positive component of at most K vertices.
//
// The labelling is one raster-order pass per set on the host over the set's runs along x,
// each joined by union-find (union by size, path halving) to the runs of the rows before it
// that it touches: 4 bytes a run (at most one run a vertex; 8 bytes from 2^31 vertices) and
// two planes of runs. Four labellings at most: the last two count the components of the
// input's negative set and of the result's positive set, which are those already counted
// when step (1), or both steps, changed nothing.
#pragma once
#include <cstddef>
#include <string>

#include "clfractal/volume.hpp"

namespace clfractal {

enum class SmallComponentsConnectivity { cube, six };

/// "cube" / "six"; throws InputError on anything else.
SmallComponentsConnectivity parse_small_components_connectivity(const std::string& name);
/// "cube" / "six".
const char* small_components_connectivity_name(SmallComponentsConnectivity c);

struct SmallComponentsResult {
    Volume volume;                       ///< the filtered volume (input type, dims, spacing)
    double isovalue = 0;                 ///< s in the data's type
    double lowered_value = 0;            ///< the value of step (1)
    double raised_value = 0;             ///< the value of step (2)
    std::size_t positive_before = 0;     ///< components of {f >= s} in the input
    std::size_t negative_before = 0;     ///< components of {f < s} in the input
    std::size_t positive_removed = 0;    ///< components lowered in step (1)
    std::size_t negative_removed = 0;    ///< components raised in step (2)
    std::size_t positive_after = 0;      ///< components of {f >= s} in the result
    std::size_t negative_after = 0;      ///< components of {f < s} in the result
    std::size_t lowered = 0;             ///< vertices set in step (1)
    std::size_t raised = 0;              ///< vertices set in step (2) (some of them lowered in (1))
    std::size_t changed = 0;             ///< vertices whose value differs from the input
    double changed_share = 0;            ///< changed / vertices
    double seconds = 0;                  ///< wall time of the labelling and the changes
};

/// The small-components filter of `v` at isovalue `iso` with size `k` (0 changes nothing).
/// Throws InputError when `iso` is not finite, when the type has no value below s or none
/// at or above it (e.g. uint8 data at s <= 0 or s > 255), or when `v` has NaN or Inf.
SmallComponentsResult small_components_filter(const Volume& v, double iso, std::size_t k,
                                              SmallComponentsConnectivity mode = SmallComponentsConnectivity::cube);

}  // namespace clfractal
