// The OpenMP baselines the benchmarks measure the device against (and the tests use as a
// second reference): plain multi-threaded C++ on the host, no OpenCL. Not part of the
// installed library.
#pragma once
#include "clfractal/local.hpp"
#include "clfractal/span.hpp"

namespace clfractal {

/// The counts of count_spans() on the host with OpenMP threads (per-thread histograms,
/// x-rows with reused column min/max). SpanResult::seconds is its wall time; slab_slices
/// is ignored.
SpanResult count_spans_openmp(const Volume& v, const IsovalueSet& iso, const SpanOptions& opt = {});

/// The field of local_fractal_dimension() on the host with OpenMP threads, by the algorithm
/// of the CPU kernels (indicator rows scanned in x and y per slice, then z; per x-row column
/// sums and two lookups per vertex), LD rounded from double.
Volume local_fractal_dimension_openmp(const Volume& v, double iso, int window = 8);

}  // namespace clfractal
