// clfractal gen: a synthetic volume written as NRRD or NIfTI.
#include "clfractal/synthetic.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct GenArgs {
    std::string name, type, output;
    SyntheticOptions opt;
};

int cmd_gen(const std::string& name, const SyntheticOptions& o, const std::string& type, const std::string& out) {
    SyntheticOptions opt = o;
    if (!type.empty()) opt.type = parse_value_type(type);
    if (opt.size < 2 || opt.size > 2048) throw InputError("--size " + std::to_string(opt.size) + ": must be 2..2048");
    Volume v = make_synthetic(name, opt);
    write_volume(v, out);
    progress("wrote " + out + " (" + dims_string(v.dims()) + " " + value_type_name(v.type()) + ")");
    return 0;
}

void setup_gen(CLI::App* c, GenArgs& a) {
    std::string names;
    for (auto& s : synthetic_catalog()) names += (names.empty() ? "" : ", ") + s.name;
    c->add_option("NAME", a.name, "one of: " + names)->required();
    c->add_option("--size", a.opt.size, "N: the volume is N^3");
    c->add_option("--noise", a.opt.noise, "uniform noise amplitude mu");
    c->add_option("--seed", a.opt.seed, "noise / point seed");
    c->add_option("--points", a.opt.points, "number of points for 'points'");
    c->add_option("--type", a.type, "convert to " + value_type_names() + " (default: the shape's own type)");
    add_output_option(c, a.output, "output .nrrd, .nii or .nii.gz");
}

}  // namespace

Command gen_command() {
    return without_device(
        command<GenArgs>("gen", "write a synthetic volume (NRRD, or NIfTI for .nii/.nii.gz)", setup_gen,
                         [](const GenArgs& a) { return cmd_gen(a.name, a.opt, a.type, a.output); }));
}

}  // namespace cli
