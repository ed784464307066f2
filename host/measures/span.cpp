#include "clfractal/span.hpp"

#include "clfractal/pyramid.hpp"
#include "device/slab_plan.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "measures/pyramid_kernel.hpp"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <memory>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace clfractal {

const SpanCurves& SpanResult::get(SpanKind k) const {
    for (auto& c : curves)
        if (c.kind == k) return c;
    throw std::logic_error("SpanResult::get: kind was not counted");
}

// ---------------------------------------------------------------- the counter

namespace {

// Partial histograms are 32-bit: a slab never holds more vertices than this.
constexpr std::size_t max_slab_vertices = std::size_t(1) << 29;

}  // namespace

struct SpanCounter::Impl {
    Context& ctx;
    IsovalueSet iso;
    ValueType type;
    Dims dims;
    SpanOptions opt;
    std::size_t nbins = 0;       // isovalues + 1
    std::size_t align = 1;       // slabs start at multiples of 2^(levels-1)
    std::size_t max_slices = 0;  // slab depth including the shared last slice
    bool private_hist = true;  // SpanVariant::private_histograms, else atomic
    bool global_hist = false;
    std::size_t wg = 1, partial_rows = 1;
    // The histogram rows of one work-item of the *_private kernels (kernels/span.cl).
    static constexpr std::size_t private_rows = 4;

    Buffer<unsigned char> iso_buf;  // the isovalue list as float or double
    std::vector<Buffer<unsigned char>> level_buf;    // slab of each level
    Buffer<int> partial;
    std::vector<std::vector<Buffer<long long>>> hist;  // [kind][level]
    // kernels/span.cl: count_cubes_* (vol, nx, ny, nzs, vmin, iso, niso, nbins, partial) and
    // count_edges_* (the same with last_slab after nzs); the atomic variants add a local
    // histogram.
    using CubesPrivate = KernelCall<cl::Buffer, int, int, int, cl_long, cl::Buffer, int, int, cl::Buffer>;
    using EdgesPrivate = KernelCall<cl::Buffer, int, int, int, int, cl_long, cl::Buffer, int, int, cl::Buffer>;
    using CubesAtomic =
        KernelCall<cl::Buffer, int, int, int, cl_long, cl::Buffer, int, int, cl::Buffer, cl::LocalSpaceArg>;
    using EdgesAtomic =
        KernelCall<cl::Buffer, int, int, int, int, cl_long, cl::Buffer, int, int, cl::Buffer, cl::LocalSpaceArg>;
    struct CountKernels {
        CubesPrivate cubes_private;
        EdgesPrivate edges_private;
        CubesAtomic cubes_atomic;
        EdgesAtomic edges_atomic;
        std::size_t work_group_limit = 0;
    };
    SubsampleKernel subsample;
    KernelCall<cl::Buffer, int, int, cl::Buffer> accumulate;  // partial, rows, nbins, hist
    std::vector<CountKernels> count;                             // per kind
    std::size_t next_z = 0, slabs = 0;
    std::size_t z_end = 0;  // one past the last slice of the counted part
    bool done = false;      // the part's last slab was added
    double seconds = 0;

    Impl(Context& c, const IsovalueSet& i, ValueType t, const Dims& d, const SpanOptions& o)
        : ctx(c), iso(i), type(t), dims(d), opt(o) {
        check_arguments();
        max_slices = plan();
        private_hist = ctx.tuning.span_variant == SpanVariant::private_histograms;
        // Work-group histograms in local memory only where they fit the device's (half of it:
        // the kernel's own local variables need the rest); else global-memory histograms.
        global_hist = !private_hist && nbins * sizeof(int) > std::min(ctx.tuning.local_hist_bytes, ctx.local_mem() / 2);
        with_cl_errors([&] {
            build_kernels();
            allocate();
            ctx.queue().finish();
        });
    }

    void check_arguments() {
        if (opt.levels < 1 || opt.levels > 16) throw InputError("--levels must be between 1 and 16");
        if (opt.kinds.empty()) throw std::logic_error("SpanCounter: no kind requested");
        if (!iso.matches(type))
            throw std::logic_error("SpanCounter: isovalue set does not match the value type");
        check_dims(dims, "volume");
        check_int_axes(dims);
        nbins = iso.size() + 1;
        align = std::size_t(1) << (opt.levels - 1);
        z_end = opt.z_end ? opt.z_end : dims.nz;
        if (opt.z_begin % align != 0 || opt.z_begin >= z_end || z_end > dims.nz ||
            (z_end < dims.nz && (z_end - 1) % align != 0))
            throw std::logic_error("SpanCounter: the part's first and last slices must be multiples of 2^(levels-1)");
        next_z = opt.z_begin;
    }

