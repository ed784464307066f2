// Output files of the command-line tool: always written to a temporary name in the
// target directory and renamed, so a failure never leaves a half-written file.
#pragma once
#include <string>

/// Writes `content` to `path` atomically; throws clfractal::InputError naming the path.
void write_file_atomic(const std::string& path, const std::string& content);

/// Renders a gnuplot `script` (which plots the datablock $DATA, filled with `data`) to
/// the PNG `path`. Throws InputError with a clear message when gnuplot is not installed.
void plot_png(const std::string& script, const std::string& data, const std::string& path);
