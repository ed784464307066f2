// Output files of the command-line tool, written through clfractal/output_file.hpp: a
// regular file through a temporary name in its folder, renamed when the run succeeds; a
// symlink through to its target; a FIFO, a character device or "-" (stdout) directly.
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

/// Writes `content` to `path` (see above); throws clfractal::InputError naming the path.
void write_file_atomic(const std::string& path, const std::string& content);

/// `text` as a gnuplot single-quoted string: nothing is substituted inside one (in a
/// double-quoted one gnuplot runs `backquoted` text as a shell command), control characters
/// become '?' (a newline would end the command), a quote is written twice.
std::string gnuplot_string(const std::string& text);

/// Renders a gnuplot `script` (which plots the datablock $DATA, filled with `data`) to
/// the PNG `path`. Throws InputError with a clear message when gnuplot is not installed.
void plot_png(const std::string& script, const std::string& data, const std::string& path);

/// The same, returning the PNG's bytes (drawn in a file of the system's temporary folder,
/// removed again); `what` names the figure in errors.
std::string plot_png_bytes(const std::string& script, const std::string& data, const std::string& what);

/// The long names of the options that name an output file, in every subcommand.
const std::vector<std::string>& output_option_names();

/// Checks every output option given to `command` before any work (clfractal::check_output:
/// folder exists and is writable, no folder or odd special file as target), that no file is
/// named twice and at most one output is "-". Returns true if one is "-".
bool check_output_options(const CLI::App& command);