    // Slab depth: the whole part if it fits, else a multiple of `align` plus one slice.
    std::size_t plan() const {
        // Partial histograms are 32-bit: never more than max_slab_vertices per slab.
        const std::size_t cap = max_slab_vertices / (dims.nx * dims.ny);
        if (dims.nz > 1 && cap < align + 1)
            throw InputError("volume: slices of " + dims_string(dims) + " hold more than 2^29 / " +
                             std::to_string(align + 1) + " vertices, too many for 32-bit partial counts");
        SlabNeed need;
        need.nz = z_end - opt.z_begin;
        need.input_slice_bytes = dims.nx * dims.ny * value_size(type);
        need.shared_step = align;
        need.forced = opt.slab_slices;
        need.max_slices = std::max<std::size_t>(1, cap);
        // Read in place (CPU devices), slabs cost no copy: small ones keep the buffers of the
        // subsampled levels small (an eighth of the slab and less, not of the volume).
        if (!ctx.tuning.slab_bytes && ctx.tuning.zero_copy)
            need.max_slices = std::min(need.max_slices, std::max<std::size_t>(align + 1, (std::size_t(32) << 20) /
                                                                                           need.input_slice_bytes));
        return plan_slab(ctx, need, dims);
    }

    // The kernels of the chosen variant and their launch shape.
    void build_kernels() {
        std::string options = type_options(type);
        if (iso.integer()) options += " -DINTEGER_VALUES";
        // Bins computed in int (kernels/common.cl): every value and bin of 8/16-bit data fits.
        if (iso.integer() && value_size(type) <= 2 && std::llabs(iso.first()) <= (1 << 20)) options += " -DNARROW_BINS";
        if (iso.float64()) options += " -DISO_DOUBLE -DFP64";
        if (global_hist) options += " -DGLOBAL_HIST";
        subsample = SubsampleKernel(ctx, "pyramid", "subsample", type_options(type));
        accumulate = decltype(accumulate)(ctx, "span", "accumulate_partials", options);
        for (SpanKind k : opt.kinds) {
            CountKernels c;
            const bool cubes = k == SpanKind::cubes;
            if (private_hist && cubes) c.cubes_private = CubesPrivate(ctx, "span", "count_cubes_private", options);
            if (private_hist && !cubes) c.edges_private = EdgesPrivate(ctx, "span", "count_edges_private", options);
            if (!private_hist && cubes) {
                c.cubes_atomic = CubesAtomic(ctx, "span", "count_cubes_atomic", options);
                c.work_group_limit = c.cubes_atomic.work_group_limit();
            }
            if (!private_hist && !cubes) {
                c.edges_atomic = EdgesAtomic(ctx, "span", "count_edges_atomic", options);
                c.work_group_limit = c.edges_atomic.work_group_limit();
            }
            count.push_back(std::move(c));
        }
        if (private_hist) {
            partial_rows = private_rows * (ctx.tuning.private_items ? ctx.tuning.private_items : 4 * ctx.compute_units());
            wg = 1;
            return;
        }
        std::size_t kmax = ctx.max_work_group();
        for (auto& k : count) kmax = std::min(kmax, k.work_group_limit);
        wg = std::max<std::size_t>(1, std::min(ctx.tuning.work_group, kmax));
        partial_rows = ctx.tuning.private_items ? ctx.tuning.private_items : 8 * ctx.compute_units();
        // Global-memory histograms spread their atomics over many bins already:
        // a few rows suffice, and each costs nbins * 4 bytes to clear and merge.
        if (global_hist) partial_rows = std::min<std::size_t>(partial_rows, 16);
    }

