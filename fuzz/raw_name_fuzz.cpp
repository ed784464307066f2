// libFuzzer target: NAME_XxYxZ_TYPE.raw name parsing, and read_raw of a file by that name.
#include <cstdint>
#include <cstdio>
#include <string>

#include "clfractal/error.hpp"
#include "clfractal/volume_io.hpp"
#include "fuzz_files.hpp"

using namespace clfractal;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string name(reinterpret_cast<const char*>(data), size);
    Dims dims;
    ValueType type = ValueType::uint8;
    if (parse_raw_name(name, dims, type)) {
        // Accepted names end in .raw and give three axes and a canonical type.
        if (name.size() < 4 || name.compare(name.size() - 4, 4, ".raw") != 0) __builtin_trap();
        if (value_type_name(type)[0] == 0) __builtin_trap();
    }
    // A file under that name (when it is one), holding 64 bytes.
    if (name.empty() || name.size() > 200 || name.find('/') != std::string::npos || name.find('\0') != std::string::npos ||
        name == "." || name == "..")
        return 0;
    const char bytes[64] = {};
    const std::string path = fuzz::put(name, bytes, sizeof bytes);
    try {
        read_volume(path);
    } catch (const InputError&) {
    }
    std::remove(path.c_str());
    return 0;
}
