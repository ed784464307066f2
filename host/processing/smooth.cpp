#include "clfractal/smooth.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <type_traits>
#include <vector>

#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/span.hpp"
#include "device/type_options.hpp"
#include "device/kernel_call.hpp"
#include "device/name_table.hpp"
#include "device/slab_plan.hpp"

namespace clfractal {

namespace {

using clock_type = std::chrono::steady_clock;

// Bits of the per-vertex flags (kernels/smooth.cl): bit a (0, 1, 2) the edge from the
// vertex to its +x, +y, +z neighbour; on the host it means "waiting in the queue". Bit 3:
// LD(v) > h.
constexpr std::uint8_t hot_bit = 8;

// ---------------------------------------------------------------- Algorithm 1, device

// The flags of the vertices of `values` (on the device, with their LD field `ld`): kernels/
// smooth.cl high_fractal_edges(vol, ld, nx, ny, nz, s, h, flags); the first `count` read into
// `dst`.
void scan_flags(const DeviceVolume& values, const DeviceVolume& ld, double iso, double h, std::uint8_t* dst,
                std::size_t count) {
    Context& ctx = values.context();
    const Dims d = values.dims();
    Buffer<cl_uchar> out(ctx, d.vertices());
    KernelCall<cl::Buffer, cl::Buffer, int, int, int, ScalarArg, cl_float, cl::Buffer> scan(
        ctx, "smooth", "high_fractal_edges", single_isovalue_options(values.type()));
    scan(cl::NDRange(d.nx, d.ny, d.nz), cl::NullRange, values.buffer(), ld.buffer(), int(d.nx), int(d.ny), int(d.nz),
         isovalue_arg(values.type(), iso), cl_float(float_threshold(h)), out.get());
    out.read(ctx.queue(), dst, count);
}

std::vector<std::uint8_t> high_fractal_flags(const DeviceVolume& v, double iso, double h, int window, Volume* keep_ld) {
    std::vector<std::uint8_t> flags(v.dims().vertices());
    with_cl_errors([&] {
        const DeviceVolume ld = local_fractal_dimension(v, iso, window);
        scan_flags(v, ld, iso, h, flags.data(), flags.size());
        if (keep_ld) *keep_ld = ld.download();
    });
    return flags;
}

// The same flags slab by slab, for CPU devices, whose buffers are host memory: output slices
// [a, b) from the LD field of ld_input_slices(a, b + 1) (slice b too: the z-edges of slice
// b - 1 read its LD), so each slab gives exactly the whole-volume flags while the buffers stay
// about 192 MiB.
std::vector<std::uint8_t> high_fractal_flags_slabs(Context& ctx, const Volume& v, double iso, double h, int window) {
    const Dims d = v.dims();
    const std::size_t plane = d.nx * d.ny;
    const std::size_t vs = value_size(v.type());
    // Tuning::slab_bytes (the values of one slab's output slices) lets tests force thin slabs.
    const std::size_t depth = ctx.tuning.slab_bytes
                                  ? std::max<std::size_t>(1, ctx.tuning.slab_bytes / (plane * vs))
                                  : std::max<std::size_t>(4 * std::size_t(window), (std::size_t(192) << 20) / (32 * plane));
    std::vector<std::uint8_t> flags(d.vertices());
    for (std::size_t a = 0; a < d.nz; a += depth) {
        const std::size_t b = std::min(d.nz, a + depth), e = std::min(d.nz, b + 1);
        const auto [lo, hi] = ld_input_slices(a, e, d.nz, window);
        Volume slab(Dims{d.nx, d.ny, hi - lo}, v.type());
        std::memcpy(slab.data(), static_cast<const unsigned char*>(v.data()) + lo * plane * vs, slab.size_bytes());
        const Volume ld = local_fractal_dimension(ctx, slab, iso, window);
        const Dims part{d.nx, d.ny, e - a};  // slices [a, e) of the slab and of its field
        const std::size_t skip = (a - lo) * plane;  // a structured binding is not captured in C++17
        with_cl_errors([&] {
            const DeviceVolume pv(ctx, static_cast<const unsigned char*>(slab.data()) + skip * vs, part, v.type());
            const DeviceVolume pl(ctx, ld.as<float>() + skip, part, ValueType::float32);
            scan_flags(pv, pl, iso, h, flags.data() + a * plane, (b - a) * plane);
        });
    }
    return flags;
}

// ---------------------------------------------------------------- Algorithm 2, host

struct Counters {
    std::uint64_t processed = 0, lowered = 0;
};

// f - Delta * weight under the rounding rules of smooth.hpp; never above f.
template <class T> T lowered_value(T f, double delta, double weight) {
    if constexpr (std::is_integral_v<T>) {
        const double dec = std::floor(delta * weight + 0.5);
        const double x = std::max(double(std::numeric_limits<T>::min()), double(f) - dec);
        return T(x);
    } else {
        return T(std::max(double(std::numeric_limits<T>::lowest()), double(f) - delta * weight));
    }
}

// The gaussian variant's step after f(v) was lowered by delta: each 26-neighbour w of v is
// lowered by delta * weight[|w - v|^2]. Writes v and the changed neighbours, in increasing
// index, to `changed` and returns their number.
template <class T>
int lower_neighbours(T* f, const Dims& d, long long v, double delta, const double weight[4], long long changed[27]) {
    const long long nx = (long long)d.nx, ny = (long long)d.ny, nz = (long long)d.nz;
    const long long vx = v % nx, vy = (v / nx) % ny, vz = v / (nx * ny);
    int count = 0;
    for (long long dz = -1; dz <= 1; ++dz)
        for (long long dy = -1; dy <= 1; ++dy)
            for (long long dx = -1; dx <= 1; ++dx) {
                const long long x = vx + dx, y = vy + dy, z = vz + dz;
                if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) continue;
                const long long w = v + dx + dy * nx + dz * nx * ny;
                if (w == v) {
                    changed[count++] = v;
                    continue;
                }
                const T lowered = lowered_value(f[w], delta, weight[dx * dx + dy * dy + dz * dz]);
                if (lowered == f[w]) continue;
                f[w] = lowered;
                changed[count++] = w;
            }
    return count;
}

template <class T, class S>
Counters run_queue(T* f, std::uint8_t* flags, const Dims& d, S s, bool gaussian, double tau) {
    const long long nx = (long long)d.nx, ny = (long long)d.ny, nz = (long long)d.nz;
    const long long stride[3] = {1, nx, nx * ny};
    const auto intersected = [s](T p, T q) {
        if constexpr (std::is_integral_v<T>)
            return std::min(std::int64_t(p), std::int64_t(q)) < s && s <= std::max(std::int64_t(p), std::int64_t(q));
        else return std::min(p, q) < s && s <= std::max(p, q);
    };
    double weight[4] = {1, 0, 0, 0};
    for (int k = 1; k <= 3; ++k) weight[k] = std::exp(-double(k) / (2.0 * tau * tau));

    std::deque<std::uint64_t> queue;  // edge id 3 * (lower vertex index) + axis
    const std::size_t n = d.vertices();
    for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            if (flags[i] & (1u << a)) queue.push_back(3 * std::uint64_t(i) + a);

    // Pushes the edge from vertex c along axis a (0..2) in direction dir (-1, +1) if it
    // exists, is intersected and high fractal, and is not already waiting.
    const auto consider = [&](long long c, const long long coord[3], int a, int dir) {
        const long long lim = a == 0 ? nx : a == 1 ? ny : nz;
        if (dir < 0 ? coord[a] == 0 : coord[a] + 1 == lim) return;
        const long long o = c + dir * stride[a];
        const long long lo = std::min(c, o);
        const std::uint8_t bit = std::uint8_t(1u << a);
        if (flags[lo] & bit) return;
        if (!intersected(f[c], f[o])) return;
        if (!((flags[c] | flags[o]) & hot_bit)) return;
        flags[lo] |= bit;
        queue.push_back(3 * std::uint64_t(lo) + a);
    };
    // The 6 edges of vertex c in increasing index of their other end.
    const auto push_around = [&](long long c) {
        const long long coord[3] = {c % nx, (c / nx) % ny, c / (nx * ny)};
        consider(c, coord, 2, -1);
        consider(c, coord, 1, -1);
        consider(c, coord, 0, -1);
        consider(c, coord, 0, +1);
        consider(c, coord, 1, +1);
        consider(c, coord, 2, +1);
    };

    Counters out;
    while (!queue.empty()) {
        const std::uint64_t e = queue.front();
        queue.pop_front();
        const long long i = (long long)(e / 3);
        const int a = int(e % 3);
        const long long j = i + stride[a];
        flags[i] &= std::uint8_t(~(1u << a));
        ++out.processed;
        if (!intersected(f[i], f[j])) continue;
        ++out.lowered;
        const long long v = f[i] > f[j] ? i : j, u = v == i ? j : i;
        if (!gaussian) {
            f[v] = f[u];
            push_around(v);
            continue;
        }
        const double delta = double(f[v]) - double(f[u]);
        f[v] = f[u];
        long long changed[27];
        const int count = lower_neighbours(f, d, v, delta, weight, changed);
        for (int c = 0; c < count; ++c) push_around(changed[c]);
    }
    return out;
}

}  // namespace

