#include "clfractal/stream.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>

#include "clfractal/local.hpp"
#include "clfractal/pyramid.hpp"

namespace clfractal {

namespace {

// Float slices must be finite, like whole volumes (docs/definitions.md §1 "Grid"); z is the
// slice's index.
void check_slice(const void* slice, ValueType type, std::size_t nx, std::size_t ny, std::size_t z) {
    if (!slice) throw std::logic_error("push_slice: null slice");
    check_finite(slice, type, nx * ny, Dims{nx, ny, z + 1}, z * nx * ny, "stream");
}

std::size_t checked_slice_bytes(std::size_t nx, std::size_t ny, ValueType type) {
    check_dims(Dims{nx, ny, 1}, "slice");
    return nx * ny * value_size(type);
}

}  // namespace

// ---------------------------------------------------------------- SpanStream

struct SpanStream::Impl {
    Context& ctx;
    std::size_t nx, ny;
    ValueType type;
    IsovalueSet iso;
    int levels;
    std::vector<SpanKind> kinds;
    std::size_t slice_bytes;
    std::unique_ptr<SpanCounter> main;  // the full batches, as inner slabs of an open-ended volume
    std::size_t batch = 0;              // slices per batch, one shared with the next
    HostBytes buf;                      // the open batch: slices base .. base + fill - 1 (aligned:
                                        // a CPU device counts it in place, without a copy)
    std::size_t base = 0, fill = 0, n = 0, batches = 0, max_slices = 0;

    Impl(Context& c, std::size_t x, std::size_t y, ValueType t, IsovalueSet i, int l, std::vector<SpanKind> k)
        : ctx(c), nx(x), ny(y), type(t), iso(std::move(i)), levels(l), kinds(std::move(k)),
          slice_bytes(checked_slice_bytes(x, y, t)) {
        if (levels < 1 || levels > 16) throw InputError("--levels must be between 1 and 16");
        const std::size_t align = std::size_t(1) << (levels - 1);
        // A few slices per launch: at least 64 inner slices where 32 MiB allow, else fewer (a
        // launch per slice would cost more in histogram merges than the counting itself).
        std::size_t steps = std::max<std::size_t>(1, (64 + align - 1) / align);
        while (steps > 1 && (steps * align + 1) * slice_bytes > (std::size_t(32) << 20)) --steps;
        // The open-ended volume: as deep as a volume may be.
        max_slices = std::min<std::size_t>(max_vertices / (nx * ny), INT_MAX);
        main = std::make_unique<SpanCounter>(ctx, iso, type, Dims{nx, ny, max_slices},
                                             SpanOptions{kinds, levels, steps * align + 1});
        batch = main->slab_slices();
        buf = HostBytes(batch * slice_bytes);
    }

    void push(const void* slice) {
        std::size_t room = 0;
        std::memcpy(next(room), slice, slice_bytes);
        filled(1);
    }

    void* next(std::size_t& room) {
        room = batch > 1 ? batch - fill : 1;
        return buf.data() + fill * slice_bytes;
    }

    // The k slices at next() were written: check them, then add them.
    void filled(std::size_t k) {
        std::size_t room = 0;
        next(room);
        if (k == 0 || k > room) throw std::logic_error("SpanStream::push_filled: more slices than next_slices() made room for");
        if (n + k > max_slices) throw InputError("stream: more than " + std::to_string(max_slices) + " slices");
        for (std::size_t i = 0; i < k; ++i) check_slice(buf.data() + (fill + i) * slice_bytes, type, nx, ny, n + i);
        fill += k;
        n += k;
        if (fill == batch && batch > 1) {
            main->add_slab(buf.data(), base, batch);
            std::memcpy(buf.data(), buf.data() + (batch - 1) * slice_bytes, slice_bytes);
            base += batch - 1;
            fill = 1;
            ++batches;
        }
    }

    SpanResult counts() {
        SpanResult r;
        r.isovalues = iso;
        const Dims dims{nx, ny, n};
        if (n == 0) {
            for (SpanKind k : kinds) {
                SpanCurves c;
                c.kind = k;
                for (int l = 0; l < levels; ++l) {
                    Dims ld = level_dims(Dims{nx, ny, 1}, l);
                    ld.nz = 0;
                    c.level_dims.push_back(ld);
                    c.counts.emplace_back(iso.size(), 0);
                }
                r.curves.push_back(std::move(c));
            }
            return r;
        }
        // The full batches (inner slabs) plus the open one as the last slab of a volume of
        // `fill` slices starting at `base`, a multiple of 2^(levels-1): its level-l slices
        // are the volume's slices base / 2^l onwards.
        r = main->snapshot();
        SpanCounter tail(ctx, iso, type, Dims{nx, ny, fill}, SpanOptions{kinds, levels, fill});
        tail.add_slab(buf.data(), 0, fill);
        const SpanResult t = tail.finish();
        for (std::size_t k = 0; k < kinds.size(); ++k) {
            SpanCurves& c = r.curves[k];
            for (int l = 0; l < levels; ++l) {
                c.level_dims[l] = level_dims(dims, l);
                for (std::size_t j = 0; j < iso.size(); ++j) c.counts[l][j] += t.curves[k].counts[l][j];
            }
        }
        r.seconds += t.seconds;
        r.slabs = batches + t.slabs;  // the full batches and the open one's
        return r;
    }
};

SpanStream::SpanStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, IsovalueSet iso, int levels)
    : SpanStream(ctx, nx, ny, type, std::move(iso), levels, {SpanKind::cubes, SpanKind::edges}) {}

