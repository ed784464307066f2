// clfractal smooth: smooth isosurface construction (thesis chapter 5, Algorithm 2).
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>

#include "clfractal/components.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/ply.hpp"
#include "clfractal/render.hpp"
#include "clfractal/smooth.hpp"
#include "cli.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct SmoothArgs {
    std::string volume, output, mesh, preview, variant = "plain";
    double iso = 0, threshold = 0, tau = 1;
    int window = 8;
    RawArgs raw;
};

int run_smooth(SmoothArgs a) {
    const SmoothVariant variant = parse_smooth_variant(a.variant);
    if (!std::isfinite(a.threshold)) throw InputError("--threshold: must be a finite number");
    Volume v = read_volume_at_isovalue(a.volume, a.raw, a.iso, {"clfractal smooth"});
    Context& ctx = Context::shared();
    progress("smooth isosurface of " + dims_string(v.dims()) + " " + value_type_name(v.type()) + " (" +
             smooth_variant_name(variant) + "), window " + std::to_string(a.window) + ", on " + ctx.description());
    const bool want_mesh = !a.mesh.empty() || !a.preview.empty();
    // The input on the device once (its counts and the smoothing read it), the result once (its
    // counts). The input's counts come first and its values go once the result is written, so
    // that the component labelling never shares memory with both volumes.
    IsoCounts before;
    std::int64_t components_before = 0;
    SmoothResult r;
    {
        const ReportVolume input(ctx, v);
        before = input.counts_at(a.iso);
        components_before = input.components_at(a.iso);
        r = input.device() ? smooth_isosurface(*input.device(), a.iso, a.threshold, a.window, variant, a.tau, want_mesh)
                           : smooth_isosurface(ctx, v, a.iso, a.threshold, a.window, variant, a.tau, want_mesh);
    }
    write_volume(r.volume, a.output, &v);
    const Dims dims = v.dims();
    const ValueType type = v.type();
    v = Volume();
    const ReportVolume output(ctx, r.volume);
    const IsoCounts after = output.counts_at(a.iso);

    const double n = double(std::max<std::size_t>(1, dims.vertices()));
    std::cout << "volume      " << a.volume << "  " << dims_string(dims) << " " << value_type_name(type) << "\n"
              << "device      " << ctx.description() << "\n"
              << "isovalue    " << a.iso << compared_as(type) << ", threshold "
              << a.threshold << ", window " << a.window << ", variant " << smooth_variant_name(variant);
    if (variant == SmoothVariant::gaussian) std::cout << " (tau " << a.tau << ")";
    std::cout << "\n"
              << "LD > h      " << r.high_vertices << " vertices\n"
              << "edges       " << r.initial_edges << " high fractal at the start, " << r.edges_processed
              << " processed, " << r.edges_lowered << " lowered\n"
              << "vertices    " << r.vertices_changed << " changed (" << std::fixed << std::setprecision(3)
              << 100.0 * double(r.vertices_changed) / n << "%)\n"
              << std::defaultfloat << "cubes       " << before.cubes << " -> " << after.cubes << " intersected\n"
              << "grid edges  " << before.edges << " -> " << after.edges << " intersected\n";
    std::cout << "components  " << components_before << " -> " << output.components_at(a.iso)
              << " (cube connectivity: 6 below, 26 above)\n";
    std::cout << std::setprecision(4) << "time        " << r.device_seconds << " s device (LD field, edge scan), "
              << r.queue_seconds << " s queue, kernels compiled in " << ctx.compile_seconds() << " s\n"
              << "wrote       " << a.output << "\n";
    if (want_mesh) {
        // The isosurface of the smoothed volume, coloured by the LD field of the input.
        Mesh mesh = extract_isosurface(r.volume, a.iso);
        color_by_ld(mesh, r.ld);
        if (!a.mesh.empty()) {
            write_ply(mesh, a.mesh);
            std::cout << "wrote       " << a.mesh << " (" << mesh.positions.size() << " vertices, "
                      << mesh.triangles.size() << " triangles, coloured by the input's LD)\n";
        }
        if (!a.preview.empty()) {
            write_png(render_mesh(mesh), a.preview);
            std::cout << "wrote       " << a.preview << "\n";
        }
    }
    return 0;
}

void setup_smooth(CLI::App* c, SmoothArgs& a) {
    add_volume_and_iso(c, a.volume, a.iso, "isovalue S (edges with a < S <= b are intersected)");
    c->add_option("--threshold", a.threshold, "h: an intersected edge is high fractal when LD > h at an end")
        ->required();
    add_window_option(c, a.window);
    c->add_option("--variant", a.variant, "plain (f(v) := f(u)) or gaussian (neighbours lowered too)")
        ->check(CLI::IsMember({"plain", "gaussian"}));
    c->add_option("--tau", a.tau, "width of the gaussian variant's lowering, in grid steps");
    add_output_option(c, a.output, "output .nrrd, .nii or .nii.gz (same type as the input)");
    add_mesh_option(c, a.mesh, "also write the smoothed isosurface as PLY, coloured by the input's LD");
    add_preview_option(c, a.preview, "render the smoothed isosurface to a PNG");
    a.raw.add(c);
}

}  // namespace

Command smooth_command() {
    return command<SmoothArgs>("smooth", "move the isosurface out of high-fractal regions (thesis Algorithm 2)",
                               setup_smooth, run_smooth);
}

}  // namespace cli
