// The report page (clfractal report) as a function of a volume in memory: the command and the
// Python package (clfractal.report) build the same page and JSON through it.
#pragma once
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "clfractal/analysis.hpp"
#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"

namespace cli {

using clock_type = std::chrono::steady_clock;

/// What the report computes and shows (clfractal report's options).
struct ReportSettings {
    double clean_fd = 2.2, clean_share = 0.01;
    int window = 8;
    std::size_t bins = 0;  ///< uniform isovalues of float and wide integer data (0: 256)
    std::size_t mesh_triangles = 50000;
    bool static_page = false;
};

/// The analysis the report computes: the whole component curve, the noise level, D4 and the
/// denoising ladder within 4x the volume + 256 MiB.
clfractal::AnalysisOptions report_options(const ReportSettings& s, const clfractal::Volume& v);

struct ReportPage {
    clfractal::Analysis analysis;
    std::string html;     ///< the self-contained page
    nlohmann::json json;  ///< the numbers of the page (clfractal report --json)
};

/// The page of `v`, whose source is `file` (the page's "file" line) read as `format`
/// (describe_volume_file's lines); "seconds" counts from `start`. Throws InputError for bins
/// given for 8/16-bit integer data; the pictures need gnuplot (plots.hpp).
ReportPage report_page(clfractal::Context& ctx, const clfractal::Volume& v, const ReportSettings& s,
                       const std::string& file, const std::vector<std::string>& format, clock_type::time_point start);

}  // namespace cli
