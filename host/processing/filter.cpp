#include "clfractal/filter.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <tuple>
#include <sstream>

#include "clfractal/local.hpp"
#include "device/slab_plan.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "measures/local_queries.hpp"

namespace clfractal {

int FilterSpec::radius() const {
    switch (kind) {
    case FilterKind::median: return 1;
    case FilterKind::gaussian: return int(std::ceil(3 * sigma));
    default: return int(std::ceil(2 * sigma_s));
    }
}

std::string FilterSpec::describe() const {
    std::ostringstream s;
    switch (kind) {
    case FilterKind::median: s << "median 3x3x3"; break;
    case FilterKind::gaussian: s << "gaussian sigma " << sigma << " (radius " << radius() << ")"; break;
    default: s << "bilateral sigma_s " << sigma_s << " sigma_r " << sigma_r << " (radius " << radius() << ")";
    }
    return s.str();
}

void FilterSpec::check() const {
    auto positive = [](double x, const char* what) {
        if (!std::isfinite(x) || x <= 0) throw InputError(std::string(what) + ": must be a finite number > 0");
    };
    if (kind == FilterKind::gaussian) {
        positive(sigma, "--gaussian SIGMA");
        if (sigma > 32.0 / 3) throw InputError("--gaussian SIGMA: at most 10.67 (radius ceil(3 sigma) <= 32)");
    } else if (kind == FilterKind::bilateral) {
        positive(sigma_s, "--bilateral SIGMA_S");
        positive(sigma_r, "--bilateral SIGMA_R");
        if (sigma_s > 5) throw InputError("--bilateral SIGMA_S: at most 5 (radius ceil(2 sigma_s) <= 10)");
    }
}

float float_threshold(double h) {
    if (std::isnan(h)) throw InputError("--threshold: must be a number");
    if (h >= double(std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
    if (h < -double(std::numeric_limits<float>::max())) return -std::numeric_limits<float>::infinity();
    float f = float(h);
    if (double(f) > h) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

namespace {

using clock = std::chrono::steady_clock;

// Normalised Gaussian weights w[r + i] = exp(-i^2 / (2 sigma^2)) / sum, i = -r..r.
std::vector<double> gaussian_weights(double sigma, int r) {
    std::vector<double> w(2 * r + 1);
    double sum = 0;
    for (int i = -r; i <= r; ++i) sum += w[i + r] = std::exp(-double(i) * i / (2 * sigma * sigma));
    for (double& x : w) x /= sum;
    return w;
}

// Spatial bilateral weights over the cube of radius r, x fastest.
std::vector<double> spatial_weights(double sigma_s, int r) {
    std::vector<double> w;
    for (int dz = -r; dz <= r; ++dz)
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx)
                w.push_back(std::exp(-double(dx * dx + dy * dy + dz * dz) / (2 * sigma_s * sigma_s)));
    return w;
}

// The Gaussian and bilateral filters accumulate in double for the types a float does not
// hold (int32, uint32, float64: is_wide), else in float (kernels/filter.cl acc_t).
std::size_t accumulator_size(ValueType t) { return is_wide(t) ? sizeof(double) : sizeof(float); }

// threshold: a per-vertex field > h; blocks: the selection of blocks of 2×2×2 vertices
// (block_selection; median_rows only); ld_guided: the LD-guided bilateral filter.
enum class Mask { none, threshold, blocks, ld_guided };

// The arguments that end a masked kernel's list (kernels/filter.cl MASK_ARGS, ROW_MASK_ARGS,
// BILATERAL_ARGS): (ld, h) for Mask::threshold, (selection, bnx, bny, phase, tally) for
// Mask::blocks, (ld) for Mask::ld_guided, none for Mask::none.
struct MaskArgs {
    const cl::Buffer* field = nullptr;  // the LD field or the block selection
    cl_float h = 0;
    cl_int bnx = 0, bny = 0, phase = 0;
    const cl::Buffer* tally = nullptr;
};

// A masked kernel: the arguments Head..., then those of the mask it was built for (-DMASKED,
// -DBLOCK_MASKED, -DLD_GUIDED or none), each list a typed call of its own.
template <class... Head> class MaskedCall {
public:
    MaskedCall() = default;
    MaskedCall(Context& ctx, const std::string& name, const std::string& options, Mask mask) : mask_(mask) {
        switch (mask) {
        case Mask::none: none_ = KernelCall<Head...>(ctx, "filter", name, options); break;
        case Mask::threshold: threshold_ = decltype(threshold_)(ctx, "filter", name, options); break;
        case Mask::blocks: blocks_ = decltype(blocks_)(ctx, "filter", name, options); break;
        case Mask::ld_guided: ld_guided_ = decltype(ld_guided_)(ctx, "filter", name, options); break;
        }
    }

    void operator()(const cl::NDRange& global, const cl::NDRange& local, const MaskArgs& m, const Head&... head) {
        switch (mask_) {
        case Mask::none: none_(global, local, head...); break;
        case Mask::threshold: threshold_(global, local, head..., *m.field, m.h); break;
        case Mask::blocks: blocks_(global, local, head..., *m.field, m.bnx, m.bny, m.phase, *m.tally); break;
        case Mask::ld_guided: ld_guided_(global, local, head..., *m.field); break;
        }
    }

private:
    Mask mask_ = Mask::none;
    KernelCall<Head...> none_;
    KernelCall<Head..., cl::Buffer, cl_float> threshold_;
    KernelCall<Head..., cl::Buffer, cl_int, cl_int, cl_int, cl::Buffer> blocks_;
    KernelCall<Head..., cl::Buffer> ld_guided_;
};

// kernels/filter.cl: median_*(in, nx, ny, nz_in, z_begin, nz_out, out, mask...);
// gauss_z_*(in, nx, ny, nz_in, z_begin, nz_out, w, tmp); gauss_y_*(tmp, nx, ny, nz, w, tmp2);
// gauss_x_*(tmp2, nx, ny, nz, w, out, orig, z_begin, mask...);
// bilateral_*(in, nx, ny, nz_in, z_begin, nz_out, w, inv_2sr2 (acc_t), out, mask...).
using MedianCall = MaskedCall<cl::Buffer, cl_int, cl_int, cl_int, cl_int, cl_int, cl::Buffer>;
using GaussZCall = KernelCall<cl::Buffer, cl_int, cl_int, cl_int, cl_int, cl_int, cl::Buffer, cl::Buffer>;
using GaussYCall = KernelCall<cl::Buffer, cl_int, cl_int, cl_int, cl::Buffer, cl::Buffer>;
using GaussXCall = MaskedCall<cl::Buffer, cl_int, cl_int, cl_int, cl::Buffer, cl::Buffer, cl::Buffer, cl_int>;
template <class Acc>
using BilateralCall = MaskedCall<cl::Buffer, cl_int, cl_int, cl_int, cl_int, cl_int, cl::Buffer, Acc, cl::Buffer>;

// Compiles and launches the kernels of one filter on one slab.
class Runner {
public:
    // `window`: the LD window of the block mask (Mask::blocks).
    Runner(Context& ctx, ValueType type, const Dims& d, const FilterSpec& spec, Mask mask, int window = 8)
        : ctx_(ctx), type_(type), d_(d), spec_(spec), mask_(mask), window_(window) {
        rows_ = ctx.tuning.filter_variant == FilterVariant::rows;
        tiled_ = ctx.tuning.filter_variant == FilterVariant::tiled && spec.kind == FilterKind::median;
        items_ = row_items(ctx);
        options_ = type_options(type) + defines({{"RADIUS", std::to_string(spec.radius())}});
        if (is_integer(type)) options_ += " -DINTEGER_VALUES";
        // Double accumulation for the wide types; the int32/uint32 median needs none (nor
        // cl_khr_fp64), float64 programs use double anyway.
        if (type == ValueType::float64 || (is_wide(type) && spec.kind != FilterKind::median))
            options_ += " -DACC_DOUBLE";
        if (is_wide(type) && spec.kind != FilterKind::median) options_ += " -DFP64";
        if (tiled_) options_ += " " + defines({{"TILE_X", std::to_string(tile_x)}, {"TILE_Y", std::to_string(tile_y)}});
        if (mask == Mask::threshold) options_ += " -DMASKED";
        if (mask == Mask::blocks) {
            if (spec.kind != FilterKind::median || !rows_)
                throw std::logic_error("Runner: the block mask is for the median's rows kernel");
            options_ += " -DBLOCK_MASKED";
            tally_ = Buffer<cl_ulong>(ctx, 2 * items_);
        }
        if (mask == Mask::ld_guided) options_ += " -DLD_GUIDED";
        const std::string suffix = rows_ ? "_rows" : "_vertices";
        if (spec.kind == FilterKind::median) {
            median_ = MedianCall(ctx, tiled_ ? "median_tiled" : "median" + suffix, options_, mask);
        } else if (spec.kind == FilterKind::gaussian) {
            gauss_z_ = GaussZCall(ctx, "filter", "gauss_z" + suffix, options_);
            gauss_y_ = GaussYCall(ctx, "filter", "gauss_y" + suffix, options_);
            gauss_x_ = GaussXCall(ctx, "gauss_x" + suffix, options_, mask);
            weights_ = accumulator_buffer(gaussian_weights(spec.sigma, spec.radius()));
        } else {
            if (is_wide(type)) bilateral_double_ = BilateralCall<cl_double>(ctx, "bilateral" + suffix, options_, mask);
            else bilateral_float_ = BilateralCall<cl_float>(ctx, "bilateral" + suffix, options_, mask);
            weights_ = accumulator_buffer(spatial_weights(spec.sigma_s, spec.radius()));
        }
    }

    // Filters output slices z_begin .. z_begin + nz_out - 1 of `in` (nz_in slices) into
    // `out`; `ld` (nz_out slices) and `h` for the masked kernels.
    void run(const cl::Buffer& in, int nz_in, int z_begin, int nz_out, const cl::Buffer& out, const cl::Buffer* ld,
             float h) {
        const int nx = int(d_.nx), ny = int(d_.ny);
        auto round_up = [](std::size_t n, std::size_t m) { return (n + m - 1) / m * m; };
        const cl::NDRange global =
            rows_ ? cl::NDRange(items_)
                  : tiled_ ? cl::NDRange(round_up(d_.nx, tile_x), round_up(d_.ny, tile_y), std::size_t(nz_out))
                           : cl::NDRange(d_.nx, d_.ny, std::size_t(nz_out));
        const cl::NDRange local = rows_ ? cl::NDRange(1) : tiled_ ? cl::NDRange(tile_x, tile_y, 1) : cl::NullRange;
        MaskArgs m;
        m.field = ld;
        m.h = h;
        if (mask_ == Mask::blocks) {
            const Dims hb = ld_block_dims(d_, window_);
            m.bnx = cl_int(hb.nx);
            m.bny = cl_int(hb.ny);
            m.phase = ld_block_phase(window_);
            m.tally = &tally_.get();
        }
        if (spec_.kind == FilterKind::median) {
            median_(global, local, m, in, nx, ny, nz_in, z_begin, nz_out, out);
        } else if (spec_.kind == FilterKind::gaussian) {
            const std::size_t n = d_.nx * d_.ny * std::size_t(nz_out);
            if (tmp_size_ < n) {
                tmp_a_ = Buffer<unsigned char>(ctx_, n * accumulator_size(type_));
                tmp_b_ = Buffer<unsigned char>(ctx_, n * accumulator_size(type_));
                tmp_size_ = n;
            }
            gauss_z_(global, local, in, nx, ny, nz_in, z_begin, nz_out, weights_, tmp_a_.get());
            // The y and x passes read the previous pass's float slab of nz_out slices.
            gauss_y_(global, local, tmp_a_.get(), nx, ny, nz_out, weights_, tmp_b_.get());
            gauss_x_(global, local, m, tmp_b_.get(), nx, ny, nz_out, weights_, out, in, z_begin);
        } else {
            const double inv = 1.0 / (2 * spec_.sigma_r * spec_.sigma_r);  // inv_2sr2 in the accumulator type
            if (is_wide(type_))
                bilateral_double_(global, local, m, in, nx, ny, nz_in, z_begin, nz_out, weights_, cl_double(inv), out);
            else
                bilateral_float_(global, local, m, in, nx, ny, nz_in, z_begin, nz_out, weights_, cl_float(float(inv)),
                                 out);
        }
    }

    // Mask::blocks, after run(): the selected vertices and, of those, the changed ones.
    std::pair<std::size_t, std::size_t> block_tally() {
        std::vector<cl_ulong> t(2 * items_);
        tally_.read(ctx_.queue(), t.data(), t.size());
        std::pair<std::size_t, std::size_t> sum{0, 0};
        for (std::size_t i = 0; i < items_; ++i) {
            sum.first += t[2 * i];
            sum.second += t[2 * i + 1];
        }
        return sum;
    }

private:
    // A read-only buffer of `w` in the accumulator type.
    cl::Buffer accumulator_buffer(const std::vector<double>& w) {
        std::vector<unsigned char> bytes(w.size() * accumulator_size(type_));
        if (is_wide(type_)) {
            std::memcpy(bytes.data(), w.data(), bytes.size());
        } else {
            const std::vector<float> f(w.begin(), w.end());
            std::memcpy(bytes.data(), f.data(), bytes.size());
        }
        return Buffer<unsigned char>(ctx_, bytes).get();
    }

    Context& ctx_;
    ValueType type_;
    Dims d_;
    FilterSpec spec_;
    Mask mask_;
    int window_;
    // Work-group of the tiled median: a 16 x 8 tile of one slice (with its 1-voxel border,
    // three slices of 18 x 10 values in local memory).
    static constexpr std::size_t tile_x = 16, tile_y = 8;
    bool rows_ = true, tiled_ = false;
    std::size_t items_ = 1;
    std::string options_;
    MedianCall median_;
    GaussZCall gauss_z_;
    GaussYCall gauss_y_;
    GaussXCall gauss_x_;
    BilateralCall<cl_float> bilateral_float_;
    BilateralCall<cl_double> bilateral_double_;
    cl::Buffer weights_;
    Buffer<unsigned char> tmp_a_, tmp_b_;  // acc_t values
    Buffer<cl_ulong> tally_;               // Mask::blocks: per work-item selected and changed counts
    std::size_t tmp_size_ = 0;
};

// What one output slice costs: input and output values, two accumulator temporaries
// (Gaussian) and the float LD field (masked); every buffer within the largest allocation,
// all of them within half the device's memory; the filter's radius as halo.
SlabNeed slab_need(const Dims& d, ValueType type, const FilterSpec& spec, Mask mask) {
    const std::size_t slice = d.nx * d.ny, vs = value_size(type);
    const std::size_t temps = spec.kind == FilterKind::gaussian ? 2 : 0, lds = mask != Mask::none ? 1 : 0;
    const std::size_t acc = accumulator_size(type);
    SlabNeed need;
    need.nz = d.nz;
    need.input_slice_bytes = slice * vs;
    need.slice_bytes = slice * (2 * vs + acc * temps + 4 * lds);
    need.largest_slice_bytes = slice * std::max({vs, temps ? acc : vs, lds ? std::size_t(4) : vs});
    need.memory_divisor = 2;
    need.halo = std::size_t(spec.radius());
    return need;
}

// Output slices per slab: all of them when the volume fits, else as many as fit with the
// halo (Tuning::slab_bytes bounds the input slab with its halo when set).
std::size_t slab_slices(const Context& ctx, const Dims& d, ValueType type, const FilterSpec& spec, Mask mask) {
    check_int_axes(d);
    return plan_slab(ctx, slab_need(d, type, spec, mask), d);
}

// Filters `v` into `out` slab by slab; `ld` (float32, same dims) for the masked filters.
// With output slabs of S slices.
void filter_slabs(Context& ctx, const Volume& v, Volume& out, const FilterSpec& spec, Mask mask, const Volume* ld,
                  float h, std::size_t S) {
    const Dims d = v.dims();
    const std::size_t r = std::size_t(spec.radius()), slice = d.nx * d.ny, vs = value_size(v.type());
    const auto* src = static_cast<const unsigned char*>(v.data());
    auto* dst = static_cast<unsigned char*>(out.data());
    with_cl_errors_finished(ctx, [&] {
        Runner runner(ctx, v.type(), d, spec, mask);
        for (std::size_t z0 = 0; z0 < d.nz; z0 += S) {
            const std::size_t z1 = std::min(d.nz, z0 + S);
            const std::size_t zi0 = z0 > r ? z0 - r : 0, zi1 = std::min(d.nz, z1 + r);
            const Dims in_dims{d.nx, d.ny, zi1 - zi0}, out_dims{d.nx, d.ny, z1 - z0};
            const DeviceVolume in(ctx, src + zi0 * slice * vs, in_dims, v.type());
            const DeviceVolume o = DeviceVolume::output(ctx, dst + z0 * slice * vs, out_dims, v.type());
            DeviceVolume m;
            if (ld) m = DeviceVolume(ctx, ld->as<float>() + z0 * slice, out_dims, ValueType::float32);
            runner.run(in.buffer(), int(zi1 - zi0), int(z0 - zi0), int(z1 - z0), o.buffer(), ld ? &m.buffer() : nullptr,
                       h);
            o.download(dst + z0 * slice * vs);
        }
    });
}

// Slabs as planned, smaller when the device runs out of memory (with_smaller_slabs).
void filter_slabs(Context& ctx, const Volume& v, Volume& out, const FilterSpec& spec, Mask mask, const Volume* ld,
                  float h) {
    with_smaller_slabs(slab_slices(ctx, v.dims(), v.type(), spec, mask),
                       [&](std::size_t S) { filter_slabs(ctx, v, out, spec, mask, ld, h, S); });
}

void check_volume(const Volume& v) {
    check_dims(v.dims(), "volume");
    if (v.vertices() == 0) throw InputError("volume: empty");
}

Volume like(const Volume& v) {
    Volume out(v.dims(), v.type(), v.name);
    out.spacing = v.spacing;
    return out;
}

std::size_t count_changed(const Volume& a, const Volume& b) {
    std::size_t changed = 0;
    visit(a, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        const T* q = b.as<T>();
        const long long n = (long long)a.vertices();
#pragma omp parallel for reduction(+ : changed) schedule(static)
        for (long long i = 0; i < n; ++i) changed += p[i] != q[i];
    });
    return changed;
}

std::size_t count_selected(const float* ld, std::size_t n, float h) {
    std::size_t selected = 0;
#pragma omp parallel for reduction(+ : selected) schedule(static)
    for (long long i = 0; i < (long long)n; ++i) selected += ld[i] > h;
    return selected;
}

void set_shares(const Volume& v, TargetedResult& res) {
    res.selected_share = double(res.selected) / double(v.vertices());
    res.changed_share = double(res.changed) / double(v.vertices());
}

void finish_result(const Volume& v, TargetedResult& res) {
    res.changed = count_changed(v, res.volume);
    set_shares(v, res);
}

// The filter of a whole device volume into `out` (its dims and type); `ld` for the masked
// filters.
void run_in_one_piece(const DeviceVolume& v, const FilterSpec& spec, Mask mask, const DeviceVolume* ld, float h,
                      const DeviceVolume& out) {
    check_dims(v.dims(), "volume");
    check_int_axes(v.dims());
    Runner runner(v.context(), v.type(), v.dims(), spec, mask);
    const int nz = int(v.dims().nz);
    runner.run(v.buffer(), nz, 0, nz, out.buffer(), ld ? &ld->buffer() : nullptr, h);
}

// The masked filter of `v` with a given field (float32, v's dims) into res.volume, slab by
// slab, and the count of selected vertices (field > hf).
void field_run(Context& ctx, const Volume& v, const FilterSpec& spec, Mask mask, const Volume& field, float hf,
               TargetedResult& res) {
    filter_slabs(ctx, v, res.volume, spec, mask, &field, hf);
    res.selected = count_selected(field.as<float>(), field.vertices(), hf);
}

// `on_device`: `v` already on the device (the same values), or nullptr to upload it here.
TargetedResult masked_run(Context& ctx, const Volume& v, const FilterSpec& spec, Mask mask, double iso, double h,
                          int window, const DeviceVolume* on_device = nullptr) {
    check_volume(v);
    spec.check();
    if (on_device && (on_device->dims() != v.dims() || on_device->type() != v.type()))
        throw InputError("targeted filter: the device volume is not the volume given (dims or type differ)");
    const float hf = mask == Mask::ld_guided ? 2.0f : float_threshold(h);
    TargetedResult res;
    res.volume = like(v);
    const Dims d = v.dims();
    // `v` on the device: the volume given, or one upload of it when needed.
    std::optional<DeviceVolume> uploaded;
    const auto values_on_device = [&]() -> const DeviceVolume& {
        return on_device ? *on_device : uploaded.emplace(ctx, v);
    };
    auto t = clock::now();
    // Whether the filter with its mask fits one slab (0: not even one slab fits).
    const std::size_t S = int_axes(d) ? slab_fit(ctx, slab_need(d, v.type(), spec, mask)) : 0;
    if (S < d.nz) {
        // Too large for one slab: the LD field in-core on its own, the filter by slabs.
        const Volume ld = local_fractal_dimension(ctx, v, iso, window);
        res.ld_seconds = seconds_since(t);
        t = clock::now();
        field_run(ctx, v, spec, mask, ld, hf, res);
    } else if (mask == Mask::threshold && spec.kind == FilterKind::median && ctx.tuning.filter_variant == FilterVariant::rows) {
        // The median on CPUs: LD > h on blocks of 2×2×2 vertices (block_selection, a byte per
        // block), read as such by the median kernel, which computes only the blocks of 16
        // columns that hold a selected vertex and counts the selected and changed vertices.
        with_cl_errors_finished(ctx, [&] {
            const DeviceVolume& values = values_on_device();
            const Buffer<cl_uchar> selection = block_selection(ctx, values.buffer(), v.type(), d, iso, window, hf);
            ctx.queue().finish();
            res.ld_seconds = seconds_since(t);
            t = clock::now();
            Runner runner(ctx, v.type(), d, spec, Mask::blocks, window);
            const DeviceVolume o = DeviceVolume::output(ctx, res.volume);
            runner.run(values.buffer(), int(d.nz), 0, int(d.nz), o.buffer(), &selection.get(), hf);
            o.download_to(res.volume);
            std::tie(res.selected, res.changed) = runner.block_tally();
        });
        set_shares(v, res);
        res.filter_seconds = seconds_since(t);
        return res;
    } else {
        // One upload: the LD field and the filter read the same device values.
        with_cl_errors_finished(ctx, [&] {
            const DeviceVolume& values = values_on_device();
            const DeviceVolume ld = local_fractal_dimension(values, iso, window);
            ctx.queue().finish();
            res.ld_seconds = seconds_since(t);
            t = clock::now();
            const DeviceVolume o = DeviceVolume::output(ctx, res.volume);
            run_in_one_piece(values, spec, mask, &ld, hf, o);
            o.download_to(res.volume);
            const Volume field = ld.download();
            res.selected = count_selected(field.as<float>(), v.vertices(), hf);
        });
    }
    finish_result(v, res);
    res.filter_seconds = seconds_since(t);
    return res;
}

}  // namespace

Volume apply_filter(Context& ctx, const Volume& v, const FilterSpec& spec) {
    check_volume(v);
    spec.check();
    Volume out = like(v);
    filter_slabs(ctx, v, out, spec, Mask::none, nullptr, 0);
    return out;
}

Volume median_filter(Context& ctx, const Volume& v) { return apply_filter(ctx, v, FilterSpec::median()); }

Volume gaussian_filter(Context& ctx, const Volume& v, double sigma) {
    return apply_filter(ctx, v, FilterSpec::gaussian(sigma));
}

Volume bilateral_filter(Context& ctx, const Volume& v, double sigma_s, double sigma_r) {
    return apply_filter(ctx, v, FilterSpec::bilateral(sigma_s, sigma_r));
}

Volume masked_filter(Context& ctx, const Volume& v, const FilterSpec& spec, const Volume& ld, double h,
                     bool ld_guided) {
    check_volume(v);
    spec.check();
    if (ld.type() != ValueType::float32 || ld.dims() != v.dims())
        throw InputError("LD field: must be float32 of the volume's dims " + dims_string(v.dims()));
    if (ld_guided && spec.kind != FilterKind::bilateral)
        throw std::logic_error("masked_filter: the LD-guided variant is a bilateral filter");
    Volume out = like(v);
    filter_slabs(ctx, v, out, spec, ld_guided ? Mask::ld_guided : Mask::threshold, &ld,
                 ld_guided ? 2.0f : float_threshold(h));
    return out;
}

TargetedResult targeted_filter(Context& ctx, const Volume& v, const FilterSpec& spec, double iso, double h,
                               int window) {
    return masked_run(ctx, v, spec, Mask::threshold, iso, h, window);
}

TargetedResult targeted_filter(const DeviceVolume& on_device, const Volume& v, const FilterSpec& spec, double iso,
                               double h, int window) {
    return masked_run(on_device.context(), v, spec, Mask::threshold, iso, h, window, &on_device);
}

TargetedResult targeted_filter(Context& ctx, const Volume& v, const FilterSpec& spec, const Volume& field, double h) {
    check_volume(v);
    spec.check();
    if (field.type() != ValueType::float32 || field.dims() != v.dims())
        throw InputError("mask field: must be float32 of the volume's dims " + dims_string(v.dims()));
    const auto t = clock::now();
    TargetedResult res;
    res.volume = like(v);
    field_run(ctx, v, spec, Mask::threshold, field, float_threshold(h), res);
    finish_result(v, res);
    res.filter_seconds = seconds_since(t);
    return res;
}

TargetedResult ld_bilateral_filter(Context& ctx, const Volume& v, double sigma_s, double sigma_r, double iso,
                                   int window) {
    return masked_run(ctx, v, FilterSpec::bilateral(sigma_s, sigma_r), Mask::ld_guided, iso, 0, window);
}

DeviceVolume apply_filter(const DeviceVolume& v, const FilterSpec& spec) {
    spec.check();
    DeviceVolume out = allocate_like(v, v.type());
    with_cl_errors([&] { run_in_one_piece(v, spec, Mask::none, nullptr, 0, out); });
    return out;
}

DeviceVolume targeted_filter(const DeviceVolume& v, const FilterSpec& spec, double iso, double h, int window) {
    spec.check();
    const float hf = float_threshold(h);
    DeviceVolume out = allocate_like(v, v.type());
    with_cl_errors([&] {
        const DeviceVolume ld = local_fractal_dimension(v, iso, window);
        run_in_one_piece(v, spec, Mask::threshold, &ld, hf, out);
    });
    return out;
}

}  // namespace clfractal
