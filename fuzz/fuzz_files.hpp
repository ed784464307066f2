// Scratch files for the fuzz targets: one folder per process, the input written there; and
// the check every reader target makes.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "clfractal/error.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/volume_io.hpp"

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
    const std::filesystem::path path = folder() / name;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(data, std::streamsize(size));
    return path.string();
}

inline std::string put(const std::string& name, const std::string& bytes) {
    return put(name, bytes.data(), bytes.size());
}

/// An empty sub-folder of folder() (emptied of what the previous input left there).
inline std::string fresh(const std::string& name) {
    const std::filesystem::path d = folder() / name;
    std::error_code ec;
    std::filesystem::remove_all(d, ec);
    std::filesystem::create_directories(d);
    return d.string();
}

/// `input` cut at each `mark` (at most `max` pieces; the last keeps the rest).
inline std::vector<std::string> pieces(const std::string& input, const std::string& mark, std::size_t max) {
    std::vector<std::string> out;
    std::size_t from = 0;
    while (out.size() + 1 < max) {
        const std::size_t at = input.find(mark, from);
        if (at == std::string::npos) break;
        out.push_back(input.substr(from, at - from));
        from = at + mark.size();
    }
    out.push_back(input.substr(from));
    return out;
}

/// A refusal is one line that names the input (its path, or the folder it lies in).
inline void check_message(const std::string& message) {
    if (message.find('\n') != std::string::npos) __builtin_trap();
    if (message.find(folder().string()) == std::string::npos) __builtin_trap();
}

/// Reads `path` in core (read_volume) and slice by slice (SliceReader): each either reads or
/// refuses with an InputError (anything else escapes to libFuzzer as a crash), and when both
/// read they give the same values.
inline void read_both(const std::string& path, const clfractal::RawOptions& raw = {}) {
    using namespace clfractal;
    std::vector<unsigned char> in_core, streamed;
    bool core_ok = false, stream_ok = false;
    try {
        const Volume v = read_volume(path, raw);
        const auto* p = static_cast<const unsigned char*>(v.data());
        in_core.assign(p, p + v.size_bytes());
        core_ok = true;
    } catch (const InputError& e) {
        check_message(e.what());
    }
    try {
        SliceReader r(path, raw);
        streamed.resize(r.slice_bytes() * r.dims().nz);
        r.read(streamed.data(), r.dims().nz);
        stream_ok = true;
    } catch (const InputError& e) {
        check_message(e.what());
    }
    if (core_ok && stream_ok && in_core != streamed) __builtin_trap();
}

}  // namespace fuzz
