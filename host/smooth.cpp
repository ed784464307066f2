#include "clfractal/smooth.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <type_traits>
#include <vector>

#include "clfractal/local.hpp"
#include "clfractal/span.hpp"

namespace clfractal {

namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t) {
    return std::chrono::duration<double>(clock_type::now() - t).count();
}

// Integer data compares with ceil(s) (as local.cpp): for integers a, b and real s,
// a < s <= b iff a < ceil(s) <= b. Clamped just past the 16-bit ranges.
int integer_isovalue(double s) { return int(std::clamp(std::ceil(s), -65537.0, 65537.0)); }

// The largest float <= h: for a float x, x > h iff x > below(h).
float float_at_or_below(double h) {
    float f = float(h);
    if (double(f) > h) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

// Bits of the per-vertex flags (kernels/smooth.cl): bit a (0, 1, 2) the edge from the
// vertex to its +x, +y, +z neighbour; on the host it means "waiting in the queue". Bit 3:
// LD(v) > h.
constexpr std::uint8_t hot_bit = 8;

// ---------------------------------------------------------------- Algorithm 1, device

std::vector<std::uint8_t> high_fractal_flags(Context& ctx, const Volume& v, double iso, double h, int window,
                                             Volume* keep_ld) {
    const Dims d = v.dims();
    std::vector<std::uint8_t> flags(d.vertices());
    with_cl_errors([&] {
        Buffer<unsigned char> values(ctx, v.size_bytes(), CL_MEM_READ_ONLY);
        values.write(ctx.queue(), static_cast<const unsigned char*>(v.data()), v.size_bytes());
        Buffer<float> ld = local_fractal_dimension(ctx, values, v.type(), d, iso, window);
        Buffer<cl_uchar> out(ctx, d.vertices());
        std::string options = defines({{"T", opencl_type_name(v.type())}});
        if (is_integer(v.type())) options += " -DINTEGER_VALUES";
        cl::Kernel scan = ctx.kernel("smooth", "high_fractal_edges", options);
        scan.setArg(0, values.get());
        scan.setArg(1, ld.get());
        scan.setArg(2, int(d.nx));
        scan.setArg(3, int(d.ny));
        scan.setArg(4, int(d.nz));
        if (is_integer(v.type())) scan.setArg(5, cl_int(integer_isovalue(iso)));
        else scan.setArg(5, cl_float(float(iso)));
        scan.setArg(6, cl_float(float_at_or_below(h)));
        scan.setArg(7, out.get());
        ctx.launch(scan, cl::NDRange(d.nx, d.ny, d.nz));
        out.read(ctx.queue(), flags.data(), flags.size());
        if (keep_ld) {
            Volume field(d, ValueType::float32, v.name);
            field.spacing = v.spacing;
            ld.read(ctx.queue(), field.as<float>(), field.vertices());
            *keep_ld = std::move(field);
        }
    });
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
        return T(std::max(double(-std::numeric_limits<float>::max()), double(f) - delta * weight));
    }
}

template <class T, class S>
Counters run_queue(T* f, std::uint8_t* flags, const Dims& d, S s, bool gaussian, double tau) {
    const long long nx = (long long)d.nx, ny = (long long)d.ny, nz = (long long)d.nz;
    const long long stride[3] = {1, nx, nx * ny};
    const auto intersected = [s](T p, T q) {
        if constexpr (std::is_integral_v<T>) return std::min(int(p), int(q)) < s && s <= std::max(int(p), int(q));
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
        // v and its 26 neighbours in increasing index; changed ones are remembered.
        const long long vx = v % nx, vy = (v / nx) % ny, vz = v / (nx * ny);
        long long changed[27];
        int count = 0;
        for (long long dz = -1; dz <= 1; ++dz)
            for (long long dy = -1; dy <= 1; ++dy)
                for (long long dx = -1; dx <= 1; ++dx) {
                    const long long x = vx + dx, y = vy + dy, z = vz + dz;
                    if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) continue;
                    const long long w = v + dx + dy * stride[1] + dz * stride[2];
                    if (w == v) {
                        changed[count++] = v;
                        continue;
                    }
                    const T lowered = lowered_value(f[w], delta, weight[dx * dx + dy * dy + dz * dz]);
                    if (lowered == f[w]) continue;
                    f[w] = lowered;
                    changed[count++] = w;
                }
        for (int c = 0; c < count; ++c) push_around(changed[c]);
    }
    return out;
}

}  // namespace

SmoothVariant parse_smooth_variant(const std::string& name) {
    if (name == "plain") return SmoothVariant::plain;
    if (name == "gaussian") return SmoothVariant::gaussian;
    throw InputError("--variant '" + name + "': must be plain or gaussian");
}

const char* smooth_variant_name(SmoothVariant v) { return v == SmoothVariant::plain ? "plain" : "gaussian"; }

SmoothResult smooth_isosurface(Context& ctx, const Volume& v, double iso, double h, int window,
                               SmoothVariant variant, double tau, bool keep_ld) {
    check_local_arguments(iso, window);
    if (std::isnan(h)) throw InputError("--threshold: the threshold must be a number");
    if (variant == SmoothVariant::gaussian && !(std::isfinite(tau) && tau > 0))
        throw InputError("--tau: must be a positive finite number");

    SmoothResult r;
    auto t = clock_type::now();
    std::vector<std::uint8_t> flags = high_fractal_flags(ctx, v, iso, h, window, keep_ld ? &r.ld : nullptr);
    r.device_seconds = seconds_since(t);
    for (std::uint8_t b : flags) {
        r.high_vertices += (b & hot_bit) != 0;
        r.initial_edges += (b & 1) + ((b >> 1) & 1) + ((b >> 2) & 1);
    }

    t = clock_type::now();
    r.volume = v;
    const bool gaussian = variant == SmoothVariant::gaussian;
    Counters c;
    visit(r.volume, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_integral_v<T>)
            c = run_queue(p, flags.data(), v.dims(), integer_isovalue(iso), gaussian, tau);
        else
            c = run_queue(p, flags.data(), v.dims(), float(iso), gaussian, tau);
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

IsoCounts intersected_counts(Context& ctx, const Volume& v, double iso) {
    if (!std::isfinite(iso)) throw InputError("--iso: the isovalue must be a finite number");
    const IsovalueSet set = is_integer(v.type()) ? IsovalueSet::integers(integer_isovalue(iso), integer_isovalue(iso))
                                                 : IsovalueSet::floats({float(iso)});
    const SpanResult r = count_spans(ctx, v, set, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 1, 0});
    return IsoCounts{r.get(SpanKind::cubes).counts[0][0], r.get(SpanKind::edges).counts[0][0]};
}

}  // namespace clfractal
