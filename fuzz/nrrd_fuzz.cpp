// libFuzzer target: NRRD header and data through both readers (read_volume and SliceReader).
// The input is an attached NRRD, or "HEADER@@DATA@@BYTES": a detached header with BYTES as
// the data files d.raw, d0.raw and d1.raw (for single names, patterns and lists). A refusal
// must be an InputError naming the file in one line; the two readers must agree on the values.
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::size_t split = input.find("@@DATA@@");
    std::string path;
    if (split == std::string::npos) {
        path = fuzz::put("f.nrrd", input.data(), input.size());
    } else {
        const std::string bytes = input.substr(split + 8);
        for (const char* name : {"d.raw", "d0.raw", "d1.raw"}) fuzz::put(name, bytes.data(), bytes.size());
        path = fuzz::put("f.nhdr", input.data(), split);
    }
    fuzz::read_both(path);
    return 0;
}
