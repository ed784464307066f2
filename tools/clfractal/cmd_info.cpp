// clfractal info: format, dimensions, type, spacing, value range, NaN count and histogram of
// a volume.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

struct InfoArgs {
    std::string volume;
    RawArgs raw;
};

int cmd_info(const std::string& spec, const RawArgs& raw) {
    // The format first: a directory of several DICOM series is listed even when none is chosen.
    std::cout << "volume    " << spec << "\n";
    for (const std::string& line : describe_volume_file(spec, raw.options())) std::cout << line << "\n";
    std::cout.flush();
    // NaN and Inf are reported, not refused: an LD field is float data with NaN where LD is
    // undefined. Range, mean and histogram are those of the finite values.
    Volume v = read_volume(spec, raw.options(), FiniteCheck::keep);
    // Range, NaN counts, mean and histogram in one pass for 8/16-bit data (two otherwise).
    const ValueSummary summary = summarize_values(v, 16);
    const NonFinite nf{summary.stats.nan, summary.stats.inf, 0};
    const std::size_t finite = summary.finite;
    const double lo = summary.stats.min, hi = summary.stats.max, mean = summary.mean, sd = summary.sd;
    const double n = double(finite);
    std::cout << "dims      " << dims_string(v.dims()) << " (" << v.vertices() << " vertices, " << v.dims().cubes()
              << " cubes)\n"
              << "type      " << value_type_name(v.type()) << "\n"
              << "spacing   " << v.spacing[0] << " " << v.spacing[1] << " " << v.spacing[2] << "\n";
    if (nf.nan + nf.inf)
        std::cout << "NaN       " << nf.nan << " (" << std::fixed << std::setprecision(2) << 100.0 * double(nf.nan) / double(v.vertices())
                  << "% of the vertices)" << std::defaultfloat << std::setprecision(6) << "\n"
                  << "infinite  " << nf.inf << "\n";
    if (finite == 0) {
        std::cout << "range     n/a (no finite value)\n";
        return 0;
    }
    std::cout << "range     " << lo << " .. " << hi << (nf.nan + nf.inf ? " (finite values)" : "") << "\n"
              << "mean      " << mean << "  (std " << sd << ")\n";
    // A 16-bin histogram of the value range, as shares of the finite values.
    const int bins = 16;
    const std::vector<std::size_t>& h = summary.histogram;
    const double w = (hi - lo) / bins;
    std::cout << "histogram (16 bins over the range, % of " << (nf.nan + nf.inf ? "the finite values" : "vertices")
              << "):\n";
    for (int b = 0; b < bins; ++b) {
        double share = 100.0 * double(h[b]) / n;
        std::cout << "  " << std::setw(12) << lo + b * w << "  " << std::setw(6) << std::fixed
                  << std::setprecision(2) << share << std::defaultfloat << std::setprecision(6) << "  "
                  << std::string(std::size_t(std::ceil(share / 2)), '#') << "\n";
    }
    if (nf.nan + nf.inf) {
        std::cout << "isovalues n/a (fd, local, filter, mesh and components need finite values)\n";
        return 0;
    }
    IsovalueSet iso = IsovalueSet::for_range(v.type(), lo, hi);
    std::cout << "isovalues " << iso.size() << (iso.integer() ? " (every integer of the range)"
                                                 : iso.float64() ? " (uniform float64 list)" : " (uniform float32 list)")
              << "\n";
    return 0;
}

void setup_info(CLI::App* c, InfoArgs& a) {
    add_volume_argument(c, a.volume);
    a.raw.add(c);
}

}  // namespace

Command info_command() {
    return without_device(command<InfoArgs>("info", "dimensions, type, value range and histogram of a volume",
                                            setup_info, [](const InfoArgs& a) { return cmd_info(a.volume, a.raw); }));
}

}  // namespace cli
