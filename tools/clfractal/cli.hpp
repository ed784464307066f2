// Shared pieces of the command-line tool: progress output, raw-file options, number
// formatting, and the registry through which each subcommand file adds its command.
#pragma once
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/advice.hpp"
#include "clfractal/analysis.hpp"
#include "clfractal/components.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/smooth.hpp"
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
/// The noise estimate: the median over the isovalues in the trusted range.
void print_noise(std::ostream& out, const clfractal::NoiseEstimate& e);
/// The recommendations (ranked, with verdicts), the noisiest isovalue and, when nothing is
/// clean, what the denoising ladder found, with the command that writes its result.
void print_advice(std::ostream& out, const clfractal::Analysis& an, const std::string& volume);

/// --window K for every command that computes LD: checked while parsing (even, >= 2), so
/// a bad window fails before any file is read or the device starts.
CLI::Option* add_window_option(CLI::App* app, int& window, const std::string& what = "LD window k");

/// --iso S: checked while parsing (a finite number, or "auto", held as auto_isovalue).
CLI::Option* add_iso_option(CLI::App* app, double& iso, const std::string& what);

/// The value --iso auto parses to (never a real isovalue: the lowest double).
constexpr double auto_isovalue = -1.7976931348623157e308;
inline bool is_auto_isovalue(double iso) { return iso == auto_isovalue; }

/// The isovalue to use for `v`: `iso` itself (with warn_isovalue_outside), or for --iso auto
/// the first recommendation of v's analysis (clfractal::auto_isovalue), said on stderr.
double checked_isovalue(const clfractal::Volume& v, double iso);

/// --q Q, the bin width of the 4D dimension: checked while parsing (finite, > 0); the
/// check against the value range needs the volume (fd4.hpp check_bin_width).
CLI::Option* add_q_option(CLI::App* app, double& q);

/// Warns on stderr (before any device work) when `iso` selects nothing in `v`: every
/// cube's span [a, b] lies inside [vmin, vmax], so s <= vmin or s > vmax intersects none.
void warn_isovalue_outside(const clfractal::Volume& v, double iso);

/// Options that say how to read a headerless raw file, and --as (any file): defined once,
/// added to every command that reads a volume.
struct RawArgs {
    std::string dims, type, endian = "little", series, as, spacing;
    bool scaled = false;
    void add(CLI::App* app);
    clfractal::RawOptions options() const;
};

/// The VOLUME argument of the commands that read one volume.
CLI::Option* add_volume_argument(CLI::App* app, std::string& volume);

/// VOLUME and --iso S (required; `what` says how S is compared): the input of the commands
/// that work on one isosurface of one volume (local, mesh, smooth).
void add_volume_and_iso(CLI::App* app, std::string& volume, double& iso, const std::string& what);

/// The host memory a command takes at most (docs/definitions.md §36): `factor` times the
/// volume's bytes plus 256 MiB; `hint` says what to do instead when it is not available.
struct MemoryNeed {
    const char* command;  ///< "clfractal components"
    double factor = 4.0;
    const char* hint = "";
    std::uint64_t bytes(std::uint64_t volume_bytes) const;
};
/// Begins creating the shared device context (Context::start_shared) for `command`, on another
/// thread while the command reads its VOLUME. When VOLUME is a file of 32 MiB or more read
/// whole (no --stream), read_volume_within begins it instead: after its read when the header
/// says the data is stored uncompressed (peek_volume's method "mmap": such a read maps its
/// pages and copies on every core, and the loading of the OpenCL
/// libraries beside it slows both: `fd` on a hot 768^3 file, medians of 9 interleaved runs,
/// 0.90-0.94 s with the start beside the read, 0.88-0.89 s after it), else before it (one
/// core decompresses or decodes, the other starts the platform).
void start_device_for(const CLI::App& command);

