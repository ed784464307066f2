// The memory check before any work (docs/definitions.md §36).
#include "clfractal/memory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "clfractal/error.hpp"

namespace clfractal {
namespace {

// The first number in `path` (a cgroup file holding "max" or bytes), if any.
std::optional<std::uint64_t> number_in(const std::string& path) {
    std::ifstream f(path);
    std::string word;
    if (!(f >> word) || word.empty() || word.find_first_not_of("0123456789") != std::string::npos) return {};
    return std::strtoull(word.c_str(), nullptr, 10);
}

// MemAvailable in /proc/meminfo (kB), in bytes.
std::optional<std::uint64_t> mem_available() {
    std::ifstream f("/proc/meminfo");
    std::string key;
    std::uint64_t kb = 0;
    std::string unit;
    while (f >> key >> kb >> unit)
        if (key == "MemAvailable:") return kb * 1024;
    return {};
}

// The room left under this process's cgroup limit: v2 (unified) or v1 (memory controller).
std::optional<std::uint64_t> cgroup_room() {
    std::ifstream f("/proc/self/cgroup");
    std::string line;
    while (std::getline(f, line)) {
        const auto a = line.find(':'), b = line.find(':', a + 1);
        if (a == std::string::npos || b == std::string::npos) continue;
        const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
        std::optional<std::uint64_t> limit, usage;
        if (controllers.empty()) {
            limit = number_in("/sys/fs/cgroup" + path + "/memory.max");
            usage = number_in("/sys/fs/cgroup" + path + "/memory.current");
        } else if (controllers.find("memory") != std::string::npos) {
            limit = number_in("/sys/fs/cgroup/memory" + path + "/memory.limit_in_bytes");
            usage = number_in("/sys/fs/cgroup/memory" + path + "/memory.usage_in_bytes");
        }
        if (limit && usage) return *limit > *usage ? *limit - *usage : 0;
    }
    return {};
}

}  // namespace

std::uint64_t parse_byte_count(const std::string& text, const std::string& what) {
    std::size_t used = 0;
    double x = -1;
    try {
        x = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    std::string rest = text.substr(used);
    rest.erase(std::remove(rest.begin(), rest.end(), ' '), rest.end());
    const std::string units = "KMGT";
    double scale = 1;
    if (!rest.empty() && (rest.size() == 1 || rest.substr(1) == "iB" || rest.substr(1) == "B")) {
        const auto k = units.find(char(std::toupper(static_cast<unsigned char>(rest[0]))));
        if (k != std::string::npos) scale = std::pow(1024.0, double(k + 1)), rest.clear();
    }
    if (used == 0 || !rest.empty() || !(x >= 0) || x * scale >= 1.8e19)
        throw InputError(what + ": expected a byte count such as 4096, 512M or 2G, got \"" + printable(text) + "\"");
    return std::uint64_t(x * scale);
}

std::string byte_size_string(std::uint64_t bytes) {
    const char* names[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    double x = double(bytes);
    int k = 0;
    while (x >= 1024 && k < 4) x /= 1024, ++k;
    char text[48];
    std::snprintf(text, sizeof text, k == 0 ? "%.0f %s" : "%.1f %s", x, names[k]);
    return text;
}

std::optional<std::uint64_t> available_memory() {
    if (const char* env = std::getenv("CLFRACTAL_MEMORY_LIMIT"); env && *env) {
        if (std::string(env) == "off") return {};
        return parse_byte_count(env, "CLFRACTAL_MEMORY_LIMIT");
    }
    std::optional<std::uint64_t> room = mem_available();
    if (const auto c = cgroup_room()) room = room ? std::min(*room, *c) : *c;
    return room;
}

void require_memory(const MemoryRequest& r) {
    const std::optional<std::uint64_t> room = available_memory();
    if (!room || r.need <= *room + r.held) return;
    throw InputError(printable(r.file) + ": " + r.what + " needs about " + byte_size_string(r.need) + " of memory" +
                     (r.basis.empty() ? "" : " (" + r.basis + ")") + ", but " + byte_size_string(*room + r.held) +
                     " is available" + (r.hint.empty() ? "" : " (" + r.hint + ")"));
}

}  // namespace clfractal
