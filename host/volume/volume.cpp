// Volume, value types and dimension checks (docs/definitions.md §1 "Grid", §2 "Value types").
#include "clfractal/volume.hpp"
#include "volume/value_counts.hpp"

#include <omp.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

namespace clfractal {

namespace {

struct TypeRow {
    const char* name;
    std::size_t size;
    const char* opencl;
    const char* nrrd;
    bool integer;
    double min, max;
};

// The rows of CLFRACTAL_VALUE_TYPES, indexed by the enumerator.
constexpr TypeRow type_rows[] = {
#define CLFRACTAL_ROW(e, c, cl, nrrd, integer) \
    {#e, sizeof(c), cl, nrrd, integer, double(std::numeric_limits<c>::lowest()), double(std::numeric_limits<c>::max())},
    CLFRACTAL_VALUE_TYPES(CLFRACTAL_ROW)
#undef CLFRACTAL_ROW
};

const TypeRow& row(ValueType t) {
    const auto i = std::size_t(t);
    if (i >= std::size(type_rows)) throw std::logic_error("invalid ValueType " + std::to_string(i));
    return type_rows[i];
}

constexpr std::size_t page = 4096;

std::size_t round_up(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23  // Linux 5.14
#endif

// From this size on, a block's pages are mapped by every core: one thread mapping a big block
// is bound by the kernel zeroing its pages (453 MB: 0.15 s on one core, 0.08 s on two).
constexpr std::size_t parallel_populate_bytes = std::size_t(32) << 20;

// Maps the pages of [p, p + len) (len a multiple of the page), a share of them a thread, by
// MADV_POPULATE_WRITE, or by writing a zero a page where the kernel lacks it; false when the
// kernel has not the memory (ENOMEM: better refused here than killed at a later fault).
bool populate_in_parallel(unsigned char* p, std::size_t len) {
    const std::size_t pages = len / page;
    const int threads = int(std::min<std::size_t>(std::size_t(omp_get_max_threads()), pages / 2048 + 1));
    std::atomic<bool> ok{true};
#pragma omp parallel for num_threads(threads) schedule(static, 1)
    for (int t = 0; t < threads; ++t) {
        unsigned char* const a = p + pages * std::size_t(t) / std::size_t(threads) * page;
        unsigned char* const b = p + pages * std::size_t(t + 1) / std::size_t(threads) * page;
        int r = madvise(a, std::size_t(b - a), MADV_POPULATE_WRITE);
        while (r != 0 && errno == EINTR) r = madvise(a, std::size_t(b - a), MADV_POPULATE_WRITE);
        if (r != 0 && errno == ENOMEM) ok = false;
        else if (r != 0)  // EINVAL: a kernel before 5.14
            for (unsigned char* q = a; q < b; q += page) *reinterpret_cast<volatile unsigned char*>(q) = 0;
    }
    return ok;
}

}  // namespace

// ---------------------------------------------------------------- HostBytes

HostBytes::HostBytes(std::size_t n) : n_(n) {
    if (n == 0) return;
    if (n < (std::size_t(1) << 20)) {
        p_ = static_cast<unsigned char*>(std::aligned_alloc(page, round_up(n, page)));
        if (!p_) throw std::bad_alloc();
        std::memset(p_, 0, n);
        return;
    }
    // The pages are mapped at once: every byte is written next (a read, a copy, a kernel's
    // output), and mapping them in one call is faster than a fault a page. (No MADV_HUGEPAGE:
    // where the kernel defragments for madvised regions, faulting in huge pages stalls for
    // seconds on a busy machine. No MAP_NORESERVE: the kernel's overcommit check then refuses
    // absurd sizes up front, as malloc's would.)
    const std::size_t len = round_up(n, page);
    const bool parallel = len >= parallel_populate_bytes && omp_get_max_threads() > 1;
    void* m = mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | (parallel ? 0 : MAP_POPULATE), -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    p_ = static_cast<unsigned char*>(m);
    mapped_ = len;
    if (parallel && !populate_in_parallel(p_, len)) {
        release();
        throw std::bad_alloc();
    }
}

HostBytes::HostBytes(const HostBytes& o) : HostBytes() {
    if (o.n_ == 0) return;
    // Every byte is overwritten: no point in having the kernel zero more than it must.
    HostBytes copy(o.n_);
    std::memcpy(copy.p_, o.p_, o.n_);
    *this = std::move(copy);
}

HostBytes& HostBytes::operator=(const HostBytes& o) {
    if (this != &o) *this = HostBytes(o);
    return *this;
}

HostBytes HostBytes::borrow(void* p, std::size_t n) {
    HostBytes b;
    b.p_ = static_cast<unsigned char*>(p);
    b.n_ = n;
    b.borrowed_ = true;
    return b;
}

HostBytes::HostBytes(HostBytes&& o) noexcept
    : p_(o.p_), n_(o.n_), mapped_(o.mapped_), borrowed_(o.borrowed_) {
    o.p_ = nullptr;
    o.n_ = o.mapped_ = 0;
    o.borrowed_ = false;
}

HostBytes& HostBytes::operator=(HostBytes&& o) noexcept {
    if (this != &o) {
        release();
        p_ = o.p_;
        n_ = o.n_;
        mapped_ = o.mapped_;
        borrowed_ = o.borrowed_;
        o.p_ = nullptr;
        o.n_ = o.mapped_ = 0;
        o.borrowed_ = false;
    }
    return *this;
}

HostBytes::~HostBytes() { release(); }

void HostBytes::release() noexcept {
    if (borrowed_) {
        // The caller's bytes: nothing to free.
    } else if (mapped_) {
        munmap(p_, mapped_);
    } else {
        std::free(p_);
    }
    p_ = nullptr;
    n_ = mapped_ = 0;
    borrowed_ = false;
}

// ---------------------------------------------------------------- value types

std::size_t value_size(ValueType t) { return row(t).size; }
const char* value_type_name(ValueType t) { return row(t).name; }
const char* opencl_type_name(ValueType t) { return row(t).opencl; }
const char* nrrd_type_name(ValueType t) { return row(t).nrrd; }
bool is_integer(ValueType t) { return row(t).integer; }
bool is_wide(ValueType t) { return t == ValueType::int32 || t == ValueType::uint32 || t == ValueType::float64; }
double type_min(ValueType t) { return row(t).min; }
double type_max(ValueType t) { return row(t).max; }

ValueType parse_value_type(std::string_view name) {
    for (ValueType t : all_value_types)
        if (name == value_type_name(t) || name == opencl_type_name(t)) return t;
    throw InputError("unknown value type '" + std::string(name) + "' (expected " + value_type_names() + ")");
}

std::string value_type_names() {
    std::string s;
    for (ValueType t : all_value_types) s += std::string(s.empty() ? "" : ", ") + value_type_name(t);
    return s;
}

std::size_t Dims::cubes() const {
    if (nx < 2 || ny < 2 || nz < 2) return 0;
    return (nx - 1) * (ny - 1) * (nz - 1);
}

std::string dims_string(const Dims& d) {
    return std::to_string(d.nx) + "x" + std::to_string(d.ny) + "x" + std::to_string(d.nz);
}

void check_dims(const Dims& d, const std::string& what) {
    if (d.nx < 1 || d.ny < 1 || d.nz < 1)
        throw InputError(what + ": dims " + dims_string(d) + " must be at least 1 on every axis");
    // Each factor is <= max_vertices, so dividing before multiplying never overflows.
    const bool too_large = d.nx > max_vertices || d.ny > max_vertices / d.nx ||
                           d.nz > max_vertices / (d.nx * d.ny);
    if (too_large)
        throw InputError(what + ": dims " + dims_string(d) + " exceed the maximum of 2^40 vertices");
}

Volume Volume::wrap(void* data, Dims dims, ValueType type, std::string name) {
    Volume v;
    v.name = std::move(name);
    check_dims(dims, v.name.empty() ? "volume" : v.name);
    v.dims_ = dims;
    v.type_ = type;
    v.bytes_ = HostBytes::borrow(data, dims.vertices() * value_size(type));
    return v;
}

Volume::Volume(Dims dims, ValueType type, std::string name_)
    : name(std::move(name_)), dims_(dims), type_(type) {
    const std::string what = name.empty() ? "volume" : name;
    check_dims(dims, what);
    const std::size_t bytes = dims.vertices() * value_size(type);
    try {
        bytes_ = HostBytes(bytes);
    } catch (const std::bad_alloc&) {
        throw HostOutOfMemory(what + ": cannot allocate " + std::to_string(bytes) + " bytes for " +
                         dims_string(dims) + " " + value_type_name(type));
    }
}

double Volume::value(std::size_t i) const {
    return visit(*this, [i](const auto* p) { return static_cast<double>(p[i]); });
}

namespace {

template <class T> ValueStats integer_stats(const T* p, std::size_t n) {
    T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
#pragma omp parallel for simd reduction(min : lo) reduction(max : hi) schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
        lo = p[i] < lo ? p[i] : lo;
        hi = p[i] > hi ? p[i] : hi;
    }
    return ValueStats{double(lo), double(hi), 0, 0};
}

// Floats: NaN and Inf told by their exponent bits, so that the loop vectorises (with
// std::isnan and std::min it does not); blocks keep the inner counters narrow.
template <class T> ValueStats float_stats(const T* p, std::size_t n) {
    using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
    constexpr U exponent = sizeof(T) == 4 ? U(0x7f800000u) : U(0x7ff0000000000000ull);
    constexpr U mantissa = sizeof(T) == 4 ? U(0x007fffffu) : U(0x000fffffffffffffull);
    T lo = std::numeric_limits<T>::infinity(), hi = -std::numeric_limits<T>::infinity();
    std::size_t nan = 0, inf = 0;
    const std::size_t block = std::size_t(1) << 14, blocks = (n + block - 1) / block;
#pragma omp parallel for reduction(min : lo) reduction(max : hi) reduction(+ : nan, inf) schedule(static)
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t i0 = b * block, i1 = std::min(n, i0 + block);
        U block_nan = 0, block_inf = 0;
        T l = lo, h = hi;
#pragma omp simd reduction(min : l) reduction(max : h) reduction(+ : block_nan, block_inf)
        for (std::size_t i = i0; i < i1; ++i) {
            U u;
            std::memcpy(&u, &p[i], sizeof u);
            const bool special = (u & exponent) == exponent;
            block_nan += special & ((u & mantissa) != 0);
            block_inf += special & ((u & mantissa) == 0);
            const T x = p[i];
            l = special ? l : (x < l ? x : l);
            h = special ? h : (x > h ? x : h);
        }
        nan += block_nan;
        inf += block_inf;
        lo = std::min(lo, l);
        hi = std::max(hi, h);
    }
    if (nan + inf == n) return ValueStats{0, 0, nan, inf};
    return ValueStats{double(lo), double(hi), nan, inf};
}

}  // namespace

ValueStats value_stats(const void* data, ValueType t, std::size_t n) {
    if (n == 0) return {};
    return visit_type(t, [&](auto zero) {
        using T = decltype(zero);
        if constexpr (std::is_integral_v<T>) return integer_stats(static_cast<const T*>(data), n);
        else return float_stats(static_cast<const T*>(data), n);
    });
}

namespace {

// Adds `count` values x to the summary's sums and bins.
struct Binning {
    double lo, width;
    int bins;
    int bin(double x) const { return width > 0 ? std::min(int((x - lo) / width), bins - 1) : 0; }
};

}  // namespace

ValueSummary summarize_values(const Volume& v, int bins) {
    ValueSummary r;
    r.histogram.assign(std::size_t(bins), 0);
    const std::size_t n = v.vertices();
    double sum = 0, sum2 = 0;
    visit(v, [&](const auto* p) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_integral_v<T> && sizeof(T) <= 2) {
            // One pass: the count of every value, then everything from the counts.
            const std::vector<std::uint64_t> counts = detail::value_counts(v);
            const std::size_t values = counts.size();
            auto value_of = [&](std::size_t k) { return double(detail::value_of_bits(k, v.type())); };
            r.stats = detail::stats_of_counts(counts, v.type());
            const Binning b{r.stats.min, (r.stats.max - r.stats.min) / bins, bins};
            for (std::size_t k = 0; k < values; ++k) {
                if (!counts[k]) continue;
                const double x = value_of(k), c = double(counts[k]);
                sum += c * x;
                sum2 += c * x * x;
                r.histogram[std::size_t(b.bin(x))] += counts[k];
            }
        } else {
            r.stats = value_stats(v);
            const Binning b{r.stats.min, (r.stats.max - r.stats.min) / bins, bins};
#pragma omp parallel reduction(+ : sum, sum2)
            {
                std::vector<std::size_t> mine(std::size_t(bins), 0);
#pragma omp for schedule(static) nowait
                for (std::size_t i = 0; i < n; ++i) {
                    const double x = double(p[i]);
                    if (!std::isfinite(x)) continue;
                    sum += x;
                    sum2 += x * x;
                    ++mine[std::size_t(b.bin(x))];
                }
#pragma omp critical
                for (int k = 0; k < bins; ++k) r.histogram[std::size_t(k)] += mine[std::size_t(k)];
            }
        }
    });
    r.finite = n - r.stats.nan - r.stats.inf;
    const double f = double(r.finite);
    r.mean = r.finite ? sum / f : 0;
    r.sd = r.finite ? std::sqrt(std::max(0.0, sum2 / f - r.mean * r.mean)) : 0;
    return r;
}

