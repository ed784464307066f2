// Shared pieces of the command-line tool (see cli.hpp).
#include "cli.hpp"

#include <cmath>
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

void RawArgs::add(CLI::App* app) {
    app->add_option("--dims", dims, "raw file dimensions X,Y,Z");
    app->add_option("--type", type, "raw file value type: " + value_type_names());
    app->add_option("--endian", endian, "raw file byte order")->check(CLI::IsMember({"little", "big"}));
    app->add_option("--as", as, "convert the values to this type on read, from any format (" + value_type_names() +
                                    "); may round (float64 -> float32 keeps 24 bits) and saturates to the type's range");
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
    if (!as.empty()) o.as = parse_value_type(as);
    return o;
}

std::string iso_string(const IsovalueSet& iso, std::size_t j) { return iso.text(j); }

std::string compared_as(ValueType t) {
    return is_integer(t) ? "" : std::string(" (compared as ") + value_type_name(t) + ")";
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
