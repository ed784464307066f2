#include "clfractal/fd4.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>
#include <type_traits>

#include "clfractal/local.hpp"
#include "clfractal/device_volume.hpp"
#include "device/type_options.hpp"
#include "clfractal/pyramid.hpp"
#include "clfractal/sat.hpp"
#include "device/kernel_call.hpp"
#include "measures/local_queries.hpp"

namespace clfractal {

double default_bin_width(const Volume& v) {
    if (is_integer(v.type())) return 1;
    const ValueRange r = value_range(v);
    const double q = (r.max - r.min) / 256;
    return q > 0 ? q : 1;
}

namespace {

// The most bins one cube can touch: those of the whole value range.
double max_bins(const ValueRange& r, double q) { return std::floor((r.max - r.min) / q) + 1; }

void check_bin_width(const Volume& v, const ValueRange& r, double q) {
    if (!std::isfinite(q) || q <= 0) throw InputError("--q: the bin width must be a finite number > 0");
    // Bin indices and 64-bit sums stay exact below 2^62.
    const double most = max_bins(r, q), limit = 0x1p62;
    if (!(most < limit) || !(most * double(std::max<std::size_t>(1, v.dims().cubes())) < limit))
    {
        std::ostringstream m;
        m << std::setprecision(9) << "--q " << q << ": too small for the value range [" << r.min << ", " << r.max
          << "] of " << dims_string(v.dims()) << " (the bin counts would overflow 64 bits)";
        throw InputError(m.str());
    }
}

// The bin width to use: q, or the default when q is 0; checked.
double bin_width(const Volume& v, const ValueRange& r, double q) {
    if (q == 0) q = default_bin_width(v);
    check_bin_width(v, r, q);
    return q;
}

// Levels 0 (G, bin width q) and 1 (G', 2q) of a volume on the device, in the form the
// kernels of kernels/fd4.cl read: the values themselves when the device computes the bins
// in double, else the host's bin indices (cl_long, -DBIN_INDEX). See fd4.hpp.
class BinnedLevels {
public:
    // `uploaded`: v on the device already (else uploaded here when the device bins it).
    BinnedLevels(Context& ctx, const Volume& v, const DeviceVolume* uploaded, double vmin, double q)
        : device_bins_(ctx.has_fp64() && ctx.tuning.use_fp64), vmin_(vmin), q_(q) {
        dims_[0] = v.dims();
        dims_[1] = level_dims(v.dims(), 1);
        if (device_bins_) {
            options_ = type_options(v.type());
            if (!uploaded) volume_ = DeviceVolume(ctx, v);
            level0_ = uploaded ? uploaded : &volume_;
            data_[1] = Buffer<unsigned char>(ctx, dims_[1].vertices() * value_size(v.type()));
            subsample(ctx, level0_->buffer(), v.type(), dims_[0], data_[1].get());
        } else {
            options_ = defines({{"T", "long"}}) + " -DBIN_INDEX";
            upload(ctx, 0, v, q);
            upload(ctx, 1, subsample(v), 2 * q);
        }
    }

    const std::string& options() const { return options_; }
    const Dims& dims(int level) const { return dims_[level]; }
    const cl::Buffer& data(int level) const {
        return device_bins_ && level == 0 ? level0_->buffer() : data_[level].get();
    }
    // The kernel arguments vmin and q (BIN_T) of `level`.
    ScalarArg bin_vmin() const { return device_bins_ ? ScalarArg::of(cl_double(vmin_)) : ScalarArg::of(cl_long(0)); }
    ScalarArg bin_width(int level) const {
        return device_bins_ ? ScalarArg::of(cl_double(level ? 2 * q_ : q_)) : ScalarArg::of(cl_long(0));
    }

private:
    void upload(Context& ctx, int level, const Volume& g, double q) {
        std::vector<cl_long> bins(g.vertices());
        visit(g, [&](const auto* p) {
            const long long n = (long long)g.vertices();
#pragma omp parallel for schedule(static)
            for (long long i = 0; i < n; ++i) bins[std::size_t(i)] = cl_long(std::floor((double(p[i]) - vmin_) / q));
        });
        data_[level] = Buffer<unsigned char>(ctx, bins.size() * sizeof(cl_long), CL_MEM_READ_ONLY);
        data_[level].write(ctx.queue(), reinterpret_cast<const unsigned char*>(bins.data()), data_[level].size());
    }

