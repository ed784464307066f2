// The DICOM reader's entries in the library: each loads the module clfractal_dicom
// (io/dicom_module.hpp) on first use and calls it. The module is looked for beside the
// library file holding this code (the build tree, the install lib dir, the Python
// package), then in the install lib dir. Without it, reading DICOM is an InputError
// "FILE: cannot read DICOM: DICOM support is missing (why)"; nothing else needs it.
#include <dlfcn.h>

#include <filesystem>
#include <string>

#include "clfractal/error.hpp"
#include "io/dicom_module.hpp"

namespace fs = std::filesystem;

namespace clfractal::io {
namespace {

/// The directory of the library (or executable) this code was linked into.
std::string own_directory() {
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&own_directory), &info) == 0 || !info.dli_fname) return {};
    const fs::path dir = fs::path(info.dli_fname).parent_path();
    return dir.empty() ? "." : dir.string();
}

/// The module, loaded once by the first caller (a function-local static: thread-safe).
struct Loaded {
    const DicomModule* module = nullptr;
    std::string why;  // what every attempt said, when none gave a module
};

/// Opens `file` and checks its table; false with the reason added to `why` otherwise.
bool try_open(const std::string& file, Loaded& out) {
    void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    std::string reason;
    if (!handle) {
        const char* e = dlerror();
        reason = e ? e : file + ": cannot be loaded";
    } else if (auto entry = reinterpret_cast<const DicomModule* (*)()>(dlsym(handle, "clfractal_dicom_module"))) {
        const DicomModule* m = entry();
        if (m && m->abi == dicom_module_abi) {
            out.module = m;  // kept loaded for the life of the process
            return true;
        }
        reason = file + ": module ABI " + std::to_string(m ? m->abi : 0) + ", expected " +
                 std::to_string(dicom_module_abi);
        dlclose(handle);
    } else {
        reason = file + ": no clfractal_dicom_module entry";
        dlclose(handle);
    }
    out.why += (out.why.empty() ? "" : "; ") + reason;
    return false;
}

Loaded load() {
    Loaded out;
    const std::string own = own_directory(), installed = CLFRACTAL_INSTALL_LIBDIR;
    if (!own.empty() && try_open((fs::path(own) / dicom_module_file).string(), out)) return out;
    if (installed != own && try_open((fs::path(installed) / dicom_module_file).string(), out)) return out;
    if (out.why.empty()) out.why = std::string(dicom_module_file) + ": not found";
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