    // The isovalue list, the levels above 0, the partial and the total histograms.
    void allocate() {
        // The list in its own type (one unused value for integer sets).
        std::vector<unsigned char> isov;
        const auto put = [&](const auto& list) {
            isov.resize(list.size() * sizeof(list[0]));
            std::memcpy(isov.data(), list.data(), isov.size());
        };
        if (iso.integer()) put(std::vector<float>{0.f});
        else if (iso.float64()) put(iso.list());
        else put(std::vector<float>(iso.list().begin(), iso.list().end()));
        iso_buf = Buffer<unsigned char>(ctx, isov);
        // Level 0 is the caller's slab where the device reads it in place; its buffer here
        // (slab_buffer(), made at the first use) takes the other host slabs and slabs copied
        // out of a larger device volume (count_spans of a DeviceVolume).
        level_buf.emplace_back();
        for (int l = 1; l < opt.levels; ++l) {
            Dims ld = level_dims(Dims{dims.nx, dims.ny, max_slices}, l);
            level_buf.emplace_back(ctx, ld.vertices() * value_size(type));
        }
        partial = Buffer<int>(ctx, partial_rows * nbins);
        hist.resize(opt.kinds.size());
        for (auto& h : hist)
            for (int l = 0; l < opt.levels; ++l) {
                h.emplace_back(ctx, nbins);
                h.back().fill(ctx.queue(), 0);
            }
    }

    void count_level(std::size_t kind, const cl::Buffer& values, int l, const Dims& ld, bool last) {
        CountKernels& k = count[kind];
        const bool cubes = opt.kinds[kind] == SpanKind::cubes;
        if (cubes && (ld.nx < 2 || ld.ny < 2 || ld.nz < 2)) return;
        const int nx = int(ld.nx), ny = int(ld.ny), nz = int(ld.nz), niso = int(iso.size()), bins = int(nbins);
        const cl_long vmin = iso.integer() ? iso.first() : 0;
        if (private_hist) {
            partial.fill(ctx.queue(), 0);
            const cl::NDRange global(partial_rows / private_rows), local(1);
            if (cubes) k.cubes_private(global, local, values, nx, ny, nz, vmin, iso_buf.get(), niso, bins, partial.get());
            else k.edges_private(global, local, values, nx, ny, nz, int(last), vmin, iso_buf.get(), niso, bins, partial.get());
            accumulate_rows(partial_rows, kind, l);
            return;
        }
        const std::size_t work = cubes ? ld.cubes() : ld.vertices();
        const std::size_t groups = std::min(partial_rows, (work + wg - 1) / wg);
        const cl::LocalSpaceArg lh = cl::Local(global_hist ? sizeof(int) : nbins * sizeof(int));
        if (global_hist) partial.fill(ctx.queue(), 0);
        const cl::NDRange global(groups * wg), local(wg);
        if (cubes) k.cubes_atomic(global, local, values, nx, ny, nz, vmin, iso_buf.get(), niso, bins, partial.get(), lh);
        else k.edges_atomic(global, local, values, nx, ny, nz, int(last), vmin, iso_buf.get(), niso, bins, partial.get(), lh);
        accumulate_rows(groups, kind, l);
    }

    void accumulate_rows(std::size_t rows, std::size_t kind, int l) {
        const std::size_t w = std::min<std::size_t>(64, ctx.max_work_group());
        accumulate(cl::NDRange((nbins + w - 1) / w * w), cl::NDRange(w), partial.get(), int(rows), int(nbins),
                   hist[kind][l].get());
    }

    void run_subsample(const cl::Buffer& src, const Dims& from, const cl::Buffer& dst, const Dims& to) {
        const std::size_t w = std::min<std::size_t>(64, ctx.max_work_group());
        subsample(cl::NDRange((to.nx + w - 1) / w * w, to.ny, to.nz), cl::NDRange(w, 1, 1), src, int(from.nx),
                  int(from.ny), dst, int(to.nx), int(to.ny));
    }

    // Host slabs are read in place where the device can (zero-copy, aligned), else written
    // into one device buffer kept for every slab: a device buffer made and freed per slab
    // left the host heap fragmented on PoCL (glibc kept the freed blocks of a slab each),
    // peak memory growing with the number of slabs.
    void add_slab(const void* data, std::size_t z0, std::size_t nzs) {
        check_slab(z0, nzs);
        ComputeTimer timer(ctx);
        const Dims slab_dims{dims.nx, dims.ny, nzs};
        if (DeviceVolume::in_place(ctx, data)) {
            // Also on an exception, no kernel may still read `data` when we return: the slab's
            // destructor waits for the queue (timed too).
            const DeviceVolume slab(ctx, data, slab_dims, type);
            with_cl_errors([&] { count_slab(slab.buffer(), z0, nzs); });
        } else {
            // A blocking write: `data` is free again when it returns.
            with_cl_errors([&] {
                ctx.queue().enqueueWriteBuffer(slab_buffer(), CL_TRUE, 0, slab_dims.vertices() * value_size(type), data);
                ctx.count_upload();
                count_slab(slab_buffer(), z0, nzs);
            });
        }
        seconds += timer.seconds();
    }

