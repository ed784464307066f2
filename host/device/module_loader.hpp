// Modules: parts of the library in files of their own (clfractal_dicom, clfractal_blas),
// opened with dlopen on first use so that a process pays for their libraries' start-up only
// when it needs them. Each exports one C entry returning its table, whose member `abi` is the
// number it was built with; the module is built from the same tree with the same compiler as
// the library, so C++ types may cross the boundary.
#pragma once
#include <string>
#include <vector>

namespace clfractal::detail {

/// Where module `file` is looked for, in order: beside the library file holding `anchor` (an
/// address in the calling library: the build tree, the install lib dir, the Python package),
/// then in the install lib dir.
std::vector<std::string> module_paths(const char* file, const void* anchor);
/// dlopen(path) and its symbol `entry`; nullptr, with the reason added to `why` and the file
/// closed again, when either fails. `handle` is the open file.
void* open_entry(const std::string& path, const char* entry, void*& handle, std::string& why);
/// Closes a file whose table was refused, with the reason added to `why`.
void refuse_module(void* handle, const std::string& path, int abi, int expected, std::string& why);

/// The table of the first of module_paths(file, anchor) whose `entry` gives one of ABI `abi`;
/// nullptr, with what every attempt said in `why`, when none does. A module found stays
/// loaded for the life of the process.
template <class Table>
const Table* load_module(const char* file, const char* entry, int abi, const void* anchor, std::string& why) {
    for (const std::string& path : module_paths(file, anchor)) {
        void* handle = nullptr;
        void* symbol = open_entry(path, entry, handle, why);
        if (!symbol) continue;
        const Table* table = reinterpret_cast<const Table* (*)()>(symbol)();
        if (table && table->abi == abi) return table;
        refuse_module(handle, path, table ? table->abi : 0, abi, why);
    }
    if (why.empty()) why = std::string(file) + ": not found";
    return nullptr;
}

}  // namespace clfractal::detail