/// read_volume, refused with an InputError naming the file and the size `need` asks for when
/// the machine does not have it: before reading where the header states the shape
/// (peek_volume), else once read and before any work.
clfractal::Volume read_volume_within(const std::string& volume, const clfractal::RawOptions& raw, const MemoryNeed& need,
                                     clfractal::FiniteCheck finite = clfractal::FiniteCheck::reject);
/// Reads `volume` as `raw` says, within `need` (read_volume_within), and resolves `iso` for it
/// (checked_isovalue: auto, warnings).
clfractal::Volume read_volume_at_isovalue(const std::string& volume, const RawArgs& raw, double& iso,
                                          const MemoryNeed& need);

/// -o/--output FILE (required): the file a command writes; `what` says which formats.
CLI::Option* add_output_option(CLI::App* app, std::string& output, const std::string& what);

/// --mesh FILE: also write an isosurface as PLY (`what` says which one).
CLI::Option* add_mesh_option(CLI::App* app, std::string& mesh, const std::string& what);

/// --preview FILE: render an isosurface to a PNG (`what` says which one).
CLI::Option* add_preview_option(CLI::App* app, std::string& preview, const std::string& what);

/// --bins K: the number of uniform isovalues for float data (0: 256).
CLI::Option* add_bins_option(CLI::App* app, std::size_t& bins);

/// --dims X,Y,Z or XxYxZ: three positive integers (`option` names them in errors).
clfractal::Dims parse_dims(const std::string& option, const std::string& text);

/// "A,B,C" or "A:B:STEP" (A, A+STEP, ... <= B, with a little slack for rounding), as
/// doubles; `option` names the list in errors.
std::vector<double> parse_list(const std::string& option, const std::string& spec);

/// --isovalues for a volume of type `type`: A:B:STEP (IsovalueSet::parse_range) or a comma
/// list A,B,... (8/16-bit integer data: consecutive integers, as every integer of a range is
/// counted at once).
clfractal::IsovalueSet parse_isovalues(const std::string& spec, clfractal::ValueType type);
/// --bins N for `type`: an InputError for 8/16-bit integer data, whose isovalues are every
/// integer of the range (--isovalues A:B:1 selects some).
void check_bins(std::size_t bins, clfractal::ValueType type);

/// --isovalues for the commands that take several: A:B:STEP or A,B,...
CLI::Option* add_isovalues_option(CLI::App* app, std::string& spec);

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

/// The curve as `components --csv` writes it: isovalue,components.
std::string components_csv(const clfractal::IsovalueSet& iso, const std::vector<std::int64_t>& components);

/// The curve as `components --json` writes it: volume (as given), dims, type, connectivity,
/// isovalues and components; no timings, so that `clfractal-mpi components --json` writes the
/// same bytes.
std::string components_json(const std::string& volume, const clfractal::Dims& dims, clfractal::ValueType type,
                            clfractal::Connectivity mode, const clfractal::IsovalueSet& iso,
                            const std::vector<std::int64_t>& components);

/// What `fd --json` says besides the analysis (clfractal::to_json): how the curve was counted.
struct FdJsonFacts {
    std::string volume;  ///< as given
    bool edge = false;
    int levels = 2;
    std::uint64_t min_count = 0;
};

/// `fd --json` without the facts of one run (device, times, slabs): the analysis's JSON and
/// the curve's summary `s` (with --min-count). `clfractal-mpi fd --json` writes the same keys,
/// so that its file equals fd's once each drops its run's facts.
nlohmann::json fd_analysis_json(const clfractal::Analysis& an, const clfractal::FdSummary& s, const FdJsonFacts& f);

/// fd's note in `skipped` when the denoising ladder was needed but the volume was never held
/// whole (--stream, clfractal-mpi).
std::string denoise_not_streamed();

/// The title of the `components --plot` figure of `volume`.
std::string components_plot_title(const std::string& volume, clfractal::Connectivity mode);

