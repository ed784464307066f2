// Errors thrown by clfractal. Front ends map InputError to exit code 2 and
// everything else to exit code 1.
#pragma once
#include <stdexcept>
#include <string>

namespace clfractal {

/// `text` with every control character (a byte below 0x20, or 0x7f) replaced by '?': for
/// messages that quote input (file names, header lines), so that none reaches a terminal.
inline std::string printable(std::string text) {
    for (char& c : text)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    return text;
}

/// Bad input: a malformed or truncated file, wrong dimensions, NaN in float data,
/// an unknown type, an absurd size or an invalid argument. The message names the
/// file (or argument) and the problem in one line.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A host allocation that failed: bad input to the command-line tool (exit code 2), but
/// told apart from other bad input by the C ABI (CLF_ERROR_OUT_OF_MEMORY).
class HostOutOfMemory : public InputError {
public:
    using InputError::InputError;
};

/// A failure of the OpenCL runtime: the message carries the OpenCL error name,
/// the call that failed and, for build failures, the build log.
class DeviceError : public std::runtime_error {
public:
    DeviceError(const std::string& what, int code) : std::runtime_error(what), code_(code) {}
    int code() const { return code_; }
    /// True for CL_MEM_OBJECT_ALLOCATION_FAILURE, CL_OUT_OF_HOST_MEMORY and
    /// CL_INVALID_BUFFER_SIZE: the input is too large for the device, not a fault.
    /// (CL_OUT_OF_RESOURCES is also how some drivers report a failed kernel: a runtime failure.)
    bool out_of_memory() const { return code_ == -4 || code_ == -6 || code_ == -61; }

private:
    int code_;
};

}  // namespace clfractal
