// libFuzzer target: MetaImage through both readers (read_volume and SliceReader). The input
// is one file f.mha (header and LOCAL data), or "HEADER@@DATA@@BYTES": f.mhd with BYTES as
// the data files d.raw and d.zraw.
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::vector<std::string> parts = fuzz::pieces(input, "@@DATA@@", 2);
    fuzz::fresh("mha");
    if (parts.size() == 1) {
        fuzz::read_both(fuzz::put("mha/f.mha", input));
        return 0;
    }
    fuzz::put("mha/d.raw", parts[1]);
    fuzz::put("mha/d.zraw", parts[1]);
    fuzz::read_both(fuzz::put("mha/f.mhd", parts[0]));
    return 0;
}