    bool device_bins_;
    double vmin_, q_;
    std::string options_;
    Dims dims_[2];
    DeviceVolume volume_;                  // level 0 uploaded here
    const DeviceVolume* level0_ = nullptr;  // level 0 when the device computes the bins
    Buffer<unsigned char> data_[2];
};

// kernels/fd4.cl cube_bins_rows(vol, nx, ny, vmin, q, sums) and cube_bins_table(vol, nx, ny,
// vmin, q, table).
using BinsKernel = KernelCall<cl::Buffer, int, int, ScalarArg, ScalarArg, cl::Buffer>;

// I4 of one level: per-row sums of B_q on the device, added here.
std::uint64_t sum_bins(Context& ctx, const BinnedLevels& levels, int level) {
    const Dims d = levels.dims(level);
    if (d.cubes() == 0) return 0;
    Buffer<cl_ulong> sums(ctx, (d.ny - 1) * (d.nz - 1));
    BinsKernel(ctx, "fd4", "cube_bins_rows", levels.options())(cl::NDRange(d.ny - 1, d.nz - 1), cl::NullRange,
                                                               levels.data(level), int(d.nx), int(d.ny),
                                                               levels.bin_vmin(), levels.bin_width(level), sums.get());
    const std::vector<cl_ulong> h = sums.to_host(ctx.queue());
    return std::accumulate(h.begin(), h.end(), std::uint64_t(0));
}

void check_input(const Volume& v) {
    check_dims(v.dims(), "volume");
    check_finite(v, "volume");
}

template <class C>
void field4(Context& ctx, const BinnedLevels& levels, ValueType type, int window, const cl::Buffer& out) {
    const std::string count = std::is_same_v<C, cl_ulong> ? "ulong" : "uint";
    Buffer<C> tables[2];
    for (int level = 0; level < 2; ++level) {
        const Dims d = levels.dims(level);
        if (d.vertices() * sizeof(C) > ctx.max_alloc())
            throw InputError("volume " + dims_string(levels.dims(0)) + ": the LD4 tables need " +
                             std::to_string((d.vertices() * sizeof(C)) >> 20) +
                             " MiB, more than the device's largest allocation (" +
                             std::to_string(ctx.max_alloc() >> 20) + " MiB)");
        tables[level] = Buffer<C>(ctx, d.vertices());
        BinsKernel(ctx, "fd4", "cube_bins_table", levels.options() + defines({{"C", count}}))(
            cl::NDRange(d.nx, d.ny, d.nz), cl::NullRange, levels.data(level), int(d.nx), int(d.ny), levels.bin_vmin(),
            levels.bin_width(level), tables[level].get());
        summed_area_table(ctx, tables[level], d);
    }
    // The query kernels of the local dimension read the tables (the value type is unused
    // there; naming it shares the program with the LD field of the same volume).
    const std::string options = single_isovalue_options(type) + defines({{"C", count}});
    window_log_ratios(ctx, tables[0], levels.dims(0), tables[1], window, options, out);
}

}  // namespace

void check_bin_width(const Volume& v, double q) { check_bin_width(v, value_range(v), q); }

namespace {

// D4 of `v` (host values), read on the device from `uploaded` when given.
Fd4Result fd4_of(Context& ctx, const Volume& v, const DeviceVolume* uploaded, double q) {
    check_input(v);
    const ValueRange r = value_range(v);
    Fd4Result res;
    res.q = bin_width(v, r, q);
    res.vmin = r.min;
    const auto t0 = std::chrono::steady_clock::now();
    with_cl_errors([&] {
        const BinnedLevels levels(ctx, v, uploaded, r.min, res.q);
        res.i4 = sum_bins(ctx, levels, 0);
        res.i4_sub = sum_bins(ctx, levels, 1);
    });
    res.seconds = seconds_since(t0);
    res.d4 = res.i4 && res.i4_sub ? std::log2(double(res.i4) / double(res.i4_sub))
                                  : std::numeric_limits<double>::quiet_NaN();
    return res;
}

// The checked inputs of an LD4 field: the value range and the bin width.
struct Ld4Bins {
    ValueRange r;
    double q = 0;
};
Ld4Bins ld4_bins(const Volume& v, double q, int window) {
    check_input(v);
    local_windows(1, window);  // checks the window before any work
    const ValueRange r = value_range(v);
    return {r, bin_width(v, r, q)};
}

// The LD4 field of `v` (host values; read on the device from `uploaded` when given) into
// `out` (v.vertices() floats on the device).
void ld4_of(Context& ctx, const Volume& v, const DeviceVolume* uploaded, const Ld4Bins& b, int window,
            const cl::Buffer& out) {
    const ValueRange& r = b.r;
    const double q = b.q;
    with_cl_errors([&] {
        const BinnedLevels levels(ctx, v, uploaded, r.min, q);
        if (max_bins(r, q) * double(v.dims().cubes()) > double(ctx.tuning.sat_max_32bit))
            field4<cl_ulong>(ctx, levels, v.type(), window, out);
        else
            field4<cl_uint>(ctx, levels, v.type(), window, out);
    });
}

}  // namespace

Fd4Result fractal_dimension_4d(Context& ctx, const Volume& v, double q) { return fd4_of(ctx, v, nullptr, q); }

Fd4Result fractal_dimension_4d(const DeviceVolume& v, double q) {
    return fd4_of(v.context(), v.download(), &v, q);
}

Volume local_fractal_dimension_4d(Context& ctx, const Volume& v, double q, int window) {
    const Ld4Bins bins = ld4_bins(v, q, window);
    Volume out(v.dims(), ValueType::float32, v.name);
    out.spacing = v.spacing;
    with_cl_errors([&] {
        Buffer<float> field(ctx, v.vertices());
        ld4_of(ctx, v, nullptr, bins, window, field.get());
        field.read(ctx.queue(), out.as<float>(), out.vertices());
    });
    return out;
}

DeviceVolume local_fractal_dimension_4d(const DeviceVolume& v, double q, int window) {
    const Volume host = v.download();
    const Ld4Bins bins = ld4_bins(host, q, window);
    DeviceVolume out = allocate_like(v, ValueType::float32);
    out.name = v.name;
    ld4_of(v.context(), host, &v, bins, window, out.buffer());
    return out;
}

}  // namespace clfractal
