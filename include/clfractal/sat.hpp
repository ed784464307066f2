// 3D summed-area tables (docs/definitions.md §12 "Summed-area tables"; thesis eq. 2.8).
//
// The inclusive table of values i(x, y, z) on an nx × ny × nz grid (x fastest) is
//
//   sat(x, y, z) = sum of i(a, b, c) over a <= x, b <= y, c <= z,
//
// so the sum over any box [x0, x1) × [y0, y1) × [z0, z1) is the 8-term inclusion-exclusion
// of sat at its corners: O(1) per query. Sums are exact modulo 2^32 (cl_uint) or 2^64
// (cl_ulong); box sums are exact whenever the box's true sum fits the type, even if the
// table itself wrapped.
#pragma once
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// Replaces the d.vertices() counts of `table` (a device buffer, x fastest) by their
/// inclusive summed-area table, with line scans along x, y and z. The kernels follow
/// ctx.tuning.sat_variant ("sequential" or "workgroup"). C is cl_uint or cl_ulong. Throws
/// std::logic_error if the buffer does not hold d.vertices() counts.
template <class C> void summed_area_table(Context& ctx, Buffer<C>& table, const Dims& d);

/// The same for host values: uploads, scans on the device, downloads.
/// The table of a uint32 volume of counts already on the device, as a new uint32 device
/// volume (sums modulo 2^32; no upload). Throws InputError for other value types.
DeviceVolume summed_area_table(const DeviceVolume& counts);

template <class C> std::vector<C> summed_area_table(Context& ctx, const std::vector<C>& values, const Dims& d);

}  // namespace clfractal
