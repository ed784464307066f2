// libFuzzer target: NRRD header and data through both readers (read_volume and SliceReader).
// The input is an attached NRRD, or "HEADER@@DATA@@BYTES": a detached header with BYTES as
// the data files d.raw, d0.raw and d1.raw (for single names, patterns and lists). A refusal
// must be an InputError naming the file; the two readers must agree on the values.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "clfractal/error.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/volume_io.hpp"
#include "fuzz_files.hpp"

using namespace clfractal;

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
    std::vector<unsigned char> in_core, streamed;
    std::string core_error, stream_error;
    try {
        const Volume v = read_volume(path);
        const auto* p = static_cast<const unsigned char*>(v.data());
        in_core.assign(p, p + v.size_bytes());
    } catch (const InputError& e) {
        core_error = e.what();
    }
    try {
        SliceReader r(path);
        streamed.resize(r.slice_bytes() * r.dims().nz);
        r.read(streamed.data(), r.dims().nz);
    } catch (const InputError& e) {
        stream_error = e.what();
    }
    for (const std::string* e : {&core_error, &stream_error})
        if (!e->empty() && e->find('\n') != std::string::npos) __builtin_trap();  // one line
    if (core_error.empty() && stream_error.empty() && in_core != streamed) __builtin_trap();
    return 0;
}
