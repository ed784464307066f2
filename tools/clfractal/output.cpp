#include "output.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "clfractal/error.hpp"

namespace fs = std::filesystem;
using clfractal::InputError;

namespace {

std::string temp_name(const std::string& path) { return path + ".tmp-" + std::to_string(getpid()); }

void rename_into_place(const std::string& tmp, const std::string& path) {
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw InputError(path + ": cannot write: " + ec.message());
    }
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& content) {
    const std::string tmp = temp_name(path);
    {
        std::ofstream out(tmp, std::ios::binary);
        out << content;
        out.flush();
        if (!out) {
            std::error_code ec;
            fs::remove(tmp, ec);
            throw InputError(path + ": cannot write (directory missing or not writable?)");
        }
    }
    rename_into_place(tmp, path);
}

void plot_png(const std::string& script, const std::string& data, const std::string& path) {
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
        throw InputError(path + ": --plot needs gnuplot (Debian: apt-get install gnuplot-nox); CSV/JSON work without it");
    const std::string tmp_png = temp_name(path) + ".png", tmp_gp = temp_name(path) + ".gp";
    write_file_atomic(tmp_gp, "$DATA << EOD\n" + data + "EOD\nset output '" + tmp_png + "'\n" + script);
    const std::string cmd = "gnuplot '" + tmp_gp + "' 2>&1";
    std::string log;
    FILE* p = popen(cmd.c_str(), "r");
    int status = -1;
    if (p) {
        char buf[256];
        while (fgets(buf, sizeof buf, p)) log += buf;
        status = pclose(p);
    }
    std::error_code ec;
    fs::remove(tmp_gp, ec);
    if (status != 0 || !fs::exists(tmp_png)) {
        fs::remove(tmp_png, ec);
        for (char& c : log)
            if (c == '\n') c = ' ';
        throw InputError(path + ": gnuplot failed: " + log);
    }
    rename_into_place(tmp_png, path);
}
