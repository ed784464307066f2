// Preview images of meshes: a small software rasterizer (z-buffer, Lambert shading) and
// PNG files through libpng. Software because the tool runs on headless machines with no
// GL; a preview is one image per run, so a few hundred milliseconds are fine.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "clfractal/mesh.hpp"

namespace clfractal {

/// An 8-bit RGB image, rows top to bottom.
struct Image {
    std::size_t width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  ///< 3 * width * height
    std::array<std::uint8_t, 3> pixel(std::size_t x, std::size_t y) const {
        const std::size_t i = 3 * (y * width + x);
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

struct RenderOptions {
    std::size_t width = 800, height = 600;
    /// The viewer's direction from the mesh: azimuth around +z from +x and elevation above
    /// the xy plane, in degrees. The default is a three-quarter view from the front right,
    /// slightly above, with z up.
    double azimuth_deg = -60, elevation_deg = 25;
    /// Rendered at supersample^2 samples per pixel and averaged (anti-aliasing).
    int supersample = 2;
    std::array<std::uint8_t, 3> background{255, 255, 255};
    /// Colour of meshes without per-vertex colours.
    std::array<std::uint8_t, 3> surface{205, 200, 190};
};

/// Renders `mesh` in orthographic projection, scaled to fill the image with a margin,
/// with a z-buffer and two-sided Lambert shading (a fixed light from the viewer's upper
/// left) of normals interpolated from the vertices; per-vertex colours are interpolated
/// across each triangle. An empty mesh gives a background-only image.
Image render_mesh(const Mesh& mesh, const RenderOptions& opt = {});

/// An axial slice of a volume with an isosurface's contour and an LD field, for reports.
struct SliceView {
    /// Slice z in grey (its 0.5% .. 99.5% value quantiles mapped black .. white), one pixel
    /// per vertex, rows top to bottom from y = ny - 1 down to y = 0, with the LD field blended
    /// over it in the colour map (ld_colour) wherever LD is defined.
    Image image;
    /// The contour of the isovalue in the slice: the segments (x0, y0, x1, y1) that marching
    /// squares draws, one per crossed face edge pair (negative vertices f < s separated, as
    /// marching cubes does on a cube face), in grid coordinates times the spacing. A grid edge
    /// with span [a, b] is crossed iff a < s <= b (float32 data compare with s rounded to
    /// float32), at the linear interpolation point of s.
    std::vector<std::array<float, 4>> contour;
};

/// The view of slice z of `v` for isovalue `iso`, with `ld` (float32, v's dims, NaN where
/// undefined; or null) blended at opacity `alpha`. Throws InputError when z is out of range
/// or ld's dims differ.
SliceView render_slice(const Volume& v, std::size_t z, double iso, const Volume* ld = nullptr, double alpha = 0.45);

/// The axial slice whose x and y grid edges the isovalue crosses most often (the nearest to
/// the middle among equals): where the contour has the most to show.
std::size_t busiest_slice(const Volume& v, double iso);

/// Writes an RGB PNG through libpng, to a temporary name renamed into place. Throws
/// InputError naming the path when it cannot be written.
void write_png(const Image& image, const std::string& path);

/// Reads any PNG through libpng, converted to 8-bit RGB; throws InputError naming the path.
Image read_png(const std::string& path);

}  // namespace clfractal