/// The `components` report's lines volume, connectivity, isovalues and most (the largest
/// count and its first isovalue).
void print_components(std::ostream& out, const std::string& volume, const clfractal::Dims& dims,
                      clfractal::ValueType type, clfractal::Connectivity mode, const clfractal::IsovalueSet& iso,
                      const std::vector<std::int64_t>& components);

/// A subcommand, the one way to register one: its name, its one-line help, and `attach`,
/// which adds its options to its CLI11 app and returns what runs when it is chosen.
struct Command {
    std::string name, help;
    std::function<std::function<int()>(CLI::App&)> attach;
    /// Whether main() begins creating the device (Context::start_shared) before the command
    /// runs, so that the platform starts while the command reads its input.
    bool uses_device = true;
};

/// `c` for a command that never needs the device (main() does not start it).
inline Command without_device(Command c) {
    c.uses_device = false;
    return c;
}

/// A Command whose options `setup(CLI::App*, Args&)` adds into an Args, and that runs
/// `run(args)` (an exit status) once the command line is parsed.
template <class Args, class Setup, class Run>
Command command(std::string name, std::string help, Setup setup, Run run) {
    return {std::move(name), std::move(help), [setup, run](CLI::App& app) {
                auto args = std::make_shared<Args>();
                setup(&app, *args);
                return std::function<int()>([args, run] { return run(*args); });
            }};
}

// The subcommands, one file each (cmd_*.cpp), in the order of --help.
Command devices_command();
Command info_command();
Command fd_command();
Command local_command();
Command gen_command();
Command mesh_command();
Command bench_command();
Command smooth_command();
Command noise_command();
Command filter_command();
Command components_command();
Command survey_command();
Command fd4_command();
Command local4_command();
Command report_command();

/// A volume that filter and smooth report on before and after: uploaded once when it fits
/// the device in one piece (slab_fit), and every report reads that copy; else each report
/// uploads it as the Volume overloads do (by slabs where needed). `v` must outlive it.
class ReportVolume {
public:
    ReportVolume(clfractal::Context& ctx, const clfractal::Volume& v);
    /// A result already on the device, with its host copy `v` (no upload).
    ReportVolume(const clfractal::Volume& v, clfractal::DeviceVolume&& on_device);
    /// The device copy, or nullptr when the volume does not fit in one piece.
    const clfractal::DeviceVolume* device() const { return device_ ? &*device_ : nullptr; }
    /// count_spans at one isovalue (cubes, levels 0 and 1).
    clfractal::SpanResult spans_at(double s) const;
    clfractal::IsoCounts counts_at(double s) const;
    std::int64_t components_at(double s) const;

private:
    clfractal::Context& ctx_;
    const clfractal::Volume& host_;
    std::optional<clfractal::DeviceVolume> device_;
};

/// The span counts of one kind of the file `reader` reads (`volume`, for messages), slice by
/// slice (fd --stream), with the isovalues given (A:B:STEP), or the default set from a first
/// pass over the file; the reader is left at the end of the file.
struct StreamedSpans {
    clfractal::Dims dims;
    clfractal::ValueType type;
    clfractal::SpanResult spans;
    std::string method;  ///< how the file was read: mmap, gzip, memory
    std::vector<std::uint64_t> histogram;  ///< isovalue_histogram at the spans' isovalues
};
StreamedSpans stream_spans(clfractal::SliceReader& reader, const std::string& volume, const std::string& isovalues,
                           std::size_t bins, int levels, clfractal::SpanKind kind);
/// components(s) at a few isovalues of the file `reader` reads, from its next slice to its
/// last, slice by slice (ComponentsAtStream):
/// memory a batch of slices (32 MiB) and O(slice) an isovalue, whatever the file size.
std::vector<std::int64_t> stream_components_at(clfractal::SliceReader& reader, const std::vector<double>& isovalues,
                                               clfractal::Connectivity mode);
/// local --stream: the LD field of a volume file read and written slice by slice.
int cmd_local_stream(const std::string& volume, const clfractal::RawOptions& raw, double iso, int window,
                     const std::string& output);

}  // namespace cli
