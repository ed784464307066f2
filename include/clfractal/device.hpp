// The device layer: device choice, context and queue, the program cache, typed RAII
// buffers and checked kernel launches, all on the Khronos C++ bindings
// (clfractal/opencl.hpp configures them).
#pragma once
#include "clfractal/opencl.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <map>
#include <set>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "clfractal/error.hpp"

namespace clfractal {

/// Name of an OpenCL error code ("CL_OUT_OF_RESOURCES").
const char* cl_error_name(int code);

/// Throws DeviceError "<call>: <CL error name> (<code>)" when code != CL_SUCCESS.
void check_cl(int code, const char* call);

/// One OpenCL device as listed by `clfractal devices`.
struct DeviceEntry {
    std::string platform, name, type;
    std::size_t global_mem = 0, max_alloc = 0;
    unsigned compute_units = 0;
    bool chosen = false;
    cl::Device device;
};

/// Every device of every platform; the one choose_device() picks is marked chosen.
std::vector<DeviceEntry> list_devices();

/// The one rule that picks a device, for CLFRACTAL_DEVICE / CLFRACTAL_DEVICE_TYPE,
/// clf_context_create's filter and the Python `device` argument. `name`, when not empty: a
/// case-insensitive substring of "platform / device" (Context::description()), so of the
/// platform or the device name. `type`, when not empty: cpu, gpu, accelerator or all
/// (case-insensitive). Neither (or type all alone): the first GPU, else the first device.
struct DeviceSelector {
    std::string name;
    std::string type;
};

/// The selector of the environment: CLFRACTAL_DEVICE and CLFRACTAL_DEVICE_TYPE.
DeviceSelector environment_selector();

/// The first device of list_devices() that `selector` picks (`chosen` as listed there).
/// Throws DeviceError (CL_DEVICE_NOT_FOUND) naming the selector and every device when none
/// matches, when the type is none of cpu, gpu, accelerator, all, or when there is no device.
DeviceEntry select_device(const DeviceSelector& selector);

/// select_device(environment_selector()).device.
cl::Device choose_device();

/// Kernel variants (Tuning), chosen per device type and forced by tests.
/// Span counting: one histogram per work-item ("private", CPUs) or work-group histograms
/// with atomics ("atomic", GPUs).
enum class SpanVariant { private_histograms, atomic };
/// Summed-area table scans (sat.hpp): a few work-items scanning whole lines or rows
/// ("sequential", CPUs) or local-memory scans per line ("workgroup", GPUs).
enum class SatVariant { sequential, workgroup };
/// Local-dimension kernels (local.hpp): a few work-items walking whole x-rows ("rows",
/// CPUs) or one work-item per vertex ("vertices", GPUs).
enum class LocalVariant { rows, vertices };
/// Filter kernels (filter.hpp): whole x-rows, 16 columns at a time ("rows", CPUs), one
/// work-item per vertex ("vertices") or the median through local-memory tiles ("tiled", GPUs).
enum class FilterVariant { rows, vertices, tiled };
/// Where count_components_at labels A = {f < s} and C = {f >= s}: on the host (runs along x
/// joined by union-find on every core: CPU devices, where it was measured faster) or on the
/// device (union-find over the runs with atomics: GPUs and other devices).
enum class LabellingPath { host, device };

/// The one name <-> enum mechanism of the library, for the command line, tests and
/// benchmarks: these variants, LabellingPath ("host", "device") and Connectivity, MeshMethod,
/// NoiseKind and SmoothVariant (whose parse_ and _name functions call it).
/// variant_name(SpanVariant::private_histograms) is "private"; parse_variant<E>(name) throws
/// InputError "<what> '<name>': expected one of <the names of E>".
template <class E> const char* variant_name(E v);
template <class E> E parse_variant(const std::string& name);
/// Every value of E, in declaration order (tests walk them).
template <class E> std::vector<E> all_variants();

/// Tuning values per device, in one place: defaults by device type, overridable by tests.
struct Tuning {
    SpanVariant span_variant = SpanVariant::private_histograms;
    std::size_t work_group = 64;     ///< work-group size of the "local" variant
    std::size_t private_items = 0;   ///< work-items of the "private" variant (0 = 4 x CUs)
    /// Largest slab in bytes of input volume; 0 = derived from the device's memory.
    std::size_t slab_bytes = 0;
    /// Read host volumes in place (CL_MEM_USE_HOST_PTR) instead of copying them to a
    /// device buffer: on for CPU devices, whose "device memory" is host memory.
    bool zero_copy = false;
    /// Largest histogram the "atomic" variant keeps in local memory (bytes); larger ones
    /// use global atomics. Set from the device (half its local memory).
    std::size_t local_hist_bytes = 0;
    SatVariant sat_variant = SatVariant::sequential;
    std::size_t sat_work_group = 256;  ///< work-group size of the "workgroup" variant
    LocalVariant local_variant = LocalVariant::rows;
    /// LD fields of host volumes from the tables of 2x2x2 blocks (an eighth of the table
    /// work, the same field bit for bit); tests clear it to compare with the full-size tables.
    bool local_blocks = true;
    FilterVariant filter_variant = FilterVariant::rows;
    /// Work-items of the row-walking variants (sat "sequential", local "rows"); 0 = 4 x CUs.
    std::size_t row_items = 0;
    /// Largest count total kept in 32-bit tables; above it tables are 64-bit. Tests
    /// lower it to force the 64-bit kernels.
    std::uint64_t sat_max_32bit = 0xffffffffu;
    /// Whether programs may use double (-DFP64) on a device with cl_khr_fp64; tests clear
    /// it to check the error a device without the extension gives.
    bool allow_fp64 = true;
    /// Use cl_khr_fp64 where the device has it (fd4.hpp: bins in double on the device);
    /// tests clear it to force the path for devices without it.
    bool use_fp64 = true;
    /// Noise level (noise_level.hpp): blocks through local-memory tiles where they fit; tests
    /// clear it to force the kernel that reads each residual's 27 values from global memory.
    bool noise_tiles = true;
    /// Components of 8/16-bit-range integer data: vertices per window of the windowed
    /// sweeps (the (value, index) order built a window at a time, memory O(window)); 0 = the
    /// whole order at once unless it would pass the memory bound. Tests set it to force windows.
    std::size_t component_window = 0;
    /// Whether the two windowed sweeps run at once, on two threads with a forest each, where
    /// both forests fit the same memory bound as the whole order (a volume of up to ~19 Mi
    /// 8-bit or ~33 Mi 16-bit vertices); else one after the other with one forest. Tests
    /// clear it to force one after the other.
    bool component_sweeps_together = true;
    /// Where count_components_at labels (LabellingPath): host on CPU devices, device
    /// elsewhere. Tests set it to force either path.
    LabellingPath labelling = LabellingPath::host;
    /// The component curve (count_components) in z-slabs counted on every core and joined:
    /// slices between the starts of consecutive slabs, each slab holding one more (shared
    /// with the next); 0 = about 2^20 vertices a slab, at least 8 slices apart, and volumes of
    /// up to 2^21 vertices in one piece. nz - 1 or more: one piece. Tests set it to force thin
    /// slabs and the one piece.
    std::size_t component_slab_slices = 0;
};

namespace detail {
struct FaultState;      // test-only fault injection (host/device/fault_injection.hpp)
struct ContextAccess;   // the library's access to it
}  // namespace detail

/// A context on one device with one in-order queue and a thread-safe program cache.
/// Create once and reuse: every analysis of every volume shares its compiled programs.
class Context {
public:
    explicit Context(cl::Device device);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    /// The process-wide context on choose_device(), created on first use and never destroyed:
    /// no OpenCL object of it is released after main returns (OpenCL runtimes tear down their
    /// own state in exit handlers; releasing after that crashes some of them).
    static Context& shared();
    /// Begins creating shared() on another thread and returns at once, so that a program can
    /// read its input while the OpenCL platform starts (tens of milliseconds on some). shared()
    /// then waits for it and throws what the creation threw. A program that calls this calls
    /// shared() or wait_shared() before it returns from main. Calls after the first do nothing.
    /// The first call also starts the calling thread's OpenMP team before the runtime loads:
    /// threads created while the runtime's libraries load wait for the dynamic loader.
    static void start_shared();
    /// Waits for a creation start_shared() began and discards its error, if any (the error
    /// path of a program that never needed the device); returns at once otherwise.
    static void wait_shared() noexcept;

