// clfractal: the command-line tool (docs/definitions.md §30). Exit 0 on success, 2 on bad input
// or arguments (one line "clfractal: error: ..."), 1 on a runtime failure. main() only
// dispatches: each subcommand lives in its own cmd_*.cpp and registers through cli::command.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/error.hpp"
#include "clfractal/version.hpp"
#include "io/output_file.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace {

struct Chosen {
    CLI::App* app;
    std::function<int()> run;
    bool uses_device;
};

// Every subcommand, in the order of --help.
std::vector<cli::Command> all_commands() {
    using namespace cli;
    return {devices_command(), info_command(),  fd_command(),     local_command(),      gen_command(),
            mesh_command(),    bench_command(), smooth_command(), noise_command(),      filter_command(),
            components_command(), survey_command(), fd4_command(), local4_command(), report_command()};
}

// Options shared by every subcommand: -q anywhere (the subcommands pass what they do not
// know to the app), and every default shown in --help.
void add_shared_options(CLI::App& app) {
    app.require_subcommand(1);
    app.fallthrough();
    app.option_defaults()->always_capture_default();
    app.add_flag("-q,--quiet", cli::quiet, "no progress on stderr (before or after the subcommand)");
    app.set_version_flag("--version", std::string("clfractal ") + clfractal::version());
}

// A default is shown where it is a value the option takes: not for required options, nor
// where "not given" means something the help line says (NaN, 0 for "automatic").
void hide_unhelpful_defaults(CLI::App& command) {
    for (CLI::Option* o : command.get_options()) {
        const std::string d = o->get_default_str();
        if (o->get_required() || d == "nan" || d == "-nan" || d == "\"\"") o->default_str("");
    }
}

// Parse errors as one line, exit 2; --help and --version as CLI11 prints them.
int parse(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::string msg = e.what();
        std::replace(msg.begin(), msg.end(), '\n', ' ');
        std::cerr << "clfractal: error: " << msg << " (see clfractal --help)\n";
        return 2;
    }
    return -1;
}

// Runs the chosen subcommand; errors as one line: 2 for bad input, 1 for a runtime failure.
int run(const CLI::App& app, const Chosen& chosen) {
    try {
        // Every output path is checked before any work; with one of them "-" (stdout), the
        // report moves to stderr. The outputs appear together when the command succeeds.
        for (const CLI::App* sub : app.get_subcommands())
            if (check_output_options(*sub)) std::cout.rdbuf(std::cerr.rdbuf());
        OutputRun outputs;
        const int rc = chosen.run();
        if (rc == 0) outputs.commit();
        // CLFRACTAL_UPLOADS set: how many volumes went to the device (tests check that a
        // command uploads its input once).
        if (std::getenv("CLFRACTAL_UPLOADS"))
            std::cerr << "clfractal: uploads " << Context::shared().uploads() << "\n";
        return rc;
    } catch (const InputError& e) {
        std::cerr << "clfractal: error: " << printable(e.what()) << "\n";
        return 2;
    } catch (const DeviceError& e) {
        std::cerr << "clfractal: error: " << (e.out_of_memory() ? "the device is out of memory: " : "") << e.what()
                  << "\n";
        return e.out_of_memory() ? 2 : 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "clfractal: error: out of host memory\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "clfractal: error: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"clfractal: isosurface fractal dimension of 3D scalar grids, for every isovalue at once"};
    add_shared_options(app);
    std::vector<Chosen> commands;
    for (const cli::Command& c : all_commands()) {
        CLI::App* sub = app.add_subcommand(c.name, c.help);
        commands.push_back({sub, c.attach(*sub), c.uses_device});
        hide_unhelpful_defaults(*sub);
    }
    const int parsed = parse(app, argc, argv);
    if (parsed >= 0) return parsed;
    for (const Chosen& c : commands)
        if (app.got_subcommand(c.app)) {
            // The commands that use the device begin creating it while they read their input.
            if (c.uses_device) cli::start_device_for(*c.app);
            const int status = run(app, c);
            Context::wait_shared();  // a command that failed before it needed the device
            release_blas_caches();  // before the OpenCL runtime's exit handlers
            return status;
        }
    return 0;
}
