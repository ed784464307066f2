// Smooth isosurface construction (docs/definitions.md §18 "Smooth isosurface construction";
// thesis chapter 5, Algorithms 1 and 2).
//
// For isovalue s, threshold h and window k the LD field (local.hpp) is computed once, on
// the input volume. A grid edge (u, w) is intersected iff its span [a, b] has a < s <= b
// (compared in the data's type, as local.hpp does), and "high fractal" iff it is
// intersected and LD(u) > h or LD(w) > h (NaN never is).
//
// Algorithm 1 (on the device): the queue starts with every high-fractal edge, in vertex
// index order, for each vertex its +x, +y, +z edge.
// Algorithm 2 (on the host, FIFO): pop an edge, oriented (v, u) with f(v) > f(u); if it is
// still intersected set f(v) := f(u), then push every edge around every changed vertex that
// is now intersected and high fractal. Changed vertices are taken in increasing index, and
// the 6 edges of each in increasing index of their other end (-z, -y, -x, +x, +y, +z).
//
// Variant `gaussian` (the thesis' non-blocky one): with Delta = f(v) - f(u) (before the
// change), each of the 26 neighbours w of v inside the grid (u among them) is lowered too,
// by Delta * exp(-d^2 / (2 tau^2)), d^2 = 1, 2 or 3 the squared distance in grid steps
// (spacing is ignored). Arithmetic, in double:
//   - integer data: the decrement is rounded to nearest, halves up (floor(x + 0.5)), and the
//     result clamped to the type's minimum; a decrement that rounds to 0 changes nothing;
//   - float data: f(w) - Delta * weight, clamped to the type's lowest value (-FLT_MAX,
//     -DBL_MAX), rounded to the type (float32: to nearest, so never above f(w)).
// So values never increase, and f(v) := f(u) exactly.
//
// Termination and cost: once an edge's two ends are below s it is never intersected again,
// so an edge is intersected during one interval of the run and is queued at most once
// (an edge already waiting in the queue is not queued twice; this yields exactly the values
// the algorithm with duplicate entries yields, as a duplicate can only be popped after the
// first entry, when the edge is no longer intersected). The run is O(n + m). At the end no
// intersected edge is high fractal.
#pragma once
#include <cstdint>
#include <string>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

enum class SmoothVariant { plain, gaussian };

/// "plain" / "gaussian"; throws InputError on anything else.
SmoothVariant parse_smooth_variant(const std::string& name);
const char* smooth_variant_name(SmoothVariant v);

struct SmoothResult {
    Volume volume;                       ///< the smoothed volume: same dims, type and spacing
    Volume ld;                           ///< the LD field used (float32), when keep_ld was set
    std::uint64_t high_vertices = 0;     ///< vertices with LD > h
    std::uint64_t initial_edges = 0;     ///< high-fractal edges of the input (Algorithm 1)
    std::uint64_t edges_processed = 0;   ///< edges popped from the queue (each at most once)
    std::uint64_t edges_lowered = 0;     ///< of those, still intersected when popped: f(v) := f(u)
    std::uint64_t vertices_changed = 0;  ///< vertices whose final value differs from the input
    double device_seconds = 0;           ///< upload, LD field and edge scan, download
    double queue_seconds = 0;            ///< Algorithm 2 on the host
};

/// Runs Algorithms 1 and 2 on `v` (any of the four types). Throws InputError when the
/// window is odd or below 2, the isovalue is not finite, h is NaN, or tau is not a positive
/// finite number (only read by the gaussian variant).
SmoothResult smooth_isosurface(Context& ctx, const Volume& v, double iso, double h, int window = 8,
                               SmoothVariant variant = SmoothVariant::plain, double tau = 1.0,
                               bool keep_ld = false);
/// The same for a volume already on the device: Algorithm 1 reads it there (no upload),
/// Algorithm 2 runs on a downloaded copy.
SmoothResult smooth_isosurface(const DeviceVolume& v, double iso, double h, int window = 8,
                               SmoothVariant variant = SmoothVariant::plain, double tau = 1.0, bool keep_ld = false);

/// Intersected cubes I(s) and intersected grid edges E(s) of `v` at one isovalue (counted
/// on the device by count_spans).
struct IsoCounts {
    std::uint64_t cubes = 0, edges = 0;
};
IsoCounts intersected_counts(Context& ctx, const Volume& v, double iso);
IsoCounts intersected_counts(const DeviceVolume& v, double iso);

}  // namespace clfractal