    // The device buffer of level-0 slabs that are not read in place, made at the first use.
    const cl::Buffer& slab_buffer() {
        const std::size_t bytes = max_slices * dims.nx * dims.ny * value_size(type);
        if (level_buf[0].size() < bytes) level_buf[0] = Buffer<unsigned char>(ctx, bytes);
        return level_buf[0].get();
    }

    // Slices [z0, z0 + nzs) of a device volume of the counter's dims: the buffer itself
    // when the slab is the whole volume, else a device-side copy.
    void add_device_slab(const cl::Buffer& volume, std::size_t z0, std::size_t nzs) {
        check_slab(z0, nzs);
        ComputeTimer timer(ctx);
        with_cl_errors([&] {
            if (nzs == dims.nz) return count_slab(volume, z0, nzs);
            const std::size_t slice_bytes = dims.nx * dims.ny * value_size(type);
            ctx.queue().enqueueCopyBuffer(volume, slab_buffer(), z0 * slice_bytes, 0, nzs * slice_bytes);
            count_slab(slab_buffer(), z0, nzs);
        });
        seconds += timer.seconds();
    }

    void check_slab(std::size_t z0, std::size_t nzs) const {
        if (done || z0 != next_z || nzs == 0 || nzs > max_slices || z0 + nzs > z_end || z0 % align != 0)
            throw std::logic_error("SpanCounter::add_slab: slabs out of order or of the wrong size");
        if (z0 + nzs != z_end && (nzs - 1) % align != 0)
            throw std::logic_error("SpanCounter::add_slab: inner slab depth must be a multiple of 2^(levels-1) plus 1");
    }

    // Counts every level of the slab whose level-0 values are `level0`.
    void count_slab(const cl::Buffer& level0, std::size_t z0, std::size_t nzs) {
        // Edges on the top slice belong to this counter only at the top of the volume.
        const bool last = z0 + nzs == dims.nz;
        Dims prev{dims.nx, dims.ny, nzs};
        for (int l = 0; l < opt.levels; ++l) {
            // Level-l slices of this slab: z0 / 2^l .. (z0 + nzs - 1) / 2^l.
            std::size_t zl0 = z0 >> l, zl1 = (z0 + nzs - 1) >> l;
            Dims ld = level_dims(Dims{dims.nx, dims.ny, 1}, l);
            ld.nz = zl1 - zl0 + 1;
            const cl::Buffer& values = l == 0 ? level0 : level_buf[l].get();
            if (l > 0) run_subsample(l == 1 ? level0 : level_buf[l - 1].get(), prev, values, ld);
            for (std::size_t k = 0; k < opt.kinds.size(); ++k) count_level(k, values, l, ld, last);
            prev = ld;
        }
        next_z = z0 + nzs - 1;
        done = z0 + nzs == z_end;
        ++slabs;
    }

    SpanResult finish() {
        if (!done) throw std::logic_error("SpanCounter::finish: not every slab was added");
        return snapshot();
    }

    SpanResult snapshot() {
        ComputeTimer timer(ctx);
        SpanResult r;
        r.isovalues = iso;
        with_cl_errors([&] {
            for (std::size_t k = 0; k < opt.kinds.size(); ++k) {
                SpanCurves c;
                c.kind = opt.kinds[k];
                for (int l = 0; l < opt.levels; ++l) {
                    c.level_dims.push_back(level_dims(dims, l));
                    std::vector<long long> h = hist[k][l].to_host(ctx.queue());
                    std::vector<std::uint64_t> counts(iso.size());
                    long long run = 0;
                    for (std::size_t j = 0; j < iso.size(); ++j) counts[j] = std::uint64_t(run += h[j]);
                    c.counts.push_back(std::move(counts));
                }
                r.curves.push_back(std::move(c));
            }
        });
        seconds += timer.seconds();
        r.seconds = seconds;
        r.slabs = slabs;
        return r;
    }
};

SpanCounter::SpanCounter(Context& ctx, const IsovalueSet& iso, ValueType type, const Dims& dims,
                         const SpanOptions& opt)
    : impl_(new Impl(ctx, iso, type, dims, opt)) {}
