// Modules loaded on first use (device/module_loader.hpp).
#include "device/module_loader.hpp"

#include <dlfcn.h>

#include <filesystem>

namespace fs = std::filesystem;

namespace clfractal::detail {

std::vector<std::string> module_paths(const char* file, const void* anchor) {
    std::vector<std::string> paths;
    Dl_info info{};
    std::string own;
    if (dladdr(anchor, &info) != 0 && info.dli_fname) {
        const fs::path dir = fs::path(info.dli_fname).parent_path();
        own = dir.empty() ? "." : dir.string();
        paths.push_back((fs::path(own) / file).string());
    }
    const std::string installed = CLFRACTAL_INSTALL_LIBDIR;
    if (installed != own) paths.push_back((fs::path(installed) / file).string());
    return paths;
}

void* open_entry(const std::string& path, const char* entry, void*& handle, std::string& why) {
    handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    std::string reason;
    if (!handle) {
        const char* e = dlerror();
        reason = e ? e : path + ": cannot be loaded";
    } else if (void* symbol = dlsym(handle, entry)) {
        return symbol;
    } else {
        reason = path + ": no " + entry + " entry";
        dlclose(handle);
    }
    handle = nullptr;
    why += (why.empty() ? "" : "; ") + reason;
    return nullptr;
}

void refuse_module(void* handle, const std::string& path, int abi, int expected, std::string& why) {
    why += (why.empty() ? "" : "; ") + path + ": module ABI " + std::to_string(abi) + ", expected " +
           std::to_string(expected);
    dlclose(handle);
}

}  // namespace clfractal::detail
