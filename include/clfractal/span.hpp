// Span counts for every isovalue at once (docs/definitions.md §4 "Span and intersection",
// §5 "Isovalue set", §6 "Pyramid levels", §7 "Counts"; thesis chapter 1 and §2.3).
//
// A cube (8 vertices) or grid edge (2 vertices) with span [a, b] = [min, max] is
// intersected by isovalue s iff a < s <= b. I_l(s) counts the intersected cubes and
// E_l(s) the intersected edges of pyramid level l, whose vertices are those of level 0
// with coordinates that are multiples of 2^l (n_l = (n_{l-1} - 1) / 2 + 1 per axis).
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/isovalue_set.hpp"
#include "clfractal/pyramid.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

enum class SpanKind { cubes, edges };

/// Counts of one kind at every level: counts[l][j] for isovalue j at level l.
struct SpanCurves {
    SpanKind kind = SpanKind::cubes;
    std::vector<Dims> level_dims;
    std::vector<std::vector<std::uint64_t>> counts;
};

/// Everything one counting pass produced.
struct SpanResult {
    IsovalueSet isovalues;
    std::vector<SpanCurves> curves;  ///< one per requested kind, in request order
    double seconds = 0;              ///< compute time: the wall time of the counting calls (uploads, kernels,
                                     ///< downloads, waits) less compilation; never below the kernels' own time
    std::size_t slabs = 0;           ///< z-slabs the volume was processed in
    const SpanCurves& get(SpanKind k) const;
};

struct SpanOptions {
    std::vector<SpanKind> kinds{SpanKind::cubes};
    int levels = 2;            ///< pyramid levels 0..levels-1 (>= 1)
    /// Largest slab in slices (0: from the device's memory and Tuning::slab_bytes). Tests
    /// force tiny slabs; results are identical for every slab size.
    std::size_t slab_slices = 0;
    /// Count only the part of the volume between vertex slices z_begin and z_end - 1
    /// (z_end = 0: to the last slice). z_begin must be a multiple of 2^(levels-1); the
    /// part's last slice is shared with the next part, whose counter counts what lies on
    /// it. Counts of parts [b0, b1+1), [b1, b2+1), ..., [bk, nz) add up to the whole
    /// volume's: this is how MPI ranks split a volume.
    std::size_t z_begin = 0, z_end = 0;
};

/// Incremental span counter over z-slabs of a volume (the engine behind count_spans and
/// slice streaming). Slabs are fed in z order; each starts on the last slice of the
/// previous one, at a z that is a multiple of 2^(levels-1).
class SpanCounter {
public:
    SpanCounter(Context& ctx, const IsovalueSet& iso, ValueType type, const Dims& dims,
                const SpanOptions& opt);
    ~SpanCounter();
    SpanCounter(const SpanCounter&) = delete;
    SpanCounter& operator=(const SpanCounter&) = delete;

    /// Counts the slab of `nzs` full-resolution slices starting at slice z0. `data`
    /// holds those slices (nx * ny * nzs values of the counter's type). The first slab
    /// starts at SpanOptions::z_begin.
    void add_slab(const void* data, std::size_t z0, std::size_t nzs);
    /// The same for slices z0 .. z0 + nzs - 1 of a device volume of the counter's dims and
    /// type (no upload).
    void add_slab(const DeviceVolume& volume, std::size_t z0, std::size_t nzs);
    /// Downloads the histograms and forms the prefix sums. Call after the last slab.
    SpanResult finish();
    /// The counts of the slabs added so far, without requiring the last one (the slab
    /// seen last counted as an inner slab: its last slice's x/y edges are not in it).
    /// level_dims are those of the whole volume given to the constructor.
    SpanResult snapshot();

    /// The slab depth (in slices, including the shared last slice) this counter uses.
    std::size_t slab_slices() const;

private:
    struct Impl;
    Impl* impl_;
};

/// Splits the nz slices of a volume into at most `parts` z-ranges [z_begin, z_end) for
/// SpanOptions, as even as the alignment allows: each starts at a multiple of
/// 2^(levels-1) and ends on the next one's first slice. Fewer ranges come back when the
/// volume has too few slices for `parts`.
std::vector<std::pair<std::size_t, std::size_t>> split_slices(std::size_t nz, int levels, std::size_t parts);

/// Counts the spans of `v` for every isovalue of `iso` at every level, on the device,
/// in one pass per slab.
SpanResult count_spans(const DeviceVolume& v, const IsovalueSet& iso, const SpanOptions& opt = {});
/// The same for a host volume, uploaded slab by slab (one upload when it fits one slab),
/// so that a volume larger than the device is counted too.
SpanResult count_spans(Context& ctx, const Volume& v, const IsovalueSet& iso, const SpanOptions& opt = {});

/// Counts the spans of `v` at its default isovalue set, IsovalueSet::for_volume(v, bins)
/// (every integer of the value range for integer data, `bins` uniform values otherwise),
/// returned in SpanResult::isovalues. 8-bit data takes no pass of its own for the value
/// range: it is counted at every value of its type and the curves are cropped to the range,
/// [vmin, vmax], which the level-0 counts give (they are not 0 at vmin + 1 and at vmax, and
/// 0 below and above, when every vertex lies on a cube or edge of the grid; a volume of one
/// value has none). With SpanOptions::z_begin/z_end the set is that of the whole volume.
SpanResult count_spans(Context& ctx, const Volume& v, const SpanOptions& opt, std::size_t bins);
/// The same on `device`, uploaded from `host` (whose values it holds): the range pass,
/// where one is needed, reads `host`.
SpanResult count_spans(const DeviceVolume& device, const Volume& host, const SpanOptions& opt, std::size_t bins);

}  // namespace clfractal
