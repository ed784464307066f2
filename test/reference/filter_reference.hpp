// Plain C++ filters straight from docs/definitions.md §16 "Filters" and
// include/clfractal/filter.hpp, in double precision: the references of
// test/processing/filter_test.cpp.
#pragma once
#include <vector>

#include "clfractal/volume.hpp"

namespace reference {

/// The median of the 27 clamped neighbours of every vertex (std::nth_element).
clfractal::Volume median_filter(const clfractal::Volume& v);

/// The separable Gaussian (radius ceil(3 sigma), normalised weights), unrounded, in double.
std::vector<double> gaussian_filter(const clfractal::Volume& v, double sigma);

/// The bilateral filter (radius ceil(2 sigma_s)), unrounded, in double. With `ld`, the
/// LD-guided variant: sigma_r(v) = sigma_r * min(LD(v) - 2, 1) where LD(v) > 2, and the
/// input value elsewhere.
std::vector<double> bilateral_filter(const clfractal::Volume& v, double sigma_s, double sigma_r,
                                     const float* ld = nullptr);

/// A double rounded to nearest (ties to even) and clamped to the range of the volume's type,
/// as the filters store integer results; float data: rounded to float.
double store_as(clfractal::ValueType t, double x);

}  // namespace reference
