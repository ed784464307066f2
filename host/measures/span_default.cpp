// count_spans at a volume's default isovalue set (clfractal/span.hpp; docs/definitions.md §5
// "Isovalue set"): 8-bit data counted at every value of its type and cropped to its value
// range, which the counts themselves give, so that the range costs no pass of its own.
#include "clfractal/span.hpp"

#include <algorithm>

namespace clfractal {

namespace {

// Whether every vertex of a grid of `d` lies on a cube (an edge) of it: then the value range
// [vmin, vmax] of a volume of more than one value is where the level-0 counts are not 0, from
// vmin + 1 to vmax. A vertex of value vmin lies on a cube (an edge) with a vertex of another
// value (the cubes, and the edges, join every vertex to every other), whose span [vmin, b]
// with b > vmin is intersected at vmin + 1 and at no integer at or below vmin; likewise at
// vmax, and at nothing above it.
bool every_vertex_counted(const Dims& d, SpanKind k) {
    return k == SpanKind::cubes ? d.nx >= 2 && d.ny >= 2 && d.nz >= 2 : d.vertices() >= 2;
}

// `count(set)` at `host`'s default set; `host` holds the values counted.
template <class Count>
SpanResult default_spans(const Volume& host, const SpanOptions& opt, std::size_t bins, Count count) {
    const Dims& d = host.dims();
    const ValueType t = host.type();
    const bool whole = opt.z_begin == 0 && (opt.z_end == 0 || opt.z_end >= d.nz);
    const bool crop = value_size(t) == 1 && whole && !opt.kinds.empty() &&
                      std::all_of(opt.kinds.begin(), opt.kinds.end(),
                                  [&](SpanKind k) { return every_vertex_counted(d, k); });
    if (!crop) return count(IsovalueSet::for_volume(host, bins));
    const auto lowest = std::int64_t(type_min(t));
    SpanResult r = count(IsovalueSet::integers(lowest, std::int64_t(type_max(t))));
    const std::vector<std::uint64_t>& c = r.curves.front().counts.front();
    const auto nonzero = [](std::uint64_t n) { return n != 0; };
    const auto first = std::find_if(c.begin(), c.end(), nonzero);
    std::size_t from, to;  // the kept indices [from, to)
    if (first == c.end()) {
        // One value (host.vertices() >= 2 here): the set of that value alone, counted 0.
        from = std::size_t(std::int64_t(host.value(0)) - lowest);
        to = from + 1;
    } else {
        from = std::size_t(first - c.begin()) - 1;  // the count at the type's lowest value is 0
        to = std::size_t(c.rend() - std::find_if(c.rbegin(), c.rend(), nonzero));
    }
    for (SpanCurves& curves : r.curves)
        for (std::vector<std::uint64_t>& level : curves.counts)
            level = std::vector<std::uint64_t>(level.begin() + std::ptrdiff_t(from), level.begin() + std::ptrdiff_t(to));
    r.isovalues = IsovalueSet::integers(lowest + std::int64_t(from), lowest + std::int64_t(to) - 1);
    return r;
}

}  // namespace

SpanResult count_spans(Context& ctx, const Volume& v, const SpanOptions& opt, std::size_t bins) {
    return default_spans(v, opt, bins, [&](const IsovalueSet& iso) { return count_spans(ctx, v, iso, opt); });
}

SpanResult count_spans(const DeviceVolume& device, const Volume& host, const SpanOptions& opt, std::size_t bins) {
    if (device.dims() != host.dims() || device.type() != host.type())
        throw std::invalid_argument("count_spans: the device volume was not uploaded from this host volume");
    return default_spans(host, opt, bins, [&](const IsovalueSet& iso) { return count_spans(device, iso, opt); });
}

}  // namespace clfractal
