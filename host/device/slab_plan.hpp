// Z-slab planning (docs/definitions.md §28 "Slabs, streams and ranks"): how many slices of a
// volume one device pass takes, from the bytes each slice needs, the halo a stage reads around
// its output slices, the alignment of slab starts and the device's limits. The one definition
// of slab sizing, the default row count and the axis-length check; every capability plans
// through it.
#pragma once
#include <cstddef>

#include "clfractal/device.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// What one slab slice costs and how slabs are laid out.
struct SlabNeed {
    std::size_t nz = 0;                   ///< slices to cover (the volume, or the part of it)
    std::size_t input_slice_bytes = 0;    ///< input values per slice: what Tuning::slab_bytes bounds
    std::size_t slice_bytes = 0;          ///< every device buffer per slice (0: input_slice_bytes)
    std::size_t largest_slice_bytes = 0;  ///< the largest one buffer per slice (0: slice_bytes), within
                                          ///< CL_DEVICE_MAX_MEM_ALLOC_SIZE and largest_bytes
    std::size_t largest_bytes = 0;        ///< a cap on the largest buffer below max_alloc (0: none)
    std::size_t memory_divisor = 4;       ///< the slab's buffers within global memory / this
    std::size_t halo = 0;                 ///< slices read on each side of the output slices
    std::size_t shared_step = 0;          ///< 0: slabs are disjoint; s: each slab shares its last
                                          ///< slice with the next, which starts a multiple of s
                                          ///< later (depth = k * s + 1, k >= 1)
    std::size_t forced = 0;               ///< a depth the caller forces (tests), instead of the budget
    std::size_t max_slices = 0;           ///< a cap on the depth from the caller (0: none)
};

/// Output slices per slab (the input slab adds `halo` slices on each side): all `nz` when
/// they fit, else the most that fit, laid out by `shared_step`; 0 when not even one slab fits.
/// With Tuning::slab_bytes set, the input slab is bounded by it alone and at least one
/// output slice is planned (tests force tiny slabs this way).
std::size_t slab_fit(const Context& ctx, const SlabNeed& need);

/// slab_fit, or InputError "volume: a slab of N slices of NXxNY does not fit the device's
/// memory" when it is 0.
std::size_t plan_slab(const Context& ctx, const SlabNeed& need, const Dims& d);

/// Work-items of the row-walking kernel variants: Tuning::row_items, or 4 per compute unit.
std::size_t row_items(const Context& ctx);

/// Whether every axis of `d` is at most 2^31 - 1 vertices (the kernels index with int).
bool int_axes(const Dims& d);
/// Throws InputError "volume: axes longer than 2^31 - 1 vertices are not supported" unless
/// int_axes(d).
void check_int_axes(const Dims& d);

/// Whether a whole-volume device copy of `bytes` would cost host memory worth avoiding: on a
/// CPU device (whose buffers are host memory) a copy above 64 MiB doubles the volume for as
/// long as it is held, so slabbed or per-call uploads are taken instead.
bool copy_doubles_host_memory(const Context& ctx, std::size_t bytes);

/// The input slices [lo, hi) whose LD field (window `window`) gives exactly the whole-volume
/// values on output slices [a, b) of a volume of `nz` slices: lo = a - window/2 rounded down
/// to even (so the slab's level-1 slices are the volume's), hi = b + window/2 (both clamped).
/// Every window of the output slices then lies inside the slab or meets the volume's ends
/// where the slab ends too.
struct SliceRange {
    std::size_t lo, hi;
};
SliceRange ld_input_slices(std::size_t a, std::size_t b, std::size_t nz, int window);

/// Returns attempt(depth); when the device runs out of memory, attempt again with half the
/// depth (rounded up), down to one slice, then rethrows. The one retry rule of slabbed work.
template <class F>
auto with_smaller_slabs(std::size_t depth, F&& attempt) -> decltype(attempt(depth)) {
    for (;; depth = (depth + 1) / 2) {
        try {
            return attempt(depth);
        } catch (const DeviceError& e) {
            if (!e.out_of_memory() || depth <= 1) throw;
        }
    }
}

}  // namespace clfractal
