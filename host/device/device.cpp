#include "clfractal/device.hpp"

#include <omp.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <csignal>
#include <cstring>
#include <future>
#include <iostream>
#include <sstream>

#include "device/fault_injection.hpp"
#include "device/kernel_sources.hpp"
#include "device/name_table.hpp"
#include "device/program_cache.hpp"

namespace clfractal {

const char* cl_error_name(int code) {
    switch (code) {
#define CLF_ERR(x) case x: return #x;
        CLF_ERR(CL_SUCCESS) CLF_ERR(CL_DEVICE_NOT_FOUND) CLF_ERR(CL_DEVICE_NOT_AVAILABLE)
        CLF_ERR(CL_COMPILER_NOT_AVAILABLE) CLF_ERR(CL_MEM_OBJECT_ALLOCATION_FAILURE)
        CLF_ERR(CL_OUT_OF_RESOURCES) CLF_ERR(CL_OUT_OF_HOST_MEMORY)
        CLF_ERR(CL_PROFILING_INFO_NOT_AVAILABLE) CLF_ERR(CL_MEM_COPY_OVERLAP)
        CLF_ERR(CL_IMAGE_FORMAT_MISMATCH) CLF_ERR(CL_IMAGE_FORMAT_NOT_SUPPORTED)
        CLF_ERR(CL_BUILD_PROGRAM_FAILURE) CLF_ERR(CL_MAP_FAILURE)
        CLF_ERR(CL_MISALIGNED_SUB_BUFFER_OFFSET) CLF_ERR(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
        CLF_ERR(CL_COMPILE_PROGRAM_FAILURE) CLF_ERR(CL_LINKER_NOT_AVAILABLE)
        CLF_ERR(CL_LINK_PROGRAM_FAILURE) CLF_ERR(CL_DEVICE_PARTITION_FAILED)
        CLF_ERR(CL_KERNEL_ARG_INFO_NOT_AVAILABLE) CLF_ERR(CL_INVALID_VALUE)
        CLF_ERR(CL_INVALID_DEVICE_TYPE) CLF_ERR(CL_INVALID_PLATFORM) CLF_ERR(CL_INVALID_DEVICE)
        CLF_ERR(CL_INVALID_CONTEXT) CLF_ERR(CL_INVALID_QUEUE_PROPERTIES)
        CLF_ERR(CL_INVALID_COMMAND_QUEUE) CLF_ERR(CL_INVALID_HOST_PTR) CLF_ERR(CL_INVALID_MEM_OBJECT)
        CLF_ERR(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR) CLF_ERR(CL_INVALID_IMAGE_SIZE)
        CLF_ERR(CL_INVALID_SAMPLER) CLF_ERR(CL_INVALID_BINARY) CLF_ERR(CL_INVALID_BUILD_OPTIONS)
        CLF_ERR(CL_INVALID_PROGRAM) CLF_ERR(CL_INVALID_PROGRAM_EXECUTABLE)
        CLF_ERR(CL_INVALID_KERNEL_NAME) CLF_ERR(CL_INVALID_KERNEL_DEFINITION) CLF_ERR(CL_INVALID_KERNEL)
        CLF_ERR(CL_INVALID_ARG_INDEX) CLF_ERR(CL_INVALID_ARG_VALUE) CLF_ERR(CL_INVALID_ARG_SIZE)
        CLF_ERR(CL_INVALID_KERNEL_ARGS) CLF_ERR(CL_INVALID_WORK_DIMENSION)
        CLF_ERR(CL_INVALID_WORK_GROUP_SIZE) CLF_ERR(CL_INVALID_WORK_ITEM_SIZE)
        CLF_ERR(CL_INVALID_GLOBAL_OFFSET) CLF_ERR(CL_INVALID_EVENT_WAIT_LIST) CLF_ERR(CL_INVALID_EVENT)
        CLF_ERR(CL_INVALID_OPERATION) CLF_ERR(CL_INVALID_GL_OBJECT) CLF_ERR(CL_INVALID_BUFFER_SIZE)
        CLF_ERR(CL_INVALID_MIP_LEVEL) CLF_ERR(CL_INVALID_GLOBAL_WORK_SIZE) CLF_ERR(CL_INVALID_PROPERTY)
        CLF_ERR(CL_INVALID_IMAGE_DESCRIPTOR) CLF_ERR(CL_INVALID_COMPILER_OPTIONS)
        CLF_ERR(CL_INVALID_LINKER_OPTIONS) CLF_ERR(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef CLF_ERR
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "unknown OpenCL error";
    }
}

void check_cl(int code, const char* call) {
    if (code == CL_SUCCESS) return;
    std::ostringstream s;
    s << call << ": " << cl_error_name(code) << " (" << code << ")";
    throw DeviceError(s.str(), code);
}

template <> struct detail::NameTable<SpanVariant> {
    static constexpr const char* what = "span variant";
    static constexpr std::pair<SpanVariant, const char*> names[] = {{SpanVariant::private_histograms, "private"},
                                                                    {SpanVariant::atomic, "atomic"}};
};
template <> struct detail::NameTable<SatVariant> {
    static constexpr const char* what = "summed-area table variant";
    static constexpr std::pair<SatVariant, const char*> names[] = {{SatVariant::sequential, "sequential"},
                                                                   {SatVariant::workgroup, "workgroup"}};
};
template <> struct detail::NameTable<LocalVariant> {
    static constexpr const char* what = "local-dimension variant";
    static constexpr std::pair<LocalVariant, const char*> names[] = {{LocalVariant::rows, "rows"},
                                                                     {LocalVariant::vertices, "vertices"}};
};
template <> struct detail::NameTable<FilterVariant> {
    static constexpr const char* what = "filter variant";
    static constexpr std::pair<FilterVariant, const char*> names[] = {
        {FilterVariant::rows, "rows"}, {FilterVariant::vertices, "vertices"}, {FilterVariant::tiled, "tiled"}};
};
template <> struct detail::NameTable<LabellingPath> {
    static constexpr const char* what = "labelling path";
    static constexpr std::pair<LabellingPath, const char*> names[] = {{LabellingPath::host, "host"},
                                                                      {LabellingPath::device, "device"}};
};

CLFRACTAL_NAME_TABLE(SpanVariant)
CLFRACTAL_NAME_TABLE(SatVariant)
CLFRACTAL_NAME_TABLE(LocalVariant)
CLFRACTAL_NAME_TABLE(FilterVariant)
CLFRACTAL_NAME_TABLE(LabellingPath)

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

std::string type_name(cl_device_type t) {
    if (t & CL_DEVICE_TYPE_GPU) return "gpu";
    if (t & CL_DEVICE_TYPE_CPU) return "cpu";
    if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
    return "other";
}

std::vector<DeviceEntry> enumerate() {
    std::vector<cl::Platform> platforms;
    try {
        cl::Platform::get(&platforms);
    } catch (const cl::Error& e) {
        if (e.err() != -1001) throw;  // CL_PLATFORM_NOT_FOUND_KHR: no ICD, an empty list
    }
    std::vector<DeviceEntry> out;
    for (auto& p : platforms) {
        std::vector<cl::Device> devices;
        try {
            p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
        } catch (const cl::Error&) {
            continue;  // a platform without devices
        }
        for (auto& d : devices) {
            DeviceEntry e;
            e.platform = p.getInfo<CL_PLATFORM_NAME>();
            e.name = d.getInfo<CL_DEVICE_NAME>();
            e.type = type_name(d.getInfo<CL_DEVICE_TYPE>());
            e.global_mem = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
            e.max_alloc = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
            e.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
            e.device = d;
            out.push_back(std::move(e));
        }
    }
    return out;
}

bool valid_type(const std::string& type) {
    return type.empty() || type == "cpu" || type == "gpu" || type == "accelerator" || type == "all";
}

// "device 'x' of type 'gpu'", "device 'x'" or "type 'gpu'".
std::string describe(const DeviceSelector& s) {
    std::string out;
    if (!s.name.empty()) out = "device '" + s.name + "'";
    if (!s.type.empty()) out += (out.empty() ? "type '" : " of type '") + s.type + "'";
    return out;
}

// Index of the device `s` picks among `all`, or -1 with `why` set.
long pick(const std::vector<DeviceEntry>& all, const DeviceSelector& s, std::string& why) {
    const std::string name = lower(s.name), type = lower(s.type);
    if (!valid_type(type)) {
        why = "device type '" + s.type + "': expected one of cpu, gpu, accelerator, all";
        return -1;
    }
    const bool any_type = type.empty() || type == "all";
    if (name.empty() && any_type)
        for (std::size_t i = 0; i < all.size(); ++i)
            if (all[i].type == "gpu") return long(i);
    for (std::size_t i = 0; i < all.size(); ++i) {
        const DeviceEntry& e = all[i];
        if ((any_type || e.type == type) && lower(e.platform + " / " + e.name).find(name) != std::string::npos)
            return long(i);
    }
    if (all.empty()) {
        why = "no OpenCL platform or device found (is an ICD such as pocl-opencl-icd installed?)";
        return -1;
    }
    std::string devices;
    for (const DeviceEntry& e : all)
        devices += (devices.empty() ? "" : ", ") + e.platform + " / " + e.name + " (" + e.type + ")";
    why = "no OpenCL device matches " + describe(s) + " (devices: " + devices + ")";
    return -1;
}

std::string environment(const char* variable) {
    const char* value = std::getenv(variable);
    return value ? value : "";
}

}  // namespace

DeviceSelector environment_selector() {
    return {environment("CLFRACTAL_DEVICE"), environment("CLFRACTAL_DEVICE_TYPE")};
}

std::vector<DeviceEntry> list_devices() {
    return with_cl_errors([] {
        auto all = enumerate();
        std::string why;
        long i = pick(all, environment_selector(), why);
        if (i >= 0) all[std::size_t(i)].chosen = true;
        return all;
    });
}

DeviceEntry select_device(const DeviceSelector& selector) {
    std::vector<DeviceEntry> all = list_devices();
    std::string why;
    const long i = pick(all, selector, why);
    if (i < 0) throw DeviceError(why, CL_DEVICE_NOT_FOUND);
    return all[std::size_t(i)];
}

cl::Device choose_device() { return select_device(environment_selector()).device; }

struct detail::FaultState {
    mutable std::mutex mutex;
    FaultPlan plan;
    std::atomic<bool> on{false};
};

struct detail::ContextAccess {
    static FaultState& faults(const Context& ctx) { return *ctx.faults_; }
};

Context::Context(cl::Device device) : device_(std::move(device)), faults_(new detail::FaultState) {
    with_cl_errors([&] {
        context_ = cl::Context(device_);
        queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
        max_alloc_ = device_.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
        global_mem_ = device_.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
        max_work_group_ = device_.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
        local_mem_ = device_.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
        max_work_item_sizes_ = device_.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
        compute_units_ = device_.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
        fp64_ = device_.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
        mem_base_align_ = std::max<std::size_t>(1, device_.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8);
    });
    tuning.span_variant = is_cpu() ? SpanVariant::private_histograms : SpanVariant::atomic;
    tuning.local_hist_bytes = local_mem_ / 2;
    tuning.zero_copy = is_cpu();
    tuning.work_group = std::min<std::size_t>(256, max_work_group_);
    tuning.sat_variant = is_cpu() ? SatVariant::sequential : SatVariant::workgroup;
    tuning.local_variant = is_cpu() ? LocalVariant::rows : LocalVariant::vertices;
    tuning.filter_variant = is_cpu() ? FilterVariant::rows : FilterVariant::tiled;
    tuning.labelling = is_cpu() ? LabellingPath::host : LabellingPath::device;
    tuning.sat_work_group = std::min<std::size_t>(256, max_work_group_);
}

Context::~Context() = default;

namespace {

// The creation start_shared() began, until shared() takes it.
struct SharedStart {
    std::mutex mutex;
    bool begun = false;
    std::future<Context*> creation;
};

SharedStart& shared_start() {
    static SharedStart* const s = new SharedStart;  // never destroyed, like the context
    return *s;
}

// Restores, when it goes, the calling thread's signal stack as it was when it came.
class SignalStackKept {
public:
    SignalStackKept() : saved_(sigaltstack(nullptr, &before_) == 0) {}
    ~SignalStackKept() {
        if (saved_) sigaltstack(&before_, nullptr);
    }
    SignalStackKept(const SignalStackKept&) = delete;
    SignalStackKept& operator=(const SignalStackKept&) = delete;

private:
    stack_t before_{};
    bool saved_;
};

// Starts the calling thread's OpenMP team (its threads then wait for work). A thread created
// while the dynamic loader maps the OpenCL runtime's libraries waits for the loader's lock, so
// the first parallel region run beside the start (fd's value range and histogram) waited
// ~11 ms for the start on PoCL when its team began there; begun before, it costs ~0.05 ms.
void start_openmp_team() {
#pragma omp parallel
    {
        volatile int started = omp_get_thread_num();
        (void)started;
    }
}

// The started creation, if one is pending (taken once); from here on start_shared() does
// nothing.
std::future<Context*> take_started() {
    SharedStart& s = shared_start();
    std::lock_guard<std::mutex> lock(s.mutex);
    s.begun = true;
    return std::move(s.creation);
}

}  // namespace

void Context::start_shared() {
    SharedStart& s = shared_start();
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.begun) return;
    s.begun = true;
    start_openmp_team();
    s.creation = std::async(std::launch::async, [] {
        // The OpenCL runtime may give the thread that starts it a signal stack of its own
        // (PoCL's LLVM does); the thread leaves with the one it came with, so that its exit
        // frees only what it set up itself (AddressSanitizer unmaps the thread's signal stack).
        SignalStackKept kept;
        return new Context(choose_device());
    });
}

void Context::wait_shared() noexcept {
    try {
        SharedStart& s = shared_start();
        std::unique_lock<std::mutex> lock(s.mutex);
        if (!s.creation.valid()) return;
        lock.unlock();
        shared();
    } catch (...) {
        // The program failed before it needed the device; the creation's error is not its.
    }
}

Context& Context::shared() {
    // Deliberately never destroyed. OpenCL runtimes tear down their own state in exit
    // handlers (Oclgrind's, NVIDIA's), and a program, queue or context released after that
    // crashes or hangs the process ("corrupted double-linked list" on Oclgrind). So no
    // OpenCL object of the shared context is released after main returns: the process's exit
    // returns its memory, and the pointer stays reachable (no leak report).
    static Context* const ctx = [] {
        std::future<Context*> started = take_started();
        return started.valid() ? started.get() : new Context(choose_device());
    }();
    return *ctx;
}

std::string Context::description() const {
    return with_cl_errors([&] {
        cl::Platform p(device_.getInfo<CL_DEVICE_PLATFORM>());
        return p.getInfo<CL_PLATFORM_NAME>() + " / " + device_.getInfo<CL_DEVICE_NAME>();
    });
}

bool Context::is_cpu() const { return (device_.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0; }

cl::Buffer create_buffer(Context& ctx, cl_mem_flags flags, std::size_t bytes, void* host) {
    if (bytes > ctx.max_alloc())
        throw DeviceError("clCreateBuffer of " + std::to_string(bytes) + " bytes: more than the device's "
                          "CL_DEVICE_MAX_MEM_ALLOC_SIZE " + std::to_string(ctx.max_alloc()),
                          CL_INVALID_BUFFER_SIZE);
    try {
        fault_point(ctx, FaultSite::allocation);
        return cl::Buffer(ctx.context(), flags, bytes, host);
    } catch (const cl::Error& e) {
        check_cl(e.err(), ("clCreateBuffer of " + std::to_string(bytes) + " bytes").c_str());
        throw;  // unreachable: check_cl throws for every error code
    }
}

std::string defines(const std::vector<std::pair<std::string, std::string>>& kv) {
    std::string s;
    for (auto& [k, v] : kv) s += " -D" + k + "=" + v;
    return s;
}

const cl::Program& Context::program(const std::string& family, const std::string& options) {
    if ((" " + options + " ").find(" -DFP64 ") != std::string::npos && !(fp64_ && tuning.allow_fp64))
        throw InputError("double precision (float64 values or isovalues, int32/uint32 filter sums) needs the "
                         "OpenCL extension cl_khr_fp64, which " + description() +
                         " lacks; convert the data on read with --as float32");
    std::lock_guard<std::mutex> lock(mutex_);
    auto key = std::make_pair(family, options);
    auto it = programs_.find(key);
    if (it != programs_.end()) return it->second;

    const char* common = nullptr;
    const char* body = nullptr;
    for (auto* k = detail::kernel_sources; k->family; ++k) {
        if (std::strcmp(k->family, "common") == 0) common = k->source;
        if (family == k->family) body = k->source;
    }
    if (!body) throw DeviceError("no kernel family '" + family + "' is embedded", CL_INVALID_KERNEL_NAME);
    std::string source = std::string(common ? common : "") + "\n#line 1\n" + body;

    auto t0 = std::chrono::steady_clock::now();
    fault_point(*this, FaultSite::build);
    std::string all_options = "-cl-std=CL1.2" + options;
    // A binary of an earlier process, when one was stored for this device, driver, source
    // and options; a binary the driver refuses is rebuilt from the source (and replaced).
    const std::string cache_dir = detail::program_cache_dir();
    const std::string cache_key =
        cache_dir.empty() ? std::string()
                          : detail::program_cache_key(
                                device_.getInfo<CL_DEVICE_NAME>() + "\n" + device_.getInfo<CL_DEVICE_VERSION>() +
                                    "\ndriver " + device_.getInfo<CL_DRIVER_VERSION>() + "\nplatform " +
                                    cl::Platform(device_.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>(),
                                source, all_options);
    if (auto binary = detail::load_program_binary(cache_dir, cache_key)) {
        try {
            cl::Program cached(context_, std::vector<cl::Device>{device_}, cl::Program::Binaries{std::move(*binary)});
            cached.build(std::vector<cl::Device>{device_}, all_options.c_str());
            compile_seconds_ += seconds_since(t0);
            return programs_.emplace(key, std::move(cached)).first->second;
        } catch (const cl::Error&) {
            // rebuilt from the source below
        }
    }
    cl::Program program(context_, source);
    cl_int err = CL_SUCCESS;
    try {
        program.build(std::vector<cl::Device>{device_}, all_options.c_str());
    } catch (const cl::Error& e) {
        err = e.err();
    }
    if (err != CL_SUCCESS) {
        std::string log;
        program.getBuildInfo(device_, CL_PROGRAM_BUILD_LOG, &log);
        throw DeviceError("building kernels/" + family + ".cl with '" + all_options + "': " +
                              cl_error_name(err) + "\n" + log,
                          err);
    }
    if (!cache_dir.empty()) {
        try {
            const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
            if (binaries.size() == 1) detail::store_program_binary(cache_dir, cache_key, binaries[0]);
        } catch (const cl::Error&) {
            // a driver without binaries: nothing to store
        }
    }
    compile_seconds_ += seconds_since(t0);
    return programs_.emplace(key, std::move(program)).first->second;
}

cl::Kernel Context::kernel(const std::string& family, const std::string& name, const std::string& options) {
    const cl::Program& p = program(family, options);
    try {
        return cl::Kernel(p, name.c_str());
    } catch (const cl::Error& e) {
        throw DeviceError("kernel " + name + " in kernels/" + family + ".cl: " + cl_error_name(e.err()), e.err());
    }
}

void set_fault_plan(Context& ctx, const FaultPlan& plan) {
    detail::FaultState& f = detail::ContextAccess::faults(ctx);
    std::lock_guard<std::mutex> lock(f.mutex);
    f.plan = plan;
    for (auto& n : f.plan.seen) n = 0;
    f.on = true;
}

FaultPlan fault_plan(const Context& ctx) {
    const detail::FaultState& f = detail::ContextAccess::faults(ctx);
    std::lock_guard<std::mutex> lock(f.mutex);
    return f.plan;
}

void fault_point(Context& ctx, FaultSite site) {
    detail::FaultState& f = detail::ContextAccess::faults(ctx);
    if (!f.on) return;
    bool fail;
    {
        std::lock_guard<std::mutex> lock(f.mutex);
        fail = ++f.plan.seen[int(site)] == f.plan.fail_at && f.plan.site == site;
    }
    if (!fail) return;
    static const int codes[3] = {CL_MEM_OBJECT_ALLOCATION_FAILURE, CL_OUT_OF_RESOURCES, CL_BUILD_PROGRAM_FAILURE};
    static const char* calls[3] = {"clCreateBuffer (injected fault)", "clEnqueueNDRangeKernel (injected fault)",
                                   "clBuildProgram (injected fault)"};
    check_cl(codes[int(site)], calls[int(site)]);
}

// The limits a launch must respect beyond the work-group size: the work-items per dimension
// (CL_DEVICE_MAX_WORK_ITEM_SIZES) and the local memory of the kernel with its arguments
// (CL_KERNEL_LOCAL_MEM_SIZE against CL_DEVICE_LOCAL_MEM_SIZE). A launch beyond them is
// refused here with the limit's name, before the device answers CL_OUT_OF_RESOURCES.
void Context::check_launch_limits(const cl::Kernel& kernel, const std::string& name, const cl::NDRange& local) const {
    const std::vector<std::size_t>& item_max = max_work_item_sizes_;
    for (cl_uint d = 0; d < local.dimensions() && d < item_max.size(); ++d)
        if (local[d] > item_max[d])
            throw DeviceError("launch of " + name + ": local size " + std::to_string(local[d]) + " in dimension " +
                                  std::to_string(d) + " exceeds CL_DEVICE_MAX_WORK_ITEM_SIZES " +
                                  std::to_string(item_max[d]),
                              CL_INVALID_WORK_ITEM_SIZE);
    const cl_ulong local_bytes = kernel.getWorkGroupInfo<CL_KERNEL_LOCAL_MEM_SIZE>(device_);
    if (local_bytes > local_mem_)
        throw DeviceError("launch of " + name + ": needs " + std::to_string(local_bytes) +
                              " bytes of local memory, more than the device's CL_DEVICE_LOCAL_MEM_SIZE " +
                              std::to_string(local_mem_),
                          CL_OUT_OF_RESOURCES);
}

void Context::launch(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local) {
    std::string name = kernel.getInfo<CL_KERNEL_FUNCTION_NAME>();
    if (local.dimensions() != 0) {
        std::size_t kernel_max = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_);
        std::size_t total = 1;
        for (cl_uint d = 0; d < local.dimensions(); ++d) {
            total *= local[d];
            if (local[d] == 0 || global[d] % local[d] != 0)
                throw DeviceError("launch of " + name + ": global size " + std::to_string(global[d]) +
                                      " is not a multiple of local size " + std::to_string(local[d]),
                                  CL_INVALID_WORK_GROUP_SIZE);
        }
        if (total > kernel_max)
            throw DeviceError("launch of " + name + ": work-group of " + std::to_string(total) +
                                  " exceeds CL_KERNEL_WORK_GROUP_SIZE " + std::to_string(kernel_max),
                              CL_INVALID_WORK_GROUP_SIZE);
    }
    check_launch_limits(kernel, name, local);
    for (cl_uint d = 0; d < global.dimensions(); ++d)
        if (global[d] == 0) return;  // nothing to do
    std::array<std::size_t, 3> local_size{0, 0, 0};
    for (cl_uint d = 0; d < local.dimensions() && d < 3; ++d) local_size[d] = local[d];
    bool first;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        first = warmed_.emplace(kernel.getInfo<CL_KERNEL_PROGRAM>()(), name, local_size).second;
    }
    try {
        // The first launch of this (kernel, options, local size): the work queued before it
        // is finished first; its wall time less the kernel's own execution (the event's
        // START..END) is what the driver spent compiling for this work-group size.
        if (first) queue_.finish();
        const auto t0 = std::chrono::steady_clock::now();
        fault_point(*this, FaultSite::enqueue);
        cl::Event event;
        queue_.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &event);
        if (first) {
            event.wait();
            const double wall = seconds_since(t0), run = event_seconds(event);
            std::lock_guard<std::mutex> lock(mutex_);
            compile_seconds_ += std::max(0.0, wall - run);
        }
        std::lock_guard<std::mutex> lock(mutex_);
        // Collected at every launch: an event holds its command and the buffers it reads
        // (a stream's consumed batches) until it is released.
        collect_completed_events();
        pending_events_.push_back(std::move(event));
    } catch (const cl::Error& e) {
        check_cl(e.err(), ("clEnqueueNDRangeKernel " + name).c_str());
    }
}

double Context::event_seconds(const cl::Event& event) {
    const cl_ulong start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    const cl_ulong end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
    return end > start ? double(end - start) * 1e-9 : 0.0;
}

// Adds the execution times of the finished kernels to kernel_seconds_ and forgets them
// (the caller holds mutex_). The queue is in order: the finished ones are a prefix.
void Context::collect_completed_events() {
    std::size_t done = 0;
    while (done < pending_events_.size() &&
           pending_events_[done].getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>() == CL_COMPLETE)
        kernel_seconds_ += event_seconds(pending_events_[done++]);
    pending_events_.erase(pending_events_.begin(), pending_events_.begin() + std::ptrdiff_t(done));
}

double Context::kernel_seconds() {
    return with_cl_errors([&] {
        queue_.finish();
        std::lock_guard<std::mutex> lock(mutex_);
        collect_completed_events();
        return kernel_seconds_;
    });
}

}  // namespace clfractal
