// libFuzzer target: the C ABI's volume entry points with arbitrary arguments. The first 13
// bytes choose the type (an int, any value), three small dims and which calls get NULL;
// the rest is the data and, written to a file, what clf_volume_read reads.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "clfractal/clfractal.h"
#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 13) return 0;
    int type = 0;
    std::memcpy(&type, data, 4);
    const std::size_t nx = data[4] % 9, ny = data[5] % 9, nz = data[6] % 9;
    const std::uint8_t nulls = data[7];
    const std::string name = (data[8] & 1) ? "v.nrrd" : (data[8] & 2) ? "v_2x2x2_uint8.raw" : "v.nhdr";
    const std::vector<std::uint8_t> rest(data + 13, data + size);
    std::vector<std::uint8_t> values(nx * ny * nz * 8 + 1, 0);  // 8: the widest value type
    if (!rest.empty()) std::memcpy(values.data(), rest.data(), std::min(values.size(), rest.size()));

    clf_volume* v = nullptr;
    const clf_status s = clf_volume_create((nulls & 1) ? nullptr : values.data(), nx, ny, nz, type,
                                           (nulls & 2) ? nullptr : &v);
    if ((s == CLF_OK) != (v != nullptr)) __builtin_trap();
    if (s != CLF_OK && clf_last_error()[0] == '\0') __builtin_trap();
    size_t dims[3] = {0, 0, 0};
    clf_volume_dims((nulls & 4) ? nullptr : v, dims);
    const clf_type t = clf_volume_type((nulls & 8) ? nullptr : v);
    if (v && !(nulls & 8) && (int(t) != type)) __builtin_trap();
    clf_volume_destroy(v);

    const std::string path = fuzz::put(name, reinterpret_cast<const char*>(rest.data()), rest.size());
    clf_volume* r = nullptr;
    if (clf_volume_read((nulls & 16) ? nullptr : path.c_str(), (nulls & 32) ? nullptr : &r) == CLF_OK) {
        clf_volume_dims(r, dims);
        clf_volume_type(r);
    }
    clf_volume_destroy(r);
    return 0;
}
