#include "output.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "clfractal/error.hpp"
#include "clfractal/output_file.hpp"

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

void plot_png(const std::string& script, const std::string& data, const std::string& path) {
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
        throw InputError(path + ": --plot needs gnuplot (Debian: apt-get install gnuplot-nox); CSV/JSON work without it");
    const std::string tmp_png = temporary_path(path) + ".png";
    // The script goes to gnuplot's stdin (no path ever reaches a shell); inside a gnuplot
    // single-quoted string a quote is written twice.
    std::string quoted;
    for (char c : tmp_png) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    const std::string text = "$DATA << EOD\n" + data + "EOD\nset output '" + quoted + "'\n" + script;
    FILE* p = popen("gnuplot", "w");
    int status = -1;
    if (p) {
        fwrite(text.data(), 1, text.size(), p);
        status = pclose(p);
    }
    std::error_code ec;
    if (status != 0 || !fs::exists(tmp_png)) {
        fs::remove(tmp_png, ec);
        throw InputError(path + ": gnuplot failed (see its message above)");
    }
    rename_into_place(tmp_png, path);
}