    const cl::Device& device() const { return device_; }
    const cl::Context& context() const { return context_; }
    cl::CommandQueue& queue() { return queue_; }
    /// "platform / device" for reports.
    std::string description() const;
    bool is_cpu() const;
    std::size_t max_alloc() const { return max_alloc_; }
    std::size_t global_mem() const { return global_mem_; }
    std::size_t max_work_group() const { return max_work_group_; }
    std::size_t local_mem() const { return local_mem_; }
    unsigned compute_units() const { return compute_units_; }
    bool has_fp64() const { return fp64_; }
    /// CL_DEVICE_MEM_BASE_ADDR_ALIGN in bytes: host memory the device reads in place
    /// (CL_MEM_USE_HOST_PTR, DeviceVolume) must start at a multiple of it.
    std::size_t mem_base_align() const { return mem_base_align_; }

    /// Volumes and slabs made visible to the device from host memory so far, by copy or by
    /// zero-copy wrap: one per DeviceVolume built from host values (device_volume.hpp).
    /// Tests count it to check that a pipeline uploads its volume once.
    std::uint64_t uploads() const { return uploads_.load(); }
    void count_upload() { ++uploads_; }

    Tuning tuning;

    /// Program of `family` (kernels/<family>.cl, after kernels/common.cl) built with
    /// `options` (-D defines), compiled once per (family, options) and cached. Build
    /// failures throw DeviceError with the options and the build log. Options with -DFP64
    /// (double values or accumulators) on a device without cl_khr_fp64 (or with
    /// tuning.allow_fp64 cleared) throw InputError naming the extension and `--as float32`.
    const cl::Program& program(const std::string& family, const std::string& options);
    /// A fresh kernel object (kernels carry their arguments, so each caller gets its own).
    cl::Kernel kernel(const std::string& family, const std::string& name, const std::string& options);

