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

void print_bands(std::ostream& out, const FdCurve& f, const std::vector<CleanBand>& bands, double max_fd,
                 double min_share) {
    const IsovalueSet& iso = f.isovalues;
    std::ostringstream head;
    head << "D <= " << max_fd << ", surface >= " << 100 * min_share << "% of the largest";
    if (bands.empty()) {
        out << "clean bands none (" << head.str() << "); every well-populated isovalue is rough\n";
        return;
    }
    out << "clean bands " << bands.size() << " (" << head.str() << "; about 2 is a clean surface, towards 3 noise)\n";
    for (std::size_t i = 0; i < bands.size() && i < 5; ++i) {
        const CleanBand& b = bands[i];
        out << "  " << (i == 0 ? "best " : "     ") << iso_string(iso, b.first) << " .. " << iso_string(iso, b.last)
            << "  (" << b.width() << " isovalue" << (b.width() > 1 ? "s" : "") << ", mean D " << b.mean_fd
            << ", up to " << b.max_count << " cubes)  use " << iso_string(iso, b.representative) << "\n";
    }
}

nlohmann::json bands_json(const FdCurve& f, const std::vector<CleanBand>& bands) {
    nlohmann::json a = nlohmann::json::array();
    for (const CleanBand& b : bands)
        a.push_back({{"first", f.isovalues.value(b.first)},
                     {"last", f.isovalues.value(b.last)},
                     {"isovalue", f.isovalues.value(b.representative)},
                     {"width", b.width()},
                     {"mean_fd", b.mean_fd},
                     {"max_fd", b.max_fd},
                     {"max_count", b.max_count}});
    return a;
}

void print_noise(std::ostream& out, const NoiseEstimate& e) {
    if (e.used == 0) {
        out << "noise       n/a: no well-populated isovalue has an edge dimension in [" << noise_fd_min << ", "
            << noise_fd_max << "] (below: too clean to measure; above: noise dominates)\n";
        return;
    }
    out << "noise       +-" << e.median_amplitude << " grey values uniform (std " << e.median_amplitude / std::sqrt(3.0)
        << "), r = noise / gradient " << e.median_ratio << "; median over " << e.used
        << " isovalues (Theorem 1 inverted)\n";
}

nlohmann::json noise_json(const NoiseEstimate& e) {
    nlohmann::json per = nlohmann::json::array();
    for (std::size_t j = 0; j < e.isovalues.size(); ++j) {
        if (std::isnan(e.ratio[j])) continue;
        per.push_back({{"isovalue", e.isovalues.value(j)},
                       {"edge_fd", e.edge_fd[j]},
                       {"ratio", e.ratio[j]},
                       {"gamma", e.gamma[j]},
                       {"amplitude", e.amplitude[j]}});
    }
    return {{"amplitude", fd_json(e.median_amplitude)},
            {"ratio", fd_json(e.median_ratio)},
            {"isovalues_used", e.used},
            {"trusted_edge_fd", {noise_fd_min, noise_fd_max}},
            {"per_isovalue", per}};
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
    return app->add_option("--iso", iso, what + " (or auto: the best clean band's)")
        ->transform(CLI::Validator(
            [](std::string& text) -> std::string {
                if (text == "auto") {
                    char buf[32];
                    std::snprintf(buf, sizeof buf, "%.17g", auto_isovalue);
                    text = buf;
                    return {};
                }
                char* end = nullptr;
                const double s = std::strtod(text.c_str(), &end);
                if (end == text.c_str() || *end || !std::isfinite(s)) return "must be a finite number or auto, not " + text;
                return {};
            },
            "S|auto"));
}

double checked_isovalue(const Volume& v, double iso) {
    if (!is_auto_isovalue(iso)) {
        warn_isovalue_outside(v, iso);
        return iso;
    }
    Context& ctx = Context::shared();
    const IsovalueSet set = IsovalueSet::for_volume(v);
    const FdCurve f = fd_curve(ctx, count_spans(ctx, v, set), SpanKind::cubes);
    const std::vector<CleanBand> bands = clean_bands(f);
    if (bands.empty())
        throw InputError("--iso auto: " + v.name + " has no clean band (D <= 2.2 on >= 1% of the largest surface); give --iso S");
    const CleanBand& b = bands.front();
    const double s = set.value(b.representative);
    progress("--iso auto: isovalue " + iso_string(set, b.representative) + ", the middle of the clean band " +
             iso_string(set, b.first) + " .. " + iso_string(set, b.last) + " (mean D " + std::to_string(b.mean_fd) + ")");
    return s;
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
    app->add_option("--type", type, "raw file value type: " + value_type_names());
    app->add_option("--endian", endian, "raw file byte order")->check(CLI::IsMember({"little", "big"}));
    app->add_option("--series", series, "DICOM: the series (SeriesInstanceUID) of a directory to read");
    app->add_flag("--scaled", scaled, "NIfTI: apply scl_slope/scl_inter to the stored values");
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
    o.series = series;
    o.scaled = scaled;
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
