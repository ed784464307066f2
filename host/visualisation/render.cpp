// Software rasterizer for mesh previews (no GL on headless machines) and PNG files
// through libpng's simplified API.
#include "io/output_file.hpp"
#include "clfractal/render.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clfractal {
namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec normalized(const Vec& a) {
    const double n = std::sqrt(dot(a, a));
    return n > 0 ? Vec{a[0] / n, a[1] / n, a[2] / n} : a;
}
Vec position(const Mesh& m, std::uint32_t i) {
    return {double(m.positions[i][0]), double(m.positions[i][1]), double(m.positions[i][2])};
}

// The camera's basis: `toward` points from the mesh to the viewer; depth grows towards the viewer.
struct Camera {
    Vec toward, right, up, light;
};

Camera make_camera(const RenderOptions& opt) {
    const double pi = 3.14159265358979323846, az = opt.azimuth_deg * pi / 180, el = opt.elevation_deg * pi / 180;
    const Vec toward{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    const Vec up_hint = std::abs(std::cos(el)) < 1e-6 ? Vec{0, 1, 0} : Vec{0, 0, 1};
    const Vec right = normalized(cross(up_hint, toward)), up = cross(toward, right);
    const Vec light = normalized({toward[0] + 0.5 * up[0] - 0.4 * right[0], toward[1] + 0.5 * up[1] - 0.4 * right[1],
                                  toward[2] + 0.5 * up[2] - 0.4 * right[2]});
    return {toward, right, up, light};
}

// Project, and fit the projected bounding box into the W x H image with a 5% margin.
std::vector<Vec> project_to_screen(const Mesh& mesh, const Camera& cam, std::size_t W, std::size_t H) {
    const Vec &right = cam.right, &up = cam.up, &toward = cam.toward;
    const std::size_t nv = mesh.positions.size();
    std::vector<Vec> screen(nv);
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    for (std::size_t i = 0; i < nv; ++i) {
        const Vec p = position(mesh, std::uint32_t(i));
        screen[i] = {dot(p, right), dot(p, up), dot(p, toward)};
        x0 = std::min(x0, screen[i][0]), x1 = std::max(x1, screen[i][0]);
        y0 = std::min(y0, screen[i][1]), y1 = std::max(y1, screen[i][1]);
    }
    const double extent = std::max({x1 - x0, (y1 - y0) * double(W) / double(H), 1e-12});
    const double scale = 0.9 * double(W) / extent, cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    for (Vec& s : screen) s = {double(W) / 2 + (s[0] - cx) * scale, double(H) / 2 - (s[1] - cy) * scale, s[2]};
    return screen;
}

// Vertex normals: sums of the adjacent triangles' area-weighted normals.
std::vector<Vec> vertex_normals(const Mesh& mesh) {
    std::vector<Vec> normal(mesh.positions.size(), Vec{0, 0, 0});
    for (const auto& t : mesh.triangles) {
        const Vec n = cross(sub(position(mesh, t[1]), position(mesh, t[0])), sub(position(mesh, t[2]), position(mesh, t[0])));
        for (std::uint32_t i : t)
            for (int a = 0; a < 3; ++a) normal[i][a] += n[a];
    }
    return normal;
}

// The supersampled frame: colour and depth of every sample, W x H.
struct Frame {
    std::size_t W, H;
    std::vector<float> rgb, depth;
};

// Fill the frame with the triangle t, depth-tested, shaded two-sided by the light.
void rasterize_triangle(const Mesh& mesh, const RenderOptions& opt, const std::vector<Vec>& screen,
                        const std::vector<Vec>& normal, const Vec& light, bool colored,
                        const std::array<std::uint32_t, 3>& t, Frame& fr) {
    const std::size_t W = fr.W, H = fr.H;
    std::vector<float>& rgb = fr.rgb;
    std::vector<float>& depth = fr.depth;
    const Vec &a = screen[t[0]], &b = screen[t[1]], &c = screen[t[2]];
    const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (std::abs(area) < 1e-12) return;  // degenerate or seen edge-on
    const Vec face = cross(sub(position(mesh, t[1]), position(mesh, t[0])), sub(position(mesh, t[2]), position(mesh, t[0])));
    // Pixel centres (px + 0.5, py + 0.5) inside the triangle's bounding box.
    const auto lo = [](double v) { return std::size_t(std::max(0.0, std::ceil(v - 0.5))); };
    const std::size_t px0 = lo(std::min({a[0], b[0], c[0]})), py0 = lo(std::min({a[1], b[1], c[1]}));
    const double px1 = std::min(double(W) - 1, std::floor(std::max({a[0], b[0], c[0]}) - 0.5));
    const double py1 = std::min(double(H) - 1, std::floor(std::max({a[1], b[1], c[1]}) - 0.5));
    for (std::size_t py = py0; double(py) <= py1; ++py)
        for (std::size_t px = px0; double(px) <= px1; ++px) {
            const double x = px + 0.5, y = py + 0.5;
            // Barycentric weights; dividing by the signed area accepts either winding.
            const double w0 = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) / area;
            const double w1 = ((c[0] - x) * (a[1] - y) - (c[1] - y) * (a[0] - x)) / area;
            const double w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            const float z = float(w0 * a[2] + w1 * b[2] + w2 * c[2]);
            const std::size_t k = py * W + px;
            if (!(z > depth[k])) continue;
            depth[k] = z;
            Vec n;
            for (int e = 0; e < 3; ++e) n[e] = w0 * normal[t[0]][e] + w1 * normal[t[1]][e] + w2 * normal[t[2]][e];
            if (dot(n, n) == 0) n = face;
            // Two-sided: the far side of an open surface is lit like the near side.
            const double shade = 0.25 + 0.75 * std::abs(dot(normalized(n), light));
            for (int e = 0; e < 3; ++e) {
                const double base = colored ? w0 * mesh.colors[t[0]][e] + w1 * mesh.colors[t[1]][e] +
                                                  w2 * mesh.colors[t[2]][e]
                                            : opt.surface[e];
                rgb[3 * k + e] = float(base * shade);
            }
        }
}

