// The DICOM reader as a module loaded on first use (io/dicom_loader.cpp): GDCM's static
// dictionaries are built only in processes that read DICOM. The module (io/dicom.cpp, the
// library file clfractal_dicom) exports one C entry, clfractal_dicom_module(), returning
// this table. The module is built from the same tree with the same compiler as the
// library, so C++ types cross the boundary, and an InputError thrown inside reaches the
// caller as an InputError.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "io/formats.hpp"

namespace clfractal::io {

/// Changed whenever the table or a signature in it changes: a module of another number
/// is not used.
constexpr int dicom_module_abi = 1;

struct DicomModule {
    int abi;
    Volume (*read_dicom)(const std::string& path, const std::string& series_uid);
    std::unique_ptr<SliceSource> (*open_dicom_slices)(const std::string& path, const std::string& series_uid);
    std::vector<std::string> (*dicom_notes)(const std::string& path, const std::string& series_uid);
};

/// The module's file name, as the loader looks for it beside the library.
constexpr const char* dicom_module_file = "libclfractal_dicom.so";

}  // namespace clfractal::io

/// The module's one entry.
extern "C" const clfractal::io::DicomModule* clfractal_dicom_module();
