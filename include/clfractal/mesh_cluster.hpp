// Meshes reduced by vertex clustering, built slab by slab so that a surface of tens of millions
// of triangles is never held whole (docs/definitions.md §37): the bounded meshes of the
// report's views and previews.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "clfractal/mesh.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// Vertex clustering with cells of edge `cell` (physical units) from the origin: a vertex at p
/// goes to the cell (floor(p_x / cell), floor(p_y / cell), floor(p_z / cell)); a cluster's
/// position is the mean of its vertices' positions, its LD the mean of their defined LD (NaN
/// when none is); a triangle whose corners fall in three distinct clusters is kept, each
/// unordered triple of clusters once, with the corner order of its first triangle.
class MeshClusters {
public:
    explicit MeshClusters(double cell);

    /// Adds the vertices and triangles of `part` (with part.ld when it has one per vertex).
    /// Parts are added in the order of the whole mesh's triangles. A vertex whose grid edge
    /// ends below grid vertex `counted_from` (part.edge_points[i].w < counted_from: it lies in
    /// the slice the part shares with the part before) is mapped to its cluster for the
    /// triangles but not counted again. Slabs added so give exactly the clusters of the whole
    /// mesh.
    void add(const Mesh& part, std::uint64_t counted_from = 0);

    /// The clustering of the same vertices and triangles with cells `factor` times as large:
    /// fine cell (i, j, k) lies in coarse cell (i / factor, j / factor, k / factor), so the
    /// result equals clustering the added vertices at that size, without them.
    MeshClusters coarsened(std::uint32_t factor) const;

    double cell() const { return cell_; }
    std::size_t clusters() const { return n_.size(); }
    std::size_t triangles() const { return triangles_.size(); }
    /// The triangles added, before clustering.
    std::uint64_t input_triangles() const { return input_triangles_; }

    /// The clustered mesh: positions, LD and its colours (ld_colour), triangles.
    Mesh mesh() const;

private:
    struct CellHash {
        std::size_t operator()(const std::array<std::int64_t, 3>& c) const;
    };
    struct TripleHash {
        std::size_t operator()(const std::array<std::uint32_t, 3>& t) const;
    };
    std::uint32_t cluster_of(const std::array<std::int64_t, 3>& cell);
    void add_triangle(const std::array<std::uint32_t, 3>& t);

    double cell_;
    std::unordered_map<std::array<std::int64_t, 3>, std::uint32_t, CellHash> id_;
    std::vector<std::array<std::int64_t, 3>> cells_;
    std::vector<std::array<double, 3>> sum_;
    std::vector<double> ld_sum_;
    std::vector<std::uint32_t> n_, ld_n_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
    std::unordered_set<std::array<std::uint32_t, 3>, TripleHash> seen_;  // sorted cluster triples kept
    std::uint64_t input_triangles_ = 0;
};

/// The isosurface f = s of `v` clustered with cells of edge `cell` as it is extracted, slab by
/// slab (extract_isosurface_layers), each part coloured from `ld` (an LD field with v's dims)
/// when it is given: exactly the clusters of the whole mesh. Each slab is extracted in parts,
/// a thread each, then clustered in z order. Memory: the clusters and one slab's
/// full-resolution part, `layers` cube layers thick (0: about 2^21 cubes).
MeshClusters cluster_isosurface(const Volume& v, double s, double cell, const Volume* ld = nullptr,
                                MeshMethod method = MeshMethod::marching_cubes, std::size_t layers = 0);

/// `c` coarsened by the smallest integer factor that leaves at most `triangles` triangles (1
/// when it already has that few), as a mesh; `factor` receives it when given.
Mesh bounded_mesh(const MeshClusters& c, std::size_t triangles, std::uint32_t* factor = nullptr);

}  // namespace clfractal
