// Bounds shared by the format readers (see input_guard.hpp).
#include "io/input_guard.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "clfractal/error.hpp"

namespace clfractal::io {

namespace {

const char* kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a plain file";
}

}  // namespace

std::uint64_t regular_file_size(const std::string& file, const std::string& name) {
    struct stat st {};
    // "x.nii: ..." for the input itself, "x.mhd: data file 'x.raw' ..." for a file it names.
    const std::string prefix = file == name ? printable(file) + ":" : printable(name) + ": data file " + quote_input(file, 200);
    if (::stat(file.c_str(), &st) != 0)
        throw InputError(prefix + (errno != ENOENT ? std::string(" cannot be opened: ") + std::strerror(errno)
                                   : file == name ? " no such file" : " does not exist"));
    if (!S_ISREG(st.st_mode)) throw InputError(prefix + (file == name ? " not" : " is not") + " a regular file (" + kind_of(st.st_mode) + ")");
    return std::uint64_t(st.st_size);
}

void check_claim(const std::string& name, const std::string& what, const std::string& layout, std::uint64_t claimed,
                 std::uint64_t available, std::uint64_t ratio) {
    if (ratio <= 1) {
        if (claimed <= available) return;
        throw InputError(printable(name) + ": truncated: " + layout + " is " + std::to_string(claimed) +
                         " bytes, but only " + std::to_string(available) + " are there (" + what + ")");
    }
    if (available > 0 && claimed / ratio <= available) return;
    throw InputError(printable(name) + ": " + layout + " is " + std::to_string(claimed) + " bytes, more than " +
                     std::to_string(available) + " compressed bytes (" + what + ") can expand to (at most " +
                     std::to_string(ratio) + ":1)");
}

std::string quote_input(const std::string& text, std::size_t keep) {
    return "'" + printable(text.size() > keep ? text.substr(0, keep) + "..." : text) + "'";
}

}  // namespace clfractal::io
