// Plain C++ definition of the noise level (include/clfractal/noise_level.hpp), written for
// obviousness, not speed: every residual summed from its 27 weighted values in long double
// (exact for integer data), every block walked vertex by vertex, the estimate from the sorted
// block variances.
#pragma once
#include <cstddef>

#include "clfractal/noise_level.hpp"
#include "clfractal/volume.hpp"

namespace ref {

/// The block statistics of `v` for blocks of side `block`, the strided residuals included.
clfractal::NoiseBlocks noise_blocks(const clfractal::Volume& v, std::size_t block);

/// The white part of the estimate from block statistics (sigma_white, the blocks, the flat
/// share; sigma and correlation left NaN), with map cells of side `map_block` and clip `clip`:
/// the map is the residual's RMS per cell.
clfractal::NoiseLevel noise_level(const clfractal::NoiseBlocks& b, std::size_t map_block, double clip);

}  // namespace ref
