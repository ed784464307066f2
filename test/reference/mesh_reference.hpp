// Plain references for the mesh tests: the Freudenthal edge count, connected components
// of {f < s} and {f >= s} by breadth-first search (docs/definitions.md §19 "Isosurface
// components"), and
// the topology of a triangle mesh (closedness, orientation, pieces, Euler characteristic).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "clfractal/mesh.hpp"
#include "clfractal/span.hpp"

namespace ref {

using clfractal::IsovalueSet;
using clfractal::Mesh;
using clfractal::Volume;

/// For every isovalue, the grid edges of the Freudenthal triangulation (offsets x, y, z,
/// x+y, y+z, x+z, x+y+z) with span [a, b], a < s <= b.
std::vector<std::uint64_t> freudenthal_edges_brute(const Volume& v, const IsovalueSet& iso);

/// Vertex adjacency: 6 (faces), 14 (Freudenthal: ±x, ±y, ±z, ±(x+y), ±(y+z), ±(x+z),
/// ±(x+y+z)) or 26 (the whole 3×3×3 neighbourhood).
enum class Adjacency { six = 6, fourteen = 14, twenty_six = 26 };

/// Connected components of {f >= s} (positive) or {f < s} (negative) by breadth-first search.
std::size_t components(const Volume& v, double s, bool positive, Adjacency adjacency);

/// What a closed, oriented surface must satisfy, counted plainly.
struct MeshTopology {
    std::size_t unused_vertices = 0;   ///< vertices no triangle uses
    std::size_t degenerate = 0;        ///< triangles repeating a vertex index
    std::size_t edges = 0;             ///< distinct undirected edges
    std::size_t open_or_branching = 0; ///< undirected edges not in exactly two triangles
    std::size_t misoriented = 0;       ///< edges of two triangles that run the same way in both
    std::size_t non_manifold_vertices = 0;  ///< vertices whose triangles do not form one fan cycle
    std::size_t pieces = 0;            ///< connected components of the triangles
    long euler = 0;                    ///< V - E + F
    double signed_volume = 0;          ///< sum of det(p0, p1, p2) / 6: > 0 when normals point out
    bool closed_manifold() const {
        return unused_vertices == 0 && degenerate == 0 && open_or_branching == 0 && misoriented == 0 &&
               non_manifold_vertices == 0;
    }
};
MeshTopology topology(const Mesh& m);

}  // namespace ref
