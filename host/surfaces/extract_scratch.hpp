// The marching cubes' per-slice arrays, kept between calls: extracting a volume in many thin
// slabs (cluster_isosurface) then allocates and initialises them once per thread, not once per
// slab.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "clfractal/mesh.hpp"
#include "clfractal/volume.hpp"

namespace clfractal::detail {

struct ExtractScratch {
    std::size_t plane = 0;  ///< the slice size the arrays were made for
    std::vector<std::uint8_t> sign_lower, sign_upper, cases;
    /// Vertex indices plus `base` (the vertices of the earlier calls), so an entry of an
    /// earlier call reads as stale without clearing the arrays.
    std::vector<std::uint32_t> lower, upper, across;
    std::uint32_t base = 0;
    /// A mesh whose vectors the next call fills (emptied, their capacity kept): the parts of
    /// cluster_isosurface come back to be filled again, instead of growing from nothing.
    Mesh spare;
};

/// extract_isosurface_layers with the arrays of `scratch` (one scratch per thread).
Mesh extract_isosurface_layers(const Volume& v, double s, std::size_t z0, std::size_t z1, MeshMethod method,
                               ExtractScratch& scratch);

/// interpolate_on_vertices into `out` (resized; its capacity kept).
void interpolate_on_vertices(const Mesh& mesh, const Volume& field, std::vector<float>& out);

}  // namespace clfractal::detail