SpanCounter::~SpanCounter() { delete impl_; }
void SpanCounter::add_slab(const void* data, std::size_t z0, std::size_t nzs) { impl_->add_slab(data, z0, nzs); }
SpanResult SpanCounter::finish() { return impl_->finish(); }
SpanResult SpanCounter::snapshot() { return impl_->snapshot(); }
std::size_t SpanCounter::slab_slices() const { return impl_->max_slices; }

std::vector<std::pair<std::size_t, std::size_t>> split_slices(std::size_t nz, int levels, std::size_t parts) {
    if (nz == 0 || parts == 0 || levels < 1 || levels > 16) throw std::logic_error("split_slices: bad arguments");
    const std::size_t align = std::size_t(1) << (levels - 1);
    const std::size_t steps = (nz - 1) / align;
    std::vector<std::size_t> starts;
    for (std::size_t i = 0; i < parts; ++i) {
        const std::size_t b = i * steps / parts * align;
        if (starts.empty() || b != starts.back()) starts.push_back(b);
    }
    std::vector<std::pair<std::size_t, std::size_t>> out;
    for (std::size_t i = 0; i < starts.size(); ++i)
        out.emplace_back(starts[i], i + 1 < starts.size() ? starts[i + 1] + 1 : nz);
    return out;
}

void SpanCounter::add_slab(const DeviceVolume& volume, std::size_t z0, std::size_t nzs) {
    if (volume.dims() != impl_->dims || volume.type() != impl_->type)
        throw std::logic_error("SpanCounter::add_slab: the device volume is not the counter's");
    impl_->add_device_slab(volume.buffer(), z0, nzs);
}

namespace {

// Feeds the slabs of the part [opt.z_begin, opt.z_end) to `counter` in z order:
// add(z0, nzs) for each.
template <class Add> SpanResult count_slabs(SpanCounter& counter, const Dims& d, const SpanOptions& opt, Add add) {
    const std::size_t step = counter.slab_slices() - 1;
    const std::size_t end = opt.z_end ? opt.z_end : d.nz;
    std::size_t z0 = opt.z_begin;
    while (true) {
        std::size_t nzs = std::min(counter.slab_slices(), end - z0);
        add(z0, nzs);
        if (z0 + nzs == end) break;
        z0 += step;
    }
    return counter.finish();
}

}  // namespace

SpanResult count_spans(Context& ctx, const Volume& v, const IsovalueSet& iso, const SpanOptions& opt) {
    // Slab by slab from host memory: a volume larger than the device never needs to fit.
    // When the device runs out of memory, again with slabs of half the depth, down to the
    // smallest the layout allows (2^(levels-1) + 1 slices).
    const std::size_t slice_bytes = v.dims().nx * v.dims().ny * value_size(v.type());
    const auto* bytes = static_cast<const unsigned char*>(v.data());
    SpanOptions o = opt;
    const std::size_t part = (opt.z_end ? opt.z_end : v.dims().nz) - std::min(opt.z_begin, v.dims().nz);
    for (;;) {
        std::size_t depth = o.slab_slices ? std::min(o.slab_slices, part) : part;  // at most
        try {
            // The call's compute time: its wall time less compilation, set-up included.
            const ComputeTimer timer(ctx);
            SpanCounter counter(ctx, iso, v.type(), v.dims(), o);
            depth = counter.slab_slices();
            SpanResult r = count_slabs(counter, v.dims(), o, [&](std::size_t z0, std::size_t nzs) {
                counter.add_slab(bytes + z0 * slice_bytes, z0, nzs);
            });
            r.seconds = timer.seconds();
            return r;
        } catch (const DeviceError& e) {
            const std::size_t smallest = (std::size_t(1) << (std::max(1, std::min(opt.levels, 16)) - 1)) + 1;
            if (!e.out_of_memory() || depth <= smallest) throw;
            o.slab_slices = std::max(smallest, depth / 2);
        }
    }
}

SpanResult count_spans(const DeviceVolume& v, const IsovalueSet& iso, const SpanOptions& opt) {
    const ComputeTimer timer(v.context());
    SpanCounter counter(v.context(), iso, v.type(), v.dims(), opt);
    SpanResult r =
        count_slabs(counter, v.dims(), opt, [&](std::size_t z0, std::size_t nzs) { counter.add_slab(v, z0, nzs); });
    r.seconds = timer.seconds();
    return r;
}

}  // namespace clfractal