    /// Seconds the device spent executing the kernels launched on this context so far, from
    /// their profiling events (CL_PROFILING_COMMAND_START..END); waits for the queue.
    double kernel_seconds();

    /// Seconds spent compiling so far (reported apart from compute time): program builds,
    /// and at the first launch of each (kernel, options, local size) its wall time less the
    /// kernel's own execution (drivers such as PoCL compile for a work-group size there).
    double compile_seconds() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return compile_seconds_;
    }

    /// Enqueues `kernel` after checking the sizes against the device and kernel limits
    /// (global a multiple of local, local <= CL_KERNEL_WORK_GROUP_SIZE and
    /// CL_DEVICE_MAX_WORK_ITEM_SIZES, the kernel's local memory <= CL_DEVICE_LOCAL_MEM_SIZE);
    /// DeviceError naming the limit otherwise. The one launch
    /// path, with the one warm-up: the first launch of each (kernel, program options,
    /// local size) on this context is waited for, and its wall time less the kernel's own
    /// execution (its profiling event) is counted as compilation (compile_seconds), because
    /// PoCL and some GPU drivers finish compiling a kernel for a work-group size at its first
    /// launch. The launch's real work stays in compute time.
    void launch(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local = cl::NullRange);

private:
    void check_launch_limits(const cl::Kernel& kernel, const std::string& name, const cl::NDRange& local) const;
    static double event_seconds(const cl::Event& event);
    void collect_completed_events();

    cl::Device device_;
    cl::Context context_;
    cl::CommandQueue queue_;
    std::size_t max_alloc_ = 0, global_mem_ = 0, max_work_group_ = 0, local_mem_ = 0;
    std::size_t mem_base_align_ = 1;
    std::vector<std::size_t> max_work_item_sizes_;
    unsigned compute_units_ = 0;
    bool fp64_ = false;
    mutable std::mutex mutex_;
    std::map<std::pair<std::string, std::string>, cl::Program> programs_;
    // (program, kernel name, local size) already launched once (warmed up).
    std::set<std::tuple<cl_program, std::string, std::array<std::size_t, 3>>> warmed_;
    double compile_seconds_ = 0;
    double kernel_seconds_ = 0;
    std::vector<cl::Event> pending_events_;  // launched kernels not yet in kernel_seconds_
    std::atomic<std::uint64_t> uploads_{0};
    std::unique_ptr<detail::FaultState> faults_;
    friend struct detail::ContextAccess;
};

