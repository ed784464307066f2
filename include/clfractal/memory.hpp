// How much host memory a command may take, checked before any work (docs/definitions.md §36):
// a volume too large for the machine is an InputError naming the file and the size it needs,
// never the kernel's OOM killer halfway through.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

namespace clfractal {

/// Bytes of memory this process can still take: the least of the kernel's MemAvailable
/// (/proc/meminfo) and, inside a cgroup with a memory limit (v2 memory.max, v1
/// memory.limit_in_bytes), that limit less its current usage. The environment variable
/// CLFRACTAL_MEMORY_LIMIT overrides it: a byte count with an optional K, M, G or T suffix
/// (powers of 1024), or "off" for no limit. Empty when nothing is known (no /proc) or "off".
std::optional<std::uint64_t> available_memory();

/// A byte count "N", "N K", "NM", "1.5G", ... (suffixes are powers of 1024); throws
/// InputError naming `what` on anything else.
std::uint64_t parse_byte_count(const std::string& text, const std::string& what);

/// "512 MiB", "3.2 GiB": `bytes` in the largest binary unit that keeps it at least 1.
std::string byte_size_string(std::uint64_t bytes);

/// What a command asks for: `need` bytes in all, of which `held` (the volume, already read)
/// are in use.
struct MemoryRequest {
    std::uint64_t need = 0;
    std::uint64_t held = 0;
    std::string file;   ///< the input, named first in the message
    std::string what;   ///< "clfractal components"
    std::string basis;  ///< how `need` comes about: "4x the 500.0 MiB volume + 256 MiB"
    std::string hint;   ///< what to do instead
};

/// Throws InputError "FILE: WHAT needs about X of memory (BASIS), but Y is available (HINT)"
/// when `need` is more than available_memory() + `held`.
void require_memory(const MemoryRequest& r);

}  // namespace clfractal
