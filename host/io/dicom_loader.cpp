// The DICOM reader's entries in the library: each loads the module clfractal_dicom
// (io/dicom_module.hpp) on first use and calls it. The module is looked for beside the
// library file holding this code (the build tree, the install lib dir, the Python
// package), then in the install lib dir. Without it, reading DICOM is an InputError
// "FILE: cannot read DICOM: DICOM support is missing (why)"; nothing else needs it.
#include <string>

#include "clfractal/error.hpp"
#include "device/module_loader.hpp"
#include "io/dicom_module.hpp"

namespace clfractal::io {
namespace {

/// The module, loaded once by the first caller (a function-local static: thread-safe).
struct Loaded {
    const DicomModule* module = nullptr;
    std::string why;  // what every attempt said, when none gave a module
};

Loaded load() {
    Loaded out;
    out.module = detail::load_module<DicomModule>(dicom_module_file, "clfractal_dicom_module", dicom_module_abi,
                                                  reinterpret_cast<const void*>(&load), out.why);
    return out;
}

const DicomModule& module_for(const std::string& path) {
    static const Loaded loaded = load();
    if (!loaded.module) throw InputError(path + ": cannot read DICOM: DICOM support is missing (" + loaded.why + ")");
    return *loaded.module;
}

}  // namespace

Volume read_dicom(const std::string& path, const std::string& series_uid) {
    return module_for(path).read_dicom(path, series_uid);
}

std::unique_ptr<SliceSource> open_dicom_slices(const std::string& path, const std::string& series_uid) {
    return module_for(path).open_dicom_slices(path, series_uid);
}

std::vector<std::string> dicom_notes(const std::string& path, const std::string& series_uid) {
    return module_for(path).dicom_notes(path, series_uid);
}

}  // namespace clfractal::io
