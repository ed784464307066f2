#include "clfractal/output_file.hpp"

#include <unistd.h>

#include <atomic>
#include <filesystem>

#include "clfractal/error.hpp"

namespace clfractal {

namespace fs = std::filesystem;

std::string temporary_path(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

void discard_temporary(const std::string& tmp, const std::string& path, const std::string& message) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw InputError(path + ": " + message);
}

void rename_into_place(const std::string& tmp, const std::string& path) {
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) discard_temporary(tmp, path, "cannot write: " + ec.message());
}

}  // namespace clfractal