/// Releases the programs CLBlast (the dense linear algebra of multi-level fits and
/// correlations) keeps in process-wide caches. Those caches are otherwise released by exit
/// handlers, after OpenCL runtimes such as Oclgrind (and some GPU drivers) have torn down
/// their own state, which crashes or hangs the process at exit. A program that used them
/// calls this before main returns (the command-line tool, the Python module at interpreter
/// exit and clf_context_destroy do); a later use compiles them again. The library's own
/// programs live in contexts: Context::shared() is never released. In a process that never
/// ran such a fit (CLBlast, a module loaded on first use, is then not even loaded) it does
/// nothing.
void release_blas_caches();

/// Seconds from `t` to now (steady clock): the one timing helper.
inline double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// Wall time since construction (or restart) less the compilation done meanwhile
/// (Context::compile_seconds: program builds and the drivers' compilation at first
/// launches, never a kernel's execution): compute time that counts every kernel and
/// transfer of the call and no compilation.
class ComputeTimer {
public:
    explicit ComputeTimer(const Context& ctx) : ctx_(ctx) { restart(); }
    void restart() {
        start_ = std::chrono::steady_clock::now();
        compile0_ = ctx_.compile_seconds();
    }
    double seconds() const {
        return std::max(0.0, seconds_since(start_) - (ctx_.compile_seconds() - compile0_));
    }

private:
    const Context& ctx_;
    std::chrono::steady_clock::time_point start_;
    double compile0_ = 0;
};

/// Builds a -D options string: defines({{"T", "uchar"}, {"WG", "64"}}).
std::string defines(const std::vector<std::pair<std::string, std::string>>& kv);

/// The one buffer allocation path: clCreateBuffer of `bytes` with `flags` (and `host`
/// for CL_MEM_USE_HOST_PTR or CL_MEM_COPY_HOST_PTR). Throws DeviceError naming the size.
cl::Buffer create_buffer(Context& ctx, cl_mem_flags flags, std::size_t bytes, void* host = nullptr);

/// A move-only typed device buffer that knows its element count.
template <class T> class Buffer {
public:
    Buffer() = default;
    Buffer(Context& ctx, std::size_t count, cl_mem_flags flags = CL_MEM_READ_WRITE) : count_(count) {
        if (count == 0) return;
        buffer_ = create_buffer(ctx, flags, count * sizeof(T));
    }
    /// A read-only buffer holding a copy of `values` (CL_MEM_COPY_HOST_PTR).
    Buffer(Context& ctx, const std::vector<T>& values) : count_(values.size()) {
        if (count_ == 0) return;
        buffer_ = create_buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes(), const_cast<T*>(values.data()));
    }
    Buffer(Buffer&&) noexcept = default;
    Buffer& operator=(Buffer&&) noexcept = default;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    std::size_t size() const { return count_; }
    std::size_t bytes() const { return count_ * sizeof(T); }
    const cl::Buffer& get() const { return buffer_; }
    cl::Buffer& get() { return buffer_; }

    void write(cl::CommandQueue& q, const T* src, std::size_t count, std::size_t offset = 0) {
        if (count) q.enqueueWriteBuffer(buffer_, CL_TRUE, offset * sizeof(T), count * sizeof(T), src);
    }
    void read(cl::CommandQueue& q, T* dst, std::size_t count, std::size_t offset = 0) const {
        if (count) q.enqueueReadBuffer(buffer_, CL_TRUE, offset * sizeof(T), count * sizeof(T), dst);
    }
    std::vector<T> to_host(cl::CommandQueue& q) const {
        std::vector<T> v(count_);
        read(q, v.data(), count_);
        return v;
    }
    void fill(cl::CommandQueue& q, T value) {
        if (count_) q.enqueueFillBuffer(buffer_, value, 0, bytes());
    }

private:
    cl::Buffer buffer_;
    std::size_t count_ = 0;
};

/// Runs f() and converts cl::Error into DeviceError with the error's name.
template <class F> decltype(auto) with_cl_errors(F&& f) {
    try {
        return f();
    } catch (const cl::Error& e) {
        check_cl(e.err(), e.what());
        throw;  // unreachable: check_cl throws for every error code
    }
}

/// with_cl_errors(f), then waits for the queue: also when f throws, so that no kernel still
/// reads or writes host memory (CL_MEM_USE_HOST_PTR) the caller frees as the exception
/// unwinds.
template <class F> void with_cl_errors_finished(Context& ctx, F&& f) {
    try {
        with_cl_errors(f);
        ctx.queue().finish();
    } catch (...) {
        try {
            ctx.queue().finish();
        } catch (...) {
        }
        throw;
    }
}

}  // namespace clfractal
