// libFuzzer target: a DICOM series through both readers (read_volume and SliceReader). The
// input is up to four files of one directory, cut at "@@SLICE@@" (s0.dcm, s1.dcm, ...).
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::vector<std::string> parts = fuzz::pieces(input, "@@SLICE@@", 4);
    const std::string dir = fuzz::fresh("dicom");
    for (std::size_t i = 0; i < parts.size(); ++i) fuzz::put("dicom/s" + std::to_string(i) + ".dcm", parts[i]);
    fuzz::read_both(dir);
    fuzz::read_both(dir + "/s0.dcm");  // one file of the series named
    return 0;
}
