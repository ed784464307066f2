// Shared pieces of the command-line tool: progress output, raw-file options, number
// formatting, and the registry through which each subcommand file adds its command.
#pragma once
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

#include "clfractal/advice.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume_io.hpp"

namespace cli {

/// Set by -q/--quiet: no progress on stderr.
extern bool quiet;

/// One progress line on stderr ("clfractal: ..."), unless --quiet.
void progress(const std::string& s);

/// The clean bands of a curve (at most 5, best first), or why there is none.
void print_bands(std::ostream& out, const clfractal::FdCurve& f, const std::vector<clfractal::CleanBand>& bands,
                 double max_fd, double min_share);
nlohmann::json bands_json(const clfractal::FdCurve& f, const std::vector<clfractal::CleanBand>& bands);
/// The noise estimate: the median over the isovalues in the trusted range.
void print_noise(std::ostream& out, const clfractal::NoiseEstimate& e);
nlohmann::json noise_json(const clfractal::NoiseEstimate& e);

/// --window K for every command that computes LD: checked while parsing (even, >= 2), so
/// a bad window fails before any file is read or the device starts.
CLI::Option* add_window_option(CLI::App* app, int& window, const std::string& what = "LD window k");

/// --iso S: checked while parsing (a finite number, or "auto", held as auto_isovalue).
CLI::Option* add_iso_option(CLI::App* app, double& iso, const std::string& what);

/// The value --iso auto parses to (never a real isovalue: the lowest double).
constexpr double auto_isovalue = -1.7976931348623157e308;
inline bool is_auto_isovalue(double iso) { return iso == auto_isovalue; }

/// The isovalue to use for `v`: `iso` itself (with warn_isovalue_outside), or for --iso auto
/// the representative of the best clean band of v's box-dimension curve, said on stderr.
/// Throws InputError when auto finds no clean band.
double checked_isovalue(const clfractal::Volume& v, double iso);

/// --q Q, the bin width of the 4D dimension: checked while parsing (finite, > 0); the
/// check against the value range needs the volume (fd4.hpp check_bin_width).
CLI::Option* add_q_option(CLI::App* app, double& q);

/// Warns on stderr (before any device work) when `iso` selects nothing in `v`: every
/// cube's span [a, b] lies inside [vmin, vmax], so s <= vmin or s > vmax intersects none.
void warn_isovalue_outside(const clfractal::Volume& v, double iso);

/// Options that say how to read a headerless raw file, and --as (any file).
struct RawArgs {
    std::string dims, type, endian = "little", series, as;
    bool scaled = false;
    void add(CLI::App* app);
    clfractal::RawOptions options() const;
};

/// An isovalue written so that it reads back to the same integer, float32 (9 significant
/// digits) or float64 (17).
std::string iso_string(const clfractal::IsovalueSet& iso, std::size_t j);

/// How a single isovalue is compared, for reports: "" (integer data: ceil(s)),
/// " (compared as float32)" or " (compared as float64)".
std::string compared_as(clfractal::ValueType t);

/// A dimension for CSV: empty where undefined (NaN).
std::string fd_string(double d);

/// A dimension for JSON: null where undefined (NaN).
nlohmann::json fd_json(double d);

/// The curve as `fd --csv` writes it: isovalue,count,count_sub,fd[,count_lL...,fd_fit]
/// [,components].
std::string fd_csv(const clfractal::FdCurve& f, const std::vector<std::int64_t>* components = nullptr);

/// A subcommand: its CLI11 app and what runs when it is chosen.
struct Command {
    CLI::App* app;
    std::function<int()> run;
};
using Commands = std::vector<Command>;

/// The span counts of one kind of a volume file read slice by slice (fd --stream), with
/// the isovalues given (A:B:STEP), or the default set from a first pass over the file.
struct StreamedSpans {
    clfractal::Dims dims;
    clfractal::ValueType type;
    clfractal::SpanResult spans;
    std::string method;  ///< how the file was read: mmap, gzip, memory
};
StreamedSpans stream_spans(const std::string& volume, const clfractal::RawOptions& raw, const std::string& isovalues,
                           std::size_t bins, int levels, clfractal::SpanKind kind);
/// local --stream: the LD field of a volume file read and written slice by slice.
int cmd_local_stream(const std::string& volume, const clfractal::RawOptions& raw, double iso, int window,
                     const std::string& output);

// Subcommands defined in their own files (cmd_*.cpp). Each adds itself to `app` and
// appends what to run; its options live in heap state owned by the closure.
void add_smooth_command(CLI::App& app, Commands& commands);
void add_filter_command(CLI::App& app, Commands& commands);
void add_components_command(CLI::App& app, Commands& commands);
void add_survey_command(CLI::App& app, Commands& commands);
/// fd4 and local4 (cmd_fd4.cpp).
void add_fd4_commands(CLI::App& app, Commands& commands);
void add_report_command(CLI::App& app, Commands& commands);

}  // namespace cli

void add_noise_command(CLI::App& app, cli::Commands& commands);
