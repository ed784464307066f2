// clfractal local: the local fractal dimension field (eq. 2.6) of one isovalue, as NRRD or
// NIfTI, optionally with the isosurface coloured by it.
#include <chrono>
#include <iomanip>
#include <iostream>

#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/ply.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct LocalArgs {
    std::string volume, output, mesh;
    double iso = 0;
    int window = 8;
    bool stream = false;
    RawArgs raw;
};

int cmd_local(LocalArgs a) {
    if (a.stream) {
        if (!a.mesh.empty()) throw InputError("--mesh: not with --stream (the mesh needs the whole volume)");
        if (is_auto_isovalue(a.iso)) throw InputError("--iso auto: not with --stream (it needs the whole curve first)");
        return cmd_local_stream(a.volume, a.raw.options(), a.iso, a.window, a.output);
    }
    Volume v = read_volume_at_isovalue(a.volume, a.raw, a.iso, {"clfractal local", 4.0, "clfractal local --stream works within 512 MiB"});
    Context& ctx = Context::shared();
    progress("local fractal dimension of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + ", window " +
             std::to_string(a.window) + ", on " + ctx.description());
    const auto t0 = std::chrono::steady_clock::now();
    Volume ld = local_fractal_dimension(ctx, v, a.iso, a.window);
    const double seconds = seconds_since(t0);
    write_volume(ld, a.output, &v);
    const LocalSummary s = summarize_local(ld);

    std::cout << "volume      " << a.volume << "  " << dims_string(v.dims()) << " " << value_type_name(v.type()) << "\n"
              << "device      " << ctx.description() << "\n"
              << "isovalue    " << a.iso << compared_as(v.type()) << ", window "
              << a.window << "\n"
              << std::fixed << std::setprecision(2) << "defined     " << s.defined << " of " << s.vertices
              << " vertices (" << 100.0 * double(s.defined) / double(s.vertices) << "%, near the surface)\n";
    if (s.defined)
        std::cout << "LD > 2.2    " << 100 * s.above_blue << "% of them (colour map: blue up to 2.2)\n"
                  << "LD > 2.5    " << 100 * s.above_red << "% of them (red from 2.5)\n"
                  << std::setprecision(4) << "mean LD     " << s.mean << "\n";
    else
        std::cout << "mean LD     n/a (the isovalue intersects no window)\n";
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << seconds << " s, kernels compiled in "
              << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << " (float32, NaN where LD is undefined)\n";
    if (!a.mesh.empty()) {
        // The marching-cubes isosurface at the same isovalue, coloured by this LD field.
        Mesh mesh = extract_isosurface(v, a.iso);
        color_by_ld(mesh, ld);
        write_ply(mesh, a.mesh);
        std::cout << "wrote       " << a.mesh << " (" << mesh.positions.size() << " vertices, " << mesh.triangles.size()
                  << " triangles, coloured by LD)\n";
    }
    return 0;
}

void setup_local(CLI::App* c, LocalArgs& a) {
    add_volume_and_iso(c, a.volume, a.iso, "isovalue S (cubes with a < S <= b are intersected)");
    add_window_option(c, a.window, "window k");
    add_output_option(c, a.output, "output .nrrd, .nii or .nii.gz (float32)");
    add_mesh_option(c, a.mesh, "also write the isosurface as PLY, coloured by LD");
    c->add_flag("--stream", a.stream, "read and write slice by slice (memory: a few slices; same field)");
    a.raw.add(c);
}

}  // namespace

Command local_command() {
    return command<LocalArgs>("local", "local fractal dimension field (eq. 2.6) for one isovalue, as NRRD", setup_local,
                              cmd_local);
}

}  // namespace cli
