// clfractal mesh: the isosurface as PLY (marching cubes or tetrahedra), optionally coloured
// by the local fractal dimension, with a preview PNG.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/ply.hpp"
#include "clfractal/render.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct MeshArgs {
    std::string volume, output, method = "mc", preview;
    double iso = 0;
    bool color_by_ld = false;
    int window = 8;
    RawArgs raw;
};

int cmd_mesh(MeshArgs a) {
    const MeshMethod method = parse_mesh_method(a.method);
    Volume v = read_volume_at_isovalue(a.volume, a.raw, a.iso, {"clfractal mesh"});
    using clock = std::chrono::steady_clock;

    auto t = clock::now();
    Mesh mesh = extract_isosurface(v, a.iso, method);
    const double extract_seconds = seconds_since(t);
    std::ostringstream times;
    times << std::setprecision(3) << "extraction " << extract_seconds << " s";
    if (a.color_by_ld) {
        Context& ctx = Context::shared();
        progress("local fractal dimension, window " + std::to_string(a.window) + ", on " + ctx.description());
        t = clock::now();
        color_by_ld(mesh, local_fractal_dimension(ctx, v, a.iso, a.window));
        times << ", LD field " << seconds_since(t) << " s";
    }
    t = clock::now();
    write_ply(mesh, a.output);
    times << ", PLY " << seconds_since(t) << " s";
    if (!a.preview.empty()) {
        t = clock::now();
        write_png(render_mesh(mesh), a.preview);
        times << ", preview " << seconds_since(t) << " s";
    }

    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n"
              << "isovalue    " << a.iso << "  ("
              << (method == MeshMethod::marching_cubes ? "marching cubes, negative vertices separated"
                                                       : "marching tetrahedra, Freudenthal triangulation")
              << ")\n"
              << "mesh        " << mesh.positions.size() << " vertices (one per intersected edge), "
              << mesh.triangles.size() << " triangles\n";
    if (mesh.triangles.empty()) {
        const ValueRange r = value_range(v);
        std::cout << "            no surface: the isovalue does not cross the values " << r.min << " .. " << r.max << "\n";
    }
    if (a.color_by_ld) {
        std::size_t red = 0, blue = 0, undefined = 0;
        for (float ld : mesh.ld) {
            red += ld >= ld_red;
            blue += ld <= ld_blue;
            undefined += std::isnan(ld);
        }
        const double n = std::max<double>(1, double(mesh.ld.size()));
        std::cout << std::fixed << std::setprecision(1) << "colour      LD window " << a.window << ": " << 100 * red / n
                  << "% red (LD >= " << ld_red << "), " << 100 * blue / n << "% blue (LD <= " << ld_blue << "), "
                  << 100 * undefined / n << "% grey (undefined)\n"
                  << std::defaultfloat;
    }
    std::cout << "time        " << times.str() << "\n";
    return 0;
}

void setup_mesh(CLI::App* c, MeshArgs& a) {
    add_volume_and_iso(c, a.volume, a.iso, "isovalue S (positive vertices: f >= S)");
    add_output_option(c, a.output, "output .ply (binary)");
    c->add_option("--method", a.method, "mc: marching cubes, mt: marching tetrahedra")
        ->check(CLI::IsMember({"mc", "mt"}));
    auto* color_flag = c->add_flag("--color-by-ld", a.color_by_ld, "colour vertices by local fractal dimension");
    add_window_option(c, a.window)->needs(color_flag);
    add_preview_option(c, a.preview, "render the mesh to a PNG (three-quarter view)");
    a.raw.add(c);
}

}  // namespace

Command mesh_command() {
    return command<MeshArgs>("mesh", "isosurface mesh as PLY (marching cubes or tetrahedra), optional preview PNG",
                             setup_mesh, cmd_mesh);
}

}  // namespace cli
