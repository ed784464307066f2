#include "output.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "clfractal/error.hpp"
#include "io/output_file.hpp"

namespace fs = std::filesystem;
using namespace clfractal;

void write_file_atomic(const std::string& path, const std::string& content) {
    const std::string tmp = temporary_path(path);
    {
        std::ofstream out(tmp, std::ios::binary);
        out << content;
        out.flush();
        if (!out) discard_temporary(tmp, path, "cannot write (directory missing or not writable?)");
    }
    rename_into_place(tmp, path);
}

namespace {

void require_gnuplot(const std::string& path) {
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
        throw InputError(path + ": --plot needs gnuplot (Debian: apt-get install gnuplot-nox); CSV/JSON work without it");
}

// Runs gnuplot on `script` (which plots the datablock $DATA, filled with `data`) with its
// output set to the regular file `png`; true when gnuplot succeeded and wrote something.
// The script goes to gnuplot's stdin (no path ever reaches a shell); inside a gnuplot
// single-quoted string a quote is written twice. gnuplot's own stdout is discarded: it
// would get the image if the output could not be opened.
bool run_gnuplot(const std::string& script, const std::string& data, const std::string& png) {
    std::string quoted;
    for (char c : png) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    const std::string text = "$DATA << EOD\n" + data + "EOD\nset output '" + quoted + "'\n" + script;
    FILE* p = popen("gnuplot >/dev/null", "w");
    int status = -1;
    if (p) {
        fwrite(text.data(), 1, text.size(), p);
        status = pclose(p);
    }
    std::error_code ec;
    return status == 0 && fs::is_regular_file(png, ec) && fs::file_size(png, ec) > 0;
}

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

}  // namespace

std::string gnuplot_string(const std::string& text) {
    std::string quoted = "'";
    for (char c : printable(text)) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    return quoted + "'";
}

void plot_png(const std::string& script, const std::string& data, const std::string& path) {
    require_gnuplot(path);
    // gnuplot writes a regular file: the temporary beside the target, or for a FIFO, a
    // device or stdout, one in the system's temporary folder that is then copied there.
    const OutputTarget target = check_output(path);
    const std::string tmp_png =
        target.direct ? (fs::temp_directory_path() / ("clfractal-plot-" + std::to_string(::getpid()) + ".png")).string()
                      : temporary_path(path);
    std::error_code ec;
    if (!run_gnuplot(script, data, tmp_png)) {
        if (target.direct) fs::remove(tmp_png, ec);
        else discard_temporary(tmp_png, path, "gnuplot failed (see its message above)");
        throw InputError(path + ": gnuplot failed (see its message above)");
    }
    if (!target.direct) return rename_into_place(tmp_png, path);
    const std::string bytes = read_bytes(tmp_png);
    fs::remove(tmp_png, ec);
    write_file_atomic(path, bytes);
}

std::string plot_png_bytes(const std::string& script, const std::string& data, const std::string& what) {
    require_gnuplot(what);
    static std::atomic<int> serial{0};  // figures may be drawn on several threads at once
    const std::string tmp_png = (fs::temp_directory_path() / ("clfractal-plot-" + std::to_string(::getpid()) + "-" +
                                                              std::to_string(serial++) + ".png"))
                                    .string();
    const bool ok = run_gnuplot(script, data, tmp_png);
    const std::string bytes = ok ? read_bytes(tmp_png) : std::string();
    std::error_code ec;
    fs::remove(tmp_png, ec);
    if (!ok) throw InputError(what + ": gnuplot failed (see its message above)");
    return bytes;
}

const std::vector<std::string>& output_option_names() {
    static const std::vector<std::string> names{"--output", "--csv",     "--json",     "--plot",
                                                "--mesh",   "--preview", "--markdown", "--histogram"};
    return names;
}

bool check_output_options(const CLI::App& command) {
    std::set<std::string> files;
    bool to_stdout = false;
    for (const CLI::Option* o : command.get_options()) {
        bool output = false;
        for (const std::string& name : o->get_lnames())
            for (const std::string& n : output_option_names()) output |= "--" + name == n;
        if (!output) continue;
        for (const std::string& path : o->results()) {
            const OutputTarget t = check_output(path);
            if (path == "-") {
                if (to_stdout) throw InputError("-: only one output can go to standard output");
                to_stdout = true;
            } else if (!t.direct && !files.insert(t.file).second) {
                throw InputError(path + ": named as two outputs of the same run");
            }
        }
    }
    return to_stdout;
}
