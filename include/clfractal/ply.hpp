// PLY files of meshes (the I/O library, clfractal::io): binary little-endian, with the
// thesis colour map and the LD value per vertex when the mesh has them.
#pragma once
#include <string>

#include "clfractal/mesh.hpp"

namespace clfractal {

/// Writes binary little-endian PLY: vertex x y z (float), then uchar red green blue when
/// the mesh has colours, then float ld when it has LD values; faces as a uchar-counted
/// int list. Written to a temporary name and renamed: never a half-written file. Throws
/// InputError naming the path when it cannot be written.
void write_ply(const Mesh& mesh, const std::string& path);

/// Reads back a PLY file of the layout write_ply produces (triangles only); throws
/// InputError naming the path on anything else. edge_points stay empty.
Mesh read_ply(const std::string& path);

}  // namespace clfractal
