// Typed kernel calls: the one way the library sets kernel arguments and launches (through
// Context::launch, which checks the sizes against the device). Private to the library.
#pragma once
#include <utility>

#include "clfractal/device.hpp"

namespace clfractal {

/// Sets argument `index` of `k` (the generic case: buffers, scalars, cl::Local). Types
/// with their own layout (e.g. an isovalue of the data's type) overload it.
template <class T> void set_kernel_arg(cl::Kernel& k, cl_uint index, const T& value) { k.setArg(index, value); }

/// A kernel with its argument list in its type (a typed kernel call):
///   KernelCall<cl::Buffer, int, int, cl::Buffer> sub(ctx, "pyramid", "subsample", options);
///   sub(global, local, src, nx, ny, dst);
/// A call sets every argument in order and launches through Context::launch (size checks,
/// warm-up); a kernel that gains a parameter needs its KernelCall type changed, and every
/// call with the old list stops compiling.
template <class... Args> class KernelCall {
public:
    KernelCall() = default;
    KernelCall(Context& ctx, const std::string& family, const std::string& name, const std::string& options)
        : ctx_(&ctx), kernel_(ctx.kernel(family, name, options)) {}

    void operator()(const cl::NDRange& global, const cl::NDRange& local, const Args&... args) {
        set(std::index_sequence_for<Args...>{}, args...);
        ctx_->launch(kernel_, global, local);
    }
    /// CL_KERNEL_WORK_GROUP_SIZE of this kernel on the context's device.
    std::size_t work_group_limit() const {
        return kernel_.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(ctx_->device());
    }

private:
    template <std::size_t... I> void set(std::index_sequence<I...>, const Args&... args) {
        (set_kernel_arg(kernel_, cl_uint(I), args), ...);
    }
    Context* ctx_ = nullptr;
    cl::Kernel kernel_;
};

}  // namespace clfractal
