// Scratch files for the fuzz targets: one folder per process, the input written there.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fuzz {

inline const std::filesystem::path& folder() {
    static const std::filesystem::path dir = [] {
        auto d = std::filesystem::temp_directory_path() / ("clfractal_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

inline std::string put(const std::string& name, const char* data, std::size_t size) {
    const std::string path = (folder() / name).string();
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(data, std::streamsize(size));
    return path;
}

}  // namespace fuzz