SpanStream::SpanStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, IsovalueSet iso, int levels,
                       std::vector<SpanKind> kinds)
    : impl_(std::make_unique<Impl>(ctx, nx, ny, type, std::move(iso), levels, std::move(kinds))) {}
SpanStream::~SpanStream() = default;
void SpanStream::push_slice(const void* slice) {
    if (!slice) throw std::logic_error("push_slice: null slice");
    impl_->push(slice);
}
void* SpanStream::next_slices(std::size_t& room) { return impl_->next(room); }
void SpanStream::push_filled(std::size_t n) { impl_->filled(n); }
std::size_t SpanStream::slices() const { return impl_->n; }
SpanResult SpanStream::counts() const { return impl_->counts(); }
FdCurve SpanStream::curve(SpanKind kind) const { return fd_curve(impl_->ctx, counts(), kind); }
ValueType SpanStream::type() const { return impl_->type; }
std::size_t SpanStream::nx() const { return impl_->nx; }
std::size_t SpanStream::ny() const { return impl_->ny; }
int SpanStream::levels() const { return impl_->levels; }
const IsovalueSet& SpanStream::isovalues() const { return impl_->iso; }
std::size_t SpanStream::batch_slices() const { return impl_->batch; }

// ---------------------------------------------------------------- LocalStream

struct LocalStream::Impl {
    Context& ctx;
    std::size_t nx, ny;
    ValueType type;
    double iso;
    std::size_t half, batch;
    Sink sink;
    std::size_t slice_bytes;
    std::vector<unsigned char> buf;  // input slices buf_lo .. received - 1
    std::size_t buf_lo = 0, received = 0, next_out = 0;
    bool finished = false;

    Impl(Context& c, std::size_t x, std::size_t y, ValueType t, double s, int window, Sink f, std::size_t b)
        : ctx(c), nx(x), ny(y), type(t), iso(s), half(std::size_t(std::max(window, 0) / 2)), batch(b),
          sink(std::move(f)), slice_bytes(checked_slice_bytes(x, y, t)) {
        check_local_arguments(iso, window);
        if (batch == 0) throw std::logic_error("LocalStream: batch must be at least 1");
        if (!sink) throw std::logic_error("LocalStream: no sink");
    }

    // The lowest input slice output slice z needs: z - k/2, rounded down to even so that the
    // slab's level-1 slices are the volume's (window W' is floor((z - k/2) / 2) based).
    std::size_t first_needed(std::size_t z) const { return z > half ? (z - half) & ~std::size_t(1) : 0; }

    // Emits output slices [a, b) from the input slab [first_needed(a), hi), hi = b + k/2 or
    // the end of the volume: every window of those slices lies inside the slab (or meets the
    // volume's ends, where the slab ends too), so the field equals the whole-volume one.
    void emit(std::size_t b, std::size_t hi) {
        const std::size_t a = next_out, lo = first_needed(a);
        Volume slab(Dims{nx, ny, hi - lo}, type);
        std::memcpy(slab.data(), buf.data() + (lo - buf_lo) * slice_bytes, slab.size_bytes());
        const Volume ld = local_fractal_dimension(ctx, slab, iso, int(2 * half));
        const std::size_t plane = nx * ny;
        for (std::size_t z = a; z < b; ++z) {
            sink(z, ld.as<float>() + (z - lo) * plane, buf.data() + (z - buf_lo) * slice_bytes);
            next_out = z + 1;
        }
        const std::size_t keep = first_needed(next_out);
        buf.erase(buf.begin(), buf.begin() + std::ptrdiff_t((keep - buf_lo) * slice_bytes));
        buf_lo = keep;
    }

    void push(const void* slice) {
        if (finished) throw std::logic_error("LocalStream::push_slice after finish()");
        check_slice(slice, type, nx, ny, received);
        const auto* p = static_cast<const unsigned char*>(slice);
        buf.insert(buf.end(), p, p + slice_bytes);
        ++received;
        while (received >= next_out + batch + half) emit(next_out + batch, next_out + batch + half);
    }

