// Shared pieces of the command-line tool (see cli.hpp).
#include "cli.hpp"

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "clfractal/error.hpp"
#include "clfractal/volume.hpp"

using namespace clfractal;

namespace cli {

bool quiet = false;
void progress(const std::string& s) {
    if (!quiet) std::cerr << "clfractal: " << s << "\n";
}

CLI::Option* add_window_option(CLI::App* app, int& window, const std::string& what) {
    return app
        ->add_option("--window", window, what + " (even, >= 2)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                const int k = std::atoi(text.c_str());
                if (k < 2 || k % 2) return "the window must be even and at least 2, not " + text;
                return {};
            },
            "EVEN>=2"))
        ->capture_default_str();
}

CLI::Option* add_iso_option(CLI::App* app, double& iso, const std::string& what) {
    return app->add_option("--iso", iso, what)->check(CLI::Validator(
        [](std::string& text) -> std::string {
            char* end = nullptr;
            const double s = std::strtod(text.c_str(), &end);
            if (end == text.c_str() || *end || !std::isfinite(s)) return "must be a finite number, not " + text;
            return {};
        },
        "S"));
}

void warn_isovalue_outside(const Volume& v, double iso) {
    const ValueRange r = value_range(v);
    if (iso > r.min && iso <= r.max) return;
    std::ostringstream msg;
    msg << "clfractal: warning: isovalue " << iso << " is outside (" << r.min << ", " << r.max << "], the values of "
        << v.name << ": no cube is intersected";
    if (!quiet) std::cerr << msg.str() << "\n";
}

void RawArgs::add(CLI::App* app) {
    app->add_option("--dims", dims, "raw file dimensions X,Y,Z");
    app->add_option("--type", type, "raw file value type: uint8|uint16|int16|float32");
    app->add_option("--endian", endian, "raw file byte order")->check(CLI::IsMember({"little", "big"}));
    app->add_option("--series", series, "DICOM: the series (SeriesInstanceUID) of a directory to read");
    app->add_flag("--scaled", scaled, "NIfTI: apply scl_slope/scl_inter to the stored values");
}

RawOptions RawArgs::options() const {
    RawOptions o;
    if (!dims.empty()) {
        Dims d;
        char c1 = 0, c2 = 0;
        std::istringstream in(dims);
        long long x = 0, y = 0, z = 0;
        if (!(in >> x >> c1 >> y >> c2 >> z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || x < 1 || y < 1 ||
            z < 1)
            throw InputError("--dims '" + dims + "': expected three positive integers X,Y,Z");
        d = Dims{std::size_t(x), std::size_t(y), std::size_t(z)};
        check_dims(d, "--dims " + dims);
        o.dims = d;
    }
    if (!type.empty()) o.type = parse_value_type(type);
    o.big_endian = endian == "big";
    o.series = series;
    o.scaled = scaled;
    return o;
}

// An isovalue written so that it reads back to the same float32 / integer.
std::string iso_string(const IsovalueSet& iso, std::size_t j) {
    char buf[64];
    if (iso.integer())
        std::snprintf(buf, sizeof buf, "%lld", (long long)(iso.first() + std::int64_t(j)));
    else
        std::snprintf(buf, sizeof buf, "%.9g", double(iso.float_values()[j]));
    return buf;
}

std::string fd_string(double d) {
    if (std::isnan(d)) return "";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", d);
    return buf;
}

nlohmann::json fd_json(double d) { return std::isnan(d) ? nlohmann::json(nullptr) : nlohmann::json(d); }

std::string fd_csv(const FdCurve& f, const std::vector<std::int64_t>* components) {
    const int levels = f.levels();
    std::ostringstream out;
    out << "isovalue,count,count_sub,fd";
    for (int l = 2; l < levels; ++l) out << ",count_l" << l;
    if (levels > 2) out << ",fd_fit";
    if (components) out << ",components";
    out << "\n";
    for (std::size_t j = 0; j < f.fd.size(); ++j) {
        out << iso_string(f.isovalues, j) << "," << f.counts[0][j] << "," << f.counts[1][j] << "," << fd_string(f.fd[j]);
        for (int l = 2; l < levels; ++l) out << "," << f.counts[l][j];
        if (levels > 2) out << "," << fd_string(f.fd_fit[j]);
        if (components) out << "," << (*components)[j];
        out << "\n";
    }
    return out.str();
}

}  // namespace cli
