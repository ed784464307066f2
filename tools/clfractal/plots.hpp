// Plots a person reads at a glance (gnuplot, through plot_png): curves over the isovalues
// annotated the same way wherever they are drawn (fd --plot, components --plot, report),
// and images (mesh previews, slices) with the LD colour bar.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "clfractal/advice.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/render.hpp"

namespace cli {

/// A gnuplot figure: the script, its $DATA, and any file the script reads (kept until the
/// figure is gone).
struct Figure {
    std::string script, data;
    std::shared_ptr<void> files;
    void write(const std::string& path) const;           ///< to a PNG file (plot_png)
    std::string png(const std::string& what) const;      ///< the PNG's bytes
};

/// The x axis every curve plot shares: the isovalues, the intersected count drawn as a grey
/// underlay on the second y axis, the isovalues with few cubes (drawn as grey points instead
/// of the line, never clipped off the chart), and the clean bands (shaded).
struct CurveAxis {
    clfractal::IsovalueSet isovalues;
    std::vector<std::uint64_t> count;  ///< the underlay, I_G(s)
    std::string count_label;           ///< "intersected cubes I(s)"
    std::vector<char> few;             ///< 1 where the subsampled count is below the floor
    std::vector<clfractal::CleanBand> bands;
};

/// The axis of a curve: I_G(s) as the underlay, few where I_G'(s) < max(min_count, 1% of its
/// largest, 1).
CurveAxis curve_axis(const clfractal::FdCurve& f, const std::vector<clfractal::CleanBand>& bands,
                     std::uint64_t min_count = 0);

/// A horizontal guide line at a value of the curve's axis.
struct Guide {
    double value;
    std::string colour, title;
};

/// One curve on the first y axis.
struct CurvePanel {
    std::string ylabel, title, colour = "#1f5fa8";
    std::vector<double> values;  ///< NaN: not drawn
    std::vector<double> fit;     ///< optional second curve, dashed (fd_fit)
    std::string fit_title;
    bool log_scale = false;
    /// Values are shown clamped into [clamp_lo, clamp_hi], so that none runs off the chart.
    double clamp_lo = -std::numeric_limits<double>::infinity(), clamp_hi = std::numeric_limits<double>::infinity();
    /// The y range always shown (NaN: gnuplot's autoscale), widened to the shown values.
    double range_lo = std::numeric_limits<double>::quiet_NaN(), range_hi = std::numeric_limits<double>::quiet_NaN();
    std::vector<Guide> guides;
};

/// D(s) with guides at 2 (clean surface) and 3 (noise), clamped into [1, 4], fd_fit dashed
/// when the curve has more than two levels.
CurvePanel fd_panel(const clfractal::FdCurve& f);
/// The component count (log scale; zero counts left out) with a guide at 1 (one connected
/// surface).
CurvePanel components_panel(const std::vector<std::int64_t>& components);

/// Draws the panels stacked over the shared axis (one PNG): each with its guide lines, the
/// clean bands shaded, the count underlay on its second axis, the few-count isovalues greyed,
/// and its legend below it.
Figure curve_plot(const CurveAxis& axis, const std::vector<CurvePanel>& panels, const std::string& title);

/// fd --plot: the annotated D(s).
void write_fd_plot(const clfractal::FdCurve& f, const std::vector<clfractal::CleanBand>& bands,
                   std::uint64_t min_count, const std::string& title, const std::string& path);

/// components --plot and fd --components --plot: the annotated component curve, under the
/// annotated D(s) when `with_fd` (thesis Figs. 2.1 + 3.2 in one figure).
void write_components_plot(const clfractal::FdCurve& f, const std::vector<clfractal::CleanBand>& bands,
                           const std::vector<std::int64_t>& components, bool with_fd, const std::string& title,
                           const std::string& path);

/// An RGB image (rows top to bottom; pixel (i, j), counted from the bottom row, is centred
/// on (i dx, j dy), as a slice's vertex is) with the LD colour bar (ld_blue .. ld_red) beside it and
/// `label` written on its top left; `lines` (x0, y0, x1, y1 in the same units) are drawn on
/// top in `line_colour`. `axes`: draw the x and y axes (a slice) or none (a mesh preview).
struct ImageFigure {
    const clfractal::Image* image = nullptr;
    double dx = 1, dy = 1;
    std::string title, label, xlabel, ylabel, line_colour = "#ffd600", line_title;
    std::vector<std::array<float, 4>> lines;
    bool axes = false;
    std::size_t width = 760, height = 600;
};
Figure image_figure(const ImageFigure& fig);

}  // namespace cli