template <> struct detail::NameTable<SmoothVariant> {
    static constexpr const char* what = "--variant";
    static constexpr std::pair<SmoothVariant, const char*> names[] = {{SmoothVariant::plain, "plain"},
                                                                      {SmoothVariant::gaussian, "gaussian"}};
};
CLFRACTAL_NAME_TABLE(SmoothVariant)

SmoothVariant parse_smooth_variant(const std::string& name) { return parse_variant<SmoothVariant>(name); }

const char* smooth_variant_name(SmoothVariant v) { return variant_name(v); }

namespace {

void check_smooth_arguments(double iso, double h, int window, SmoothVariant variant, double tau) {
    check_local_arguments(iso, window);
    if (std::isnan(h)) throw InputError("--threshold: the threshold must be a number");
    if (variant == SmoothVariant::gaussian && !(std::isfinite(tau) && tau > 0))
        throw InputError("--tau: must be a positive finite number");
}

// Algorithms 1 (on the device, `dv`) and 2 (on the host, `v`: the same values).
// Algorithm 2 on a copy of `v`, given the flags of Algorithm 1.
SmoothResult smooth(std::vector<std::uint8_t> flags, const Volume& v, double iso, SmoothVariant variant, double tau,
                    SmoothResult r) {
    for (std::uint8_t b : flags) {
        r.high_vertices += (b & hot_bit) != 0;
        r.initial_edges += (b & 1) + ((b >> 1) & 1) + ((b >> 2) & 1);
    }

    const auto t = clock_type::now();
    r.volume = v;
    const bool gaussian = variant == SmoothVariant::gaussian;
    Counters c;
    visit(r.volume, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_integral_v<T>)
            c = run_queue(p, flags.data(), v.dims(), integer_isovalue(iso), gaussian, tau);
        else
            c = run_queue(p, flags.data(), v.dims(), T(iso), gaussian, tau);  // float32: float(s); float64: s
    });
    r.edges_processed = c.processed;
    r.edges_lowered = c.lowered;
    visit(v, [&](const auto* in) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(in)>>;
        const T* out = r.volume.as<T>();
        for (std::size_t i = 0; i < v.vertices(); ++i) r.vertices_changed += in[i] != out[i];
    });
    r.queue_seconds = seconds_since(t);
    return r;
}

