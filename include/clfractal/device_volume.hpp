// A volume on the device (docs/definitions.md §29 "Devices and uploads": Volume → DeviceVolume
// (one upload) → kernels → small results or device fields → download only what the caller
// asks for).
//
// The one place host memory is made visible to kernels and read back. Built from host values
// it is an upload, counted by Context::uploads(): zero-copy (CL_MEM_USE_HOST_PTR, the host
// memory itself) where Tuning::zero_copy says the device shares host memory and the host
// pointer is aligned to CL_DEVICE_MEM_BASE_ADDR_ALIGN, else one copy into a device buffer.
// Every capability takes a `const DeviceVolume&`; its `Volume` overload uploads and calls it.
#pragma once
#include <array>
#include <cstddef>
#include <string>

#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

class DeviceVolume {
public:
    DeviceVolume() = default;
    /// Uploads `v` (dims, type, spacing and name come along). Zero-copy keeps a reference to
    /// v's memory: `v` must outlive this object and stay unchanged while kernels read it.
    DeviceVolume(Context& ctx, const Volume& v);
    /// Not from a temporary: a zero-copy upload would read freed memory.
    DeviceVolume(Context& ctx, Volume&& v) = delete;
    /// Uploads the `dims.vertices()` values of `type` at `data` (e.g. a z-slab of a larger
    /// volume), with the same zero-copy rule and lifetime as above.
    DeviceVolume(Context& ctx, const void* data, const Dims& dims, ValueType type);
    /// A device volume of `dims` and `type` for results (contents undefined); no upload.
    static DeviceVolume allocate(Context& ctx, const Dims& dims, ValueType type);
    /// A result whose values are to end in `target` (its dims and type): with zero-copy the
    /// kernels write target's memory directly; download_to(target) then only makes the writes
    /// visible, else it reads the device copy. `target` must outlive this object.
    static DeviceVolume output(Context& ctx, Volume& target);
    /// The same for the `dims.vertices()` values of `type` at `data` (e.g. a z-slab).
    static DeviceVolume output(Context& ctx, void* data, const Dims& dims, ValueType type);
    /// Waits for the queue when the buffer is host memory (no kernel may still use it).
    ~DeviceVolume();
    DeviceVolume(DeviceVolume&& o) noexcept;
    DeviceVolume& operator=(DeviceVolume&& o) noexcept;
    DeviceVolume(const DeviceVolume&) = delete;
    DeviceVolume& operator=(const DeviceVolume&) = delete;

    Context& context() const { return *ctx_; }
    const Dims& dims() const { return dims_; }
    ValueType type() const { return type_; }
    std::size_t vertices() const { return dims_.vertices(); }
    std::size_t bytes() const { return dims_.vertices() * value_size(type_); }
    /// The values, x fastest.
    const cl::Buffer& buffer() const { return buffer_; }
    /// True when buffer() is host memory read in place (zero-copy).
    bool in_host_memory() const { return host_ != nullptr; }
    /// Whether a volume of (at least one byte of) host memory at `data` would use that memory
    /// in place, as input or output() target: Tuning::zero_copy and `data` aligned to
    /// CL_DEVICE_MEM_BASE_ADDR_ALIGN.
    static bool in_place(const Context& ctx, const void* data);

    /// The values as a new host Volume with this volume's dims, type, spacing and name.
    Volume download() const;
    /// The values into `target` (same dims and type; spacing and name are left alone).
    void download_to(Volume& target) const;
    /// The values into `bytes()` bytes at `dst` (for an output() volume: its own memory).
    void download(void* dst) const;

    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    std::string name;

private:
    Context* ctx_ = nullptr;
    Dims dims_{};
    ValueType type_ = ValueType::uint8;
    cl::Buffer buffer_;
    void* host_ = nullptr;  // the host memory of a zero-copy buffer
};

/// A result volume of `like`'s dims and spacing and of type `type`, on the device; no upload.
DeviceVolume allocate_like(const DeviceVolume& like, ValueType type);

}  // namespace clfractal
