// Output files are written to a temporary name beside the target and renamed into place,
// so that a failure never leaves a half-written file (DESIGN §3).
#pragma once
#include <string>

namespace clfractal {

/// A temporary name beside `path`, unique per process and call (same directory, so the
/// final rename is atomic).
std::string temporary_path(const std::string& path);

/// Renames `tmp` to `path`. On failure removes `tmp` and throws InputError naming `path`.
void rename_into_place(const std::string& tmp, const std::string& path);

/// Removes `tmp` (ignoring errors) and throws InputError "<path>: <message>".
[[noreturn]] void discard_temporary(const std::string& tmp, const std::string& path, const std::string& message);

}  // namespace clfractal
