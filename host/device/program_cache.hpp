// The program binaries of earlier processes: one file per (device, driver, source, options)
// in the user's cache directory, so that a new process skips the OpenCL C compiler.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace clfractal::detail {

/// The cache directory: $CLFRACTAL_PROGRAM_CACHE when set ("off" disables the cache), else
/// $XDG_CACHE_HOME/clfractal, else $HOME/.cache/clfractal; "" when disabled or unknown.
std::string program_cache_dir();

/// What a binary depends on, written into its file and checked on load: device, driver and
/// platform versions, the build options and the source.
std::string program_cache_key(const std::string& device_identity, const std::string& source,
                              const std::string& options);

/// The binary stored under `key`, or nothing when it is absent, truncated, corrupt or for
/// another key.
std::optional<std::vector<unsigned char>> load_program_binary(const std::string& dir, const std::string& key);

/// Stores a binary under `key`: written to a temporary file and renamed over the entry, so
/// that concurrent processes read either a whole old entry or a whole new one. Failures
/// (read-only or full disk) are ignored: the cache only saves time.
void store_program_binary(const std::string& dir, const std::string& key, const std::vector<unsigned char>& binary);

/// The file of `key` in `dir` (tests corrupt it).
std::string program_cache_file(const std::string& dir, const std::string& key);

}  // namespace clfractal::detail
