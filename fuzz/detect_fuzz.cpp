// libFuzzer target: format detection by content and the reader it picks. The first byte
// chooses the file's name (extension), the rest is the file; read_volume and SliceReader
// read it, and describe_volume_file (clfractal info's format lines) describes it.
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* names[] = {"f",     "f.nrrd", "f.nhdr", "f.nii", "f.nii.gz", "f.hdr", "f.img",  "f.dcm",
                                  "f.tif", "f.tiff", "f.mha",  "f.mhd", "f.gz",     "f.raw", "f_4x4x4_uint8.raw",
                                  "f.dat"};
    const std::string name = names[data[0] % (sizeof names / sizeof names[0])];
    fuzz::fresh("detect");
    const std::string path = fuzz::put("detect/" + name, reinterpret_cast<const char*>(data) + 1, size - 1);
    if (name == "f.img") fuzz::put("detect/f.hdr", reinterpret_cast<const char*>(data) + 1, size - 1);
    fuzz::read_both(path);
    try {
        clfractal::describe_volume_file(path, {});
    } catch (const clfractal::InputError& e) {
        fuzz::check_message(e.what());
    }
    return 0;
}