// Algorithm 1 on the device copy `dv` of `v`, Algorithm 2 on `v`.
SmoothResult smooth_on_device(const DeviceVolume& dv, const Volume& v, double iso, double h, int window,
                              SmoothVariant variant, double tau, bool keep_ld) {
    SmoothResult r;
    const auto t = clock_type::now();
    std::vector<std::uint8_t> flags = high_fractal_flags(dv, iso, h, window, keep_ld ? &r.ld : nullptr);
    r.device_seconds = seconds_since(t);
    return smooth(std::move(flags), v, iso, variant, tau, std::move(r));
}

}  // namespace

SmoothResult smooth_isosurface(Context& ctx, const Volume& v, double iso, double h, int window,
                               SmoothVariant variant, double tau, bool keep_ld) {
    check_smooth_arguments(iso, h, window, variant, tau);
    // On a CPU device, a volume above 64 MiB without the field to keep: the flags slab by
    // slab (no whole-volume LD field or device copy beside the values).
    const bool slabs = copy_doubles_host_memory(ctx, v.size_bytes()) || (ctx.is_cpu() && ctx.tuning.slab_bytes);
    if (slabs && !keep_ld && v.dims().nz > 1) {
        SmoothResult r;
        const auto t = clock_type::now();
        std::vector<std::uint8_t> flags = high_fractal_flags_slabs(ctx, v, iso, h, window);
        r.device_seconds = seconds_since(t);
        return smooth(std::move(flags), v, iso, variant, tau, std::move(r));
    }
    return smooth_on_device(DeviceVolume(ctx, v), v, iso, h, window, variant, tau, keep_ld);
}

SmoothResult smooth_isosurface(const DeviceVolume& v, double iso, double h, int window, SmoothVariant variant,
                               double tau, bool keep_ld) {
    check_smooth_arguments(iso, h, window, variant, tau);
    return smooth_on_device(v, v.download(), iso, h, window, variant, tau, keep_ld);
}

IsoCounts intersected_counts(Context& ctx, const Volume& v, double iso) {
    return intersected_counts(DeviceVolume(ctx, v), iso);
}

IsoCounts intersected_counts(const DeviceVolume& v, double iso) {
    if (!std::isfinite(iso)) throw InputError("--iso: the isovalue must be a finite number");
    const IsovalueSet set = IsovalueSet::single(v.type(), iso);
    const SpanResult r = count_spans(v, set, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 1, 0});
    return IsoCounts{r.get(SpanKind::cubes).counts[0][0], r.get(SpanKind::edges).counts[0][0]};
}

}  // namespace clfractal
