// Isosurface meshes (docs/definitions.md §15 "Isosurface meshes", with §4 "Span and
// intersection", §14 "Colour map", §19 "Isosurface components"; thesis §2.4 and chapter 5):
// marching cubes and marching tetrahedra with one mesh vertex per intersected grid edge
// (PLY files: ply.hpp).
//
// A vertex is positive when f >= s and negative when f < s; a grid edge with span
// [a, b] is intersected iff a < s <= b, and carries exactly one mesh vertex, shared by
// every cube around it, at the linear interpolation point of s along the edge.
//
// Marching cubes separates negative vertices: inside each cube the surface keeps
// negative vertices apart unless they are joined by cube edges, and keeps all positive
// vertices of the cube in one region. So the negative set {f < s} is 6-connected and the
// positive set {f >= s} 26-connected (the `cube` connectivity of docs/definitions.md §19),
// the mesh has b0(A, 6) + b0(C, 26) - 1 pieces, and it is a closed 2-manifold away from the
// grid border.
// Its vertex count is E(s) (count_spans with SpanKind::edges).
//
// Marching tetrahedra splits every cube into the 6 tetrahedra of the Freudenthal (Kuhn)
// triangulation around the diagonal (0,0,0)-(1,1,1). Its grid edges are the edges from a
// vertex to the offsets x, y, z, x+y, y+z, x+z, x+y+z, so both sets are 14-connected (the
// `freudenthal` connectivity) and the surface is the level set of the piecewise-linear
// function.
//
// Orientation: every triangle (a, b, c) has its right-hand normal (b - a) x (c - a)
// pointing towards the negative side, i.e. towards lower values, which is outwards for
// a bright object on a dark background (CT, MRI).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

enum class MeshMethod { marching_cubes, marching_tetrahedra };

/// "mc" / "mt" (also "marching-cubes" / "marching-tetrahedra"); throws InputError.
MeshMethod parse_mesh_method(const std::string& name);

/// Where a mesh vertex lies: on the grid edge from vertex `u` to vertex `w` (linear
/// indices, u the one with smaller coordinates), at u + t (w - u), t in [0, 1].
struct EdgePoint {
    std::uint64_t u = 0, w = 0;
    float t = 0;
};

struct Mesh {
    /// Positions in physical units: grid coordinates times Volume::spacing.
    std::vector<std::array<float, 3>> positions;
    /// Triangles as vertex indices, oriented towards the negative side (see above).
    std::vector<std::array<std::uint32_t, 3>> triangles;
    /// The grid edge of every vertex (filled by extraction, empty after read_ply).
    std::vector<EdgePoint> edge_points;
    /// Optional per-vertex scalar (the local fractal dimension): empty or one per vertex.
    std::vector<float> ld;
    /// Optional per-vertex colour (RGB): empty or one per vertex.
    std::vector<std::array<std::uint8_t, 3>> colors;
};

/// The isosurface f = s of `v`. For float32 data s is rounded to float32 first, as every
/// float32 isovalue is (docs/definitions.md §3); other types compare in double, exactly. An
/// axis of fewer than 2 vertices has no cubes: the mesh is then empty. Throws InputError when
/// the mesh would exceed 2^31 - 1 vertices or triangles (the PLY index type).
Mesh extract_isosurface(const Volume& v, double s, MeshMethod method = MeshMethod::marching_cubes);
/// The part of extract_isosurface(v, s) in the cube layers z0 <= z < z1 (layer z joins slices z
/// and z + 1): the same vertices (positions, edge points) and triangles, in the same order, as
/// the whole mesh has there; a vertex on slice z0 or z1 shared with a neighbouring slab is in
/// both parts. Consecutive slabs [0, a), [a, b), ... together give the whole mesh.
Mesh extract_isosurface_layers(const Volume& v, double s, std::size_t z0, std::size_t z1,
                               MeshMethod method = MeshMethod::marching_cubes);
/// The same for a device volume (meshing runs on the host: the values are downloaded).
Mesh extract_isosurface(const DeviceVolume& v, double s, MeshMethod method = MeshMethod::marching_cubes);

/// Per-vertex values of a field with the volume's dims (float32, e.g. the LD field),
/// interpolated along each vertex's grid edge: field(u) + t (field(w) - field(u)); NaN when
/// either end is NaN. Needs mesh.edge_points; throws InputError on a dims mismatch.
std::vector<float> interpolate_on_vertices(const Mesh& mesh, const Volume& field);

/// Sets mesh.ld from an LD field (float32, the volume's dims, as local_fractal_dimension
/// returns it) and mesh.colors from the thesis colour map ld_colour (local.hpp).
void color_by_ld(Mesh& mesh, const Volume& ld_field);
/// The same with the LD field on the device (downloaded).
void color_by_ld(Mesh& mesh, const DeviceVolume& ld_field);

}  // namespace clfractal
