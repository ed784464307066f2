// libFuzzer target: NIfTI-1/2 through both readers (read_volume and SliceReader), stored
// values and --scaled. The input is one file (f.nii, or f.nii.gz when it starts with the
// gzip magic), or "HEADER@@IMG@@DATA": an ANALYZE/NIfTI pair f.hdr + f.img.
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::vector<std::string> parts = fuzz::pieces(input, "@@IMG@@", 2);
    std::string path;
    const std::string dir = fuzz::fresh("nifti");
    if (parts.size() == 2) {
        fuzz::put("nifti/f.img", parts[1]);
        path = fuzz::put("nifti/f.hdr", parts[0]);
    } else {
        const bool gz = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
        path = fuzz::put(gz ? "nifti/f.nii.gz" : "nifti/f.nii", input);
    }
    fuzz::read_both(path);
    clfractal::RawOptions scaled;
    scaled.scaled = true;
    fuzz::read_both(path, scaled);
    return 0;
}