// Average each ss x ss block of samples into one pixel.
Image downsample(const std::vector<float>& rgb, std::size_t W, std::size_t ss, const RenderOptions& opt) {
    Image image;
    image.width = opt.width;
    image.height = opt.height;
    image.rgb.resize(3 * opt.width * opt.height);
    for (std::size_t y = 0; y < opt.height; ++y)
        for (std::size_t x = 0; x < opt.width; ++x)
            for (int e = 0; e < 3; ++e) {
                double sum = 0;
                for (std::size_t sy = 0; sy < ss; ++sy)
                    for (std::size_t sx = 0; sx < ss; ++sx) sum += rgb[3 * ((y * ss + sy) * W + x * ss + sx) + e];
                image.rgb[3 * (y * opt.width + x) + e] = std::uint8_t(std::lround(std::clamp(sum / double(ss * ss), 0.0, 255.0)));
            }
    return image;
}

}  // namespace

Image render_mesh(const Mesh& mesh, const RenderOptions& opt) {
    if (opt.width == 0 || opt.height == 0 || opt.width > 16384 || opt.height > 16384 || opt.supersample < 1 ||
        opt.supersample > 4)
        throw InputError("preview: image size must be 1..16384 and supersampling 1..4");
    const std::size_t ss = std::size_t(opt.supersample), W = opt.width * ss, H = opt.height * ss;

    const Camera cam = make_camera(opt);
    const std::size_t nv = mesh.positions.size();
    const std::vector<Vec> screen = project_to_screen(mesh, cam, W, H);
    const std::vector<Vec> normal = vertex_normals(mesh);

    Frame fr{W, H, std::vector<float>(3 * W * H), std::vector<float>(W * H, -std::numeric_limits<float>::infinity())};
    for (std::size_t i = 0; i < W * H; ++i)
        for (int c = 0; c < 3; ++c) fr.rgb[3 * i + c] = opt.background[c];
    const bool colored = mesh.colors.size() == nv;

    for (const auto& t : mesh.triangles) rasterize_triangle(mesh, opt, screen, normal, cam.light, colored, t, fr);

    return downsample(fr.rgb, W, ss, opt);
}

void write_png(const Image& image, const std::string& path) {
    if (image.rgb.size() != 3 * image.width * image.height || image.width == 0)
        throw std::logic_error("write_png: image size and pixel buffer disagree");
    const std::string tmp = temporary_path(path);
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = png_uint_32(image.width);
    png.height = png_uint_32(image.height);
    png.format = PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&png, tmp.c_str(), 0, image.rgb.data(), 0, nullptr))
        discard_temporary(tmp, path, std::string("cannot write PNG: ") + png.message);
    rename_into_place(tmp, path);
}

Image read_png(const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.c_str())) throw InputError(path + ": cannot read PNG: " + png.message);
    png.format = PNG_FORMAT_RGB;
    Image image;
    image.width = png.width;
    image.height = png.height;
    image.rgb.resize(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr)) {
        const std::string message = png.message;
        png_image_free(&png);
        throw InputError(path + ": cannot read PNG: " + message);
    }
    return image;
}

}  // namespace clfractal