    void finish() {
        if (finished) return;
        finished = true;
        if (next_out < received) emit(received, received);
    }
};

LocalStream::LocalStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, double iso, int window,
                         Sink sink, std::size_t batch)
    : impl_(std::make_unique<Impl>(ctx, nx, ny, type, iso, window, std::move(sink), batch)) {}
LocalStream::~LocalStream() = default;
void LocalStream::push_slice(const void* slice) { impl_->push(slice); }
void LocalStream::finish() { impl_->finish(); }
const void* LocalStream::input_slice(std::size_t z) const {
    const Impl& s = *impl_;
    if (z < s.buf_lo || z >= s.received) return nullptr;
    return s.buf.data() + (z - s.buf_lo) * s.slice_bytes;
}
std::size_t LocalStream::slices() const { return impl_->received; }
std::size_t LocalStream::emitted() const { return impl_->next_out; }
std::size_t LocalStream::delay() const { return impl_->half + impl_->batch - 1; }
ValueType LocalStream::type() const { return impl_->type; }

struct TargetedFilterStream::Impl {
    Context& ctx;
    std::size_t nx, ny;
    ValueType type;
    FilterSpec spec;
    double h;
    Sink sink;
    std::size_t radius, slice_bytes, selected = 0, changed = 0;
    std::unique_ptr<LocalStream> local;

    Impl(Context& c, std::size_t x, std::size_t y, ValueType t, const FilterSpec& f, double iso, double threshold,
         int window, Sink out)
        : ctx(c), nx(x), ny(y), type(t), spec(f), h(threshold), sink(std::move(out)),
          slice_bytes(checked_slice_bytes(x, y, t)) {
        spec.check();
        if (!sink) throw std::logic_error("TargetedFilterStream: no sink");
        if (!std::isfinite(h)) throw InputError("--threshold: must be a finite number");
        radius = std::size_t(spec.radius());
        if (window >= 2 && radius > std::size_t(window / 2))
            throw InputError("filter radius " + std::to_string(radius) + " exceeds k/2 = " + std::to_string(window / 2) +
                             ": a streamed targeted filter sees k/2 slices around each output slice");
        local = std::make_unique<LocalStream>(
            c, x, y, t, iso, window, [this](std::size_t z, const float* ld, const void*) { emit(z, ld); });
    }

    // Output slice z: the filter of the slab of input slices z - r .. z + r (clamped to the
    // volume, as the whole-volume filter clamps), masked by LD slice z only.
    void emit(std::size_t z, const float* ld) {
        const std::size_t depth = 2 * radius + 1, plane = nx * ny;
        Volume slab(Dims{nx, ny, depth}, type);
        Volume mask(Dims{nx, ny, depth}, ValueType::float32);
        std::fill(mask.as<float>(), mask.as<float>() + mask.vertices(), std::numeric_limits<float>::quiet_NaN());
        std::memcpy(mask.as<float>() + radius * plane, ld, plane * sizeof(float));
        const void* last = nullptr;
        for (std::size_t i = 0; i < depth; ++i) {
            const long zi = long(z) + long(i) - long(radius);
            const void* src = zi < 0 ? local->input_slice(0) : local->input_slice(std::size_t(zi));
            if (!src) src = last;  // past the volume's last slice: clamp to it
            last = src;
            std::memcpy(static_cast<unsigned char*>(slab.data()) + i * slice_bytes, src, slice_bytes);
        }
        const Volume out = masked_filter(ctx, slab, spec, mask, h);
        const auto* filtered = static_cast<const unsigned char*>(out.data()) + radius * slice_bytes;
        const auto* input = static_cast<const unsigned char*>(slab.data()) + radius * slice_bytes;
        const float hf = float_threshold(h);
        const std::size_t size = value_size(type);
        for (std::size_t i = 0; i < plane; ++i) {
            if (ld[i] > hf) ++selected;
            if (std::memcmp(filtered + i * size, input + i * size, size) != 0) ++changed;
        }
        sink(z, filtered, ld);
    }
};

TargetedFilterStream::TargetedFilterStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type,
                                           const FilterSpec& spec, double iso, double h, int window, Sink sink)
    : impl_(std::make_unique<Impl>(ctx, nx, ny, type, spec, iso, h, window, std::move(sink))) {}
TargetedFilterStream::~TargetedFilterStream() = default;
void TargetedFilterStream::push_slice(const void* slice) { impl_->local->push_slice(slice); }
void TargetedFilterStream::finish() { impl_->local->finish(); }
std::size_t TargetedFilterStream::slices() const { return impl_->local->slices(); }
std::size_t TargetedFilterStream::emitted() const { return impl_->local->emitted(); }
std::size_t TargetedFilterStream::selected() const { return impl_->selected; }
std::size_t TargetedFilterStream::changed() const { return impl_->changed; }

}  // namespace clfractal