ValueRange value_range(const Volume& v) {
    const ValueStats s = value_stats(v);
    return ValueRange{s.min, s.max};
}

std::size_t first_non_finite(const void* data, ValueType t, std::size_t n) {
    return visit_type(t, [&](auto zero) {
        using T = decltype(zero);
        if constexpr (std::is_integral_v<T>) {
            return n;
        } else {
            const T* p = static_cast<const T*>(data);
            return std::size_t(std::find_if(p, p + n, [](T f) { return !std::isfinite(f); }) - p);
        }
    });
}

void convert_values(const void* src, ValueType from, void* dst, ValueType to, std::size_t n) {
    visit_type(from, [&](auto from_zero) {
        visit_type(to, [&](auto to_zero) {
            using S = decltype(from_zero);
            using D = decltype(to_zero);
            const S* in = static_cast<const S*>(src);
            D* out = static_cast<D*>(dst);
            const double lo = double(std::numeric_limits<D>::lowest()), hi = double(std::numeric_limits<D>::max());
#pragma omp parallel for schedule(static)
            for (long long i = 0; i < (long long)n; ++i) {
                const S x = in[i];
                if constexpr (std::is_integral_v<D>) {
                    // Every value of every type is exact in double, except int64-sized ones we do not have.
                    out[i] = D(std::clamp(std::nearbyint(double(x)), lo, hi));
                } else {
                    out[i] = D(std::clamp(double(x), lo, hi));
                }
            }
        });
    });
}

Volume convert_volume(const Volume& v, ValueType to) {
    Volume out(v.dims(), to, v.name);
    out.spacing = v.spacing;
    convert_values(v.data(), v.type(), out.data(), to, v.vertices());
    return out;
}

}  // namespace clfractal
