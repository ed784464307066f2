// Isosurface components for every isovalue at once, and their correlation with the
// fractal dimension (docs/definitions.md §19 "Isosurface components", §20 "Correlation";
// thesis §3.1).
//
// With A = {f < s} and C = {f >= s}, the isosurface at s has
//   components(s) = b0(A) + b0(C) - 1   (0 when A or C is empty)
// connected pieces, because the contour tree of a box is a tree. Connectivity modes:
//   cube        A 6-connected, C 26-connected (marching cubes with separated negative
//               vertices; Wenger's ijkscalarinfo);
//   freudenthal both 14-connected (±x, ±y, ±z, ±(x+y), ±(y+z), ±(x+z), ±(x+y+z)): the
//               piecewise-linear function of the Freudenthal triangulation (marching
//               tetrahedra).
// All isovalues come from two union-find sweeps over the vertices sorted by (value,
// index): increasing with A's neighbourhood (join: down(v) = distinct components among
// the neighbours already swept) and decreasing with C's (split: up(v)); then
//   components(s) = sum over f(v) < s of (up(v) - down(v)),
// one prefix sum over the isovalues.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

enum class Connectivity { cube, freudenthal };

/// "cube" / "freudenthal"; throws InputError on anything else.
Connectivity parse_connectivity(const std::string& name);
/// "cube" / "freudenthal".
const char* connectivity_name(Connectivity c);

struct ComponentCurve {
    IsovalueSet isovalues;
    std::vector<std::int64_t> components;  ///< one per isovalue
    double seconds = 0;                    ///< wall time of masks, sorting, sweeps and prefix sum (no compilation)
};

/// components(s) for every isovalue of `iso` (integers or a list in the data's own type,
/// compared exactly as the span counts). Two union-find sweeps on the host, one a core (they
/// are sequential): a vertex whose swept neighbours form one group is linked in index order,
/// without a sort or a find, and only the others are sorted by (value, index) (counting sort
/// for 8- and 16-bit data, 32-bit keys for other 32-bit types, comparisons for float64) and
/// swept. Memory beyond the volume: 4 bytes a vertex for the neighbour masks (computed on
/// the device when the volume is there), 4 for each sweep's forest (8 above 2^32 vertices)
/// and 12 for each vertex a sweep sorts; integer data whose sweeps would pass 4 volumes + 128
/// MiB is ordered a window at a time instead (Tuning::component_window). A volume of more than 2^21 vertices is cut into z-slabs of about 2^20
/// vertices sharing a slice (Tuning::component_slab_slices), each ordered and swept on the
/// host on every core at once and all joined exactly by their boundary links
/// (docs/definitions.md §28): the same curve, memory the volume + about 20 bytes a slab
/// vertex a thread + O(slice).
ComponentCurve count_components(Context& ctx, const Volume& v, const IsovalueSet& iso,
                                Connectivity mode = Connectivity::cube);
/// The same for a volume already on the device: the device steps read it there, the
/// union-find sweeps run on a downloaded copy.
ComponentCurve count_components(const DeviceVolume& v, const IsovalueSet& iso, Connectivity mode = Connectivity::cube);

/// components(s) at each of a few isovalues (each as IsovalueSet::single makes it: integer
/// data ceil(s), float32 data s rounded to float32, float64 data s; 0 where that leaves A or C
/// the whole grid, as for s beyond the type's range), equal to the curve of
/// count_components there (finite data). Labels A = {f < s} and C = {f >= s} directly, up to 8
/// isovalues in one pass over the volume: runs of vertices along x joined by union-find plane
/// by plane, in z-chunks on every core joined at their seams. Memory O(slice) an isovalue;
/// cheaper than the curve for
/// up to a few dozen isovalues. Throws InputError for a non-finite isovalue or a slice of 2^30
/// vertices or more.
std::vector<std::int64_t> count_components_at(const Volume& v, const std::vector<double>& isovalues,
                                              Connectivity mode = Connectivity::cube);
/// components(s) at a few isovalues of a volume given in z order, a batch of slices at a time
/// (a file larger than memory, a scanner's slices as they arrive): after the last slice,
/// counts() equals count_components_at on the whole volume. Each batch is labelled in z-chunks
/// on every core and joined to the slices before it at their seam; between batches only the
/// last slice's runs are kept (memory O(slice) an isovalue).
class ComponentsAtStream {
public:
    /// Slices of nx x ny vertices of `type`; the isovalues as count_components_at takes them
    /// (InputError for a non-finite one, an empty slice or one of 2^30 vertices or more).
    ComponentsAtStream(std::size_t nx, std::size_t ny, ValueType type, const std::vector<double>& isovalues,
                       Connectivity mode = Connectivity::cube);
    ~ComponentsAtStream();
    ComponentsAtStream(ComponentsAtStream&&) noexcept;
    ComponentsAtStream& operator=(ComponentsAtStream&&) noexcept;

    /// The next `count` slices: nx * ny * count values of the type, x fastest, then y, then z
    /// (InputError, nothing added, when float slices hold NaN or Inf).
    void push_slices(const void* slices, std::size_t count);
    /// The slices pushed so far.
    std::size_t slices() const;
    /// components(s) of the slices pushed so far, one an isovalue (0 before any).
    std::vector<std::int64_t> counts() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Up to this many isovalues, `clfractal components` and Python's `components()` label each
/// directly (count_components_at) instead of sorting and sweeping the whole volume.
constexpr std::size_t few_isovalues = 32;

/// components(s) at a few isovalues as above, labelled where ctx.tuning.labelling says
/// (LabellingPath: the host on CPU devices, the device elsewhere). The device labelling is
/// union-find over the runs of A and C along x with 32-bit atomics: labels are vertex indices
/// in 32 bits, so it takes volumes below 2^32 vertices whose 4 bytes of labels a vertex fit
/// the device's largest allocation; other volumes are labelled on the host. Same counts on
/// either path.
std::vector<std::int64_t> count_components_at(Context& ctx, const Volume& v, const std::vector<double>& isovalues,
                                              Connectivity mode = Connectivity::cube);
/// The same for a volume already on the device: labelled there when the rule above picks the
/// device (no download), else downloaded and labelled on the host.
std::vector<std::int64_t> count_components_at(const DeviceVolume& v, const std::vector<double>& isovalues,
                                              Connectivity mode = Connectivity::cube);

/// components(s) at one isovalue (as above).
std::int64_t count_components_at(Context& ctx, const Volume& v, double isovalue,
                                 Connectivity mode = Connectivity::cube);

/// The same for a volume already on the device.
std::int64_t count_components_at(const DeviceVolume& v, double isovalue, Connectivity mode = Connectivity::cube);

/// Pearson correlation of x and y (population moments, centred on the host, the three dot
/// products with CLBlast on the device). NaN with fewer than 2 points or zero variance.
double pearson(Context& ctx, const std::vector<double>& x, const std::vector<double>& y);

/// docs/definitions.md §20 "Correlation": over the isovalues where D(s) is defined and the
/// level-0 edge count E(s) >= (product of the two smallest vertex dims) / 4, Pearson of D
/// with components(s) and with components(s) / E(s).
struct ComponentCorrelation {
    std::size_t used = 0;                ///< isovalues that enter
    double components = 0;               ///< corr(D, components)
    double components_per_area = 0;      ///< corr(D, components / E)
};
ComponentCorrelation correlate_components(Context& ctx, const std::vector<double>& fd,
                                          const std::vector<std::uint64_t>& edges,
                                          const std::vector<std::int64_t>& components, const Dims& dims);

}  // namespace clfractal
