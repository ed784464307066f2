// libFuzzer target: TIFF through both readers (read_volume and SliceReader). The input is
// one (multi-page) file f.tif, or, cut at "@@SLICE@@", up to four single-page slices of a
// directory.
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::vector<std::string> parts = fuzz::pieces(input, "@@SLICE@@", 4);
    const std::string dir = fuzz::fresh("tiff");
    if (parts.size() == 1) {
        fuzz::read_both(fuzz::put("tiff/f.tif", input));
        return 0;
    }
    for (std::size_t i = 0; i < parts.size(); ++i) fuzz::put("tiff/s" + std::to_string(i) + ".tif", parts[i]);
    fuzz::read_both(dir);
    return 0;
}
