// Grid subsampling (docs/definitions.md §6 "Pyramid levels"): level l keeps the vertices whose
// coordinates are multiples of 2^l; per axis n_l = (n_{l-1} - 1) / 2 + 1. G' is level 1.
#pragma once
#include "clfractal/device.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// Dims of pyramid level l.
Dims level_dims(const Dims& d, int level);

/// The next pyramid level of v on the host (the device does the same in kernels/pyramid.cl).
Volume subsample(const Volume& v);

/// The next pyramid level on the device: `src` holds d.vertices() values of `type`, `dst`
/// receives level_dims(d, 1).vertices() of them.
void subsample(Context& ctx, const cl::Buffer& src, ValueType type, const Dims& d, const cl::Buffer& dst);

/// The next pyramid level of a volume on the device, left there (spacing doubled, as the
/// host subsample's); no upload.
DeviceVolume subsample(const DeviceVolume& v);

}  // namespace clfractal
