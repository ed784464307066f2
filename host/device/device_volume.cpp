#include "clfractal/device_volume.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace clfractal {

namespace {

bool aligned(const Context& ctx, const void* p) {
    return reinterpret_cast<std::uintptr_t>(p) % ctx.mem_base_align() == 0;
}

// A device buffer of `bytes` (at least one byte: OpenCL refuses empty buffers).
cl::Buffer device_buffer(Context& ctx, std::size_t bytes, cl_mem_flags flags) {
    return create_buffer(ctx, flags, std::max<std::size_t>(bytes, 1));
}

}  // namespace

bool DeviceVolume::in_place(const Context& ctx, const void* data) {
    return ctx.tuning.zero_copy && aligned(ctx, data);
}

DeviceVolume::DeviceVolume(Context& ctx, const void* data, const Dims& dims, ValueType type)
    : ctx_(&ctx), dims_(dims), type_(type) {
    const std::size_t n = bytes();
    with_cl_errors([&] {
        if (n && in_place(ctx, data)) {
            host_ = const_cast<void*>(data);
            buffer_ = create_buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, n, host_);
        } else {
            buffer_ = device_buffer(ctx, n, CL_MEM_READ_ONLY);
            if (n) ctx.queue().enqueueWriteBuffer(buffer_, CL_TRUE, 0, n, data);
        }
    });
    ctx.count_upload();
}

DeviceVolume::DeviceVolume(Context& ctx, const Volume& v) : DeviceVolume(ctx, v.data(), v.dims(), v.type()) {
    spacing = v.spacing;
    name = v.name;
}

DeviceVolume DeviceVolume::allocate(Context& ctx, const Dims& dims, ValueType type) {
    DeviceVolume d;
    d.ctx_ = &ctx;
    d.dims_ = dims;
    d.type_ = type;
    with_cl_errors([&] { d.buffer_ = device_buffer(ctx, d.bytes(), CL_MEM_READ_WRITE); });
    return d;
}

DeviceVolume DeviceVolume::output(Context& ctx, void* data, const Dims& dims, ValueType type) {
    DeviceVolume d;
    d.ctx_ = &ctx;
    d.dims_ = dims;
    d.type_ = type;
    if (d.bytes() == 0 || !in_place(ctx, data)) return allocate(ctx, dims, type);
    d.host_ = data;
    with_cl_errors([&] { d.buffer_ = create_buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, d.bytes(), data); });
    return d;
}

DeviceVolume DeviceVolume::output(Context& ctx, Volume& target) {
    DeviceVolume d = output(ctx, target.data(), target.dims(), target.type());
    d.spacing = target.spacing;
    d.name = target.name;
    return d;
}

DeviceVolume allocate_like(const DeviceVolume& like, ValueType type) {
    DeviceVolume d = DeviceVolume::allocate(like.context(), like.dims(), type);
    d.spacing = like.spacing;
    d.name = like.name;
    return d;
}

DeviceVolume::~DeviceVolume() {
    if (!host_ || !ctx_) return;
    try {
        ctx_->queue().finish();
    } catch (...) {
        // destructors never throw; the error surfaces at the next queue call
    }
}

DeviceVolume::DeviceVolume(DeviceVolume&& o) noexcept
    : spacing(o.spacing), name(std::move(o.name)), ctx_(o.ctx_), dims_(o.dims_), type_(o.type_),
      buffer_(std::move(o.buffer_)), host_(std::exchange(o.host_, nullptr)) {}

DeviceVolume& DeviceVolume::operator=(DeviceVolume&& o) noexcept {
    if (this == &o) return *this;
    if (host_ && ctx_) {
        try {
            ctx_->queue().finish();
        } catch (...) {
        }
    }
    spacing = o.spacing;
    name = std::move(o.name);
    ctx_ = o.ctx_;
    dims_ = o.dims_;
    type_ = o.type_;
    buffer_ = std::move(o.buffer_);
    host_ = std::exchange(o.host_, nullptr);
    return *this;
}

void DeviceVolume::download(void* dst) const {
    const std::size_t n = bytes();
    if (n == 0) return;
    with_cl_errors([&] {
        cl::CommandQueue& q = ctx_->queue();
        if (host_) {
            // Mapping makes the device's writes visible in host memory (a no-op on CPUs).
            void* p = q.enqueueMapBuffer(buffer_, CL_TRUE, CL_MAP_READ, 0, n);
            if (dst != host_) std::memcpy(dst, p, n);
            q.enqueueUnmapMemObject(buffer_, p);
            q.finish();
        } else {
            q.enqueueReadBuffer(buffer_, CL_TRUE, 0, n, dst);
        }
    });
}

void DeviceVolume::download_to(Volume& target) const {
    if (target.dims() != dims_ || target.type() != type_)
        throw std::logic_error("DeviceVolume::download_to: the target is not " + dims_string(dims_) + " " +
                               value_type_name(type_));
    download(target.data());
}

Volume DeviceVolume::download() const {
    Volume v(dims_, type_, name);
    v.spacing = spacing;
    download(v.data());
    return v;
}

}  // namespace clfractal
