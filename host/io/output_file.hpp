// How output files are written (docs/definitions.md §30): a regular file goes to a temporary
// name beside its final place and is renamed there, so that a failure never leaves a
// half-written file; a symlink is written through (the temporary sits beside the link's final
// target, and the link stays); a FIFO, a character device and "-" (standard output) are written
// directly. An OutputRun makes the renames of one run all-or-nothing: they happen at commit(),
// and a run that ends without commit() leaves no output file and no temporary behind.
#pragma once
#include <string>

namespace clfractal {

/// Where an output path is written.
struct OutputTarget {
    std::string path;     ///< as given (named in messages)
    std::string file;     ///< what is opened: the final file, the symlink's target, or /dev/stdout for "-"
    bool direct = false;  ///< FIFO, character device or stdout: written in place, never renamed
};

/// Resolves `path` and checks, before any work, that it can be written: "-" is standard
/// output; an existing FIFO or character device is written directly; a symlink is followed
/// (also a dangling one) to its final target; otherwise the folder must exist and be
/// writable and the path must not be a directory or another special file. Throws
/// InputError "<path>: <problem>".
OutputTarget check_output(const std::string& path);

/// What a writer opens for `path`: for a direct target the target itself, otherwise a
/// temporary name beside the final file, unique per process and call (same directory, so
/// the final rename is atomic). The name is removed again if the process is stopped by
/// SIGINT, SIGTERM or SIGHUP while an OutputRun is open. `suffix` ends the temporary name
/// (a writer that tells the format by the extension, as nifticlib does, keeps it).
std::string temporary_path(const std::string& path, const std::string& suffix = "");

/// Renames `tmp` to the final file of `path` (nothing for a direct target). While an
/// OutputRun is open, the rename is deferred to its commit(). On failure removes `tmp` and
/// throws InputError naming `path`.
void rename_into_place(const std::string& tmp, const std::string& path);

/// Removes `tmp` (ignoring errors; never a direct target) and throws InputError
/// "<path>: <message>".
[[noreturn]] void discard_temporary(const std::string& tmp, const std::string& path, const std::string& message);

/// Removes `tmp` if it is a temporary from temporary_path (never a direct target).
void remove_temporary(const std::string& tmp);

/// One run's outputs, committed together. At most one is open at a time (the command-line
/// tool opens one per command); without one, every rename happens at once.
class OutputRun {
public:
    OutputRun();
    /// Removes every temporary not yet committed.
    ~OutputRun();
    OutputRun(const OutputRun&) = delete;
    OutputRun& operator=(const OutputRun&) = delete;
    /// Renames every finished output into place. If a rename fails, the outputs not yet
    /// renamed are removed and InputError names the one that failed.
    void commit();
};

}  // namespace clfractal
