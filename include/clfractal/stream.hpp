// Slice streaming (docs/definitions.md §28 "Slabs, streams and ranks"): volumes that arrive
// slice by slice in z order, as from a scanner, analysed with memory for a few slices only.
//
//   SpanStream   span counts and FD curves of the slices seen so far, at any time,
//                identical to count_spans / fd_curve on the volume of those slices;
//   LocalStream  the local fractal dimension field, emitted slice by slice with a delay
//                of k/2 slices, identical to local_fractal_dimension on the whole volume.
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <stdexcept>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/span.hpp"
#include "clfractal/volume.hpp"

namespace clfractal {

/// Span counts of a volume fed one nx × ny slice at a time, in z order.
///
/// Slices are gathered into batches of batch_slices() slices (2^(levels-1) m + 1, a few
/// slices) that are counted as one z-slab; consecutive batches share one slice. Host and
/// device hold one batch (plus its subsampled levels), whatever the number of slices.
/// counts() adds the slices of the open batch as the volume's last slab, on the side, so
/// that the stream goes on afterwards.
class SpanStream {
public:
    /// Counts cubes and edges, levels 0..levels-1. `iso` must match the type
    /// (IsovalueSet::matches).
    SpanStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, IsovalueSet iso, int levels = 2);
    /// Counts only the given kinds (SpanResult::curves in this order).
    SpanStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, IsovalueSet iso, int levels,
               std::vector<SpanKind> kinds);
    ~SpanStream();
    SpanStream(const SpanStream&) = delete;
    SpanStream& operator=(const SpanStream&) = delete;

    /// Adds the next slice: nx * ny values of the stream's type (raw bytes), x fastest.
    /// Float slices with NaN or Inf are rejected (InputError) and not added.
    void push_slice(const void* slice);
    /// Type-checked: throws std::logic_error if T is not the stream's type (raw bytes of
    /// another type go through the const void* overload).
    template <class T> void push_slice(const T* slice) {
        if (value_type_of<T>::value != type()) throw std::logic_error("SpanStream::push_slice: type mismatch");
        push_slice(static_cast<const void*>(slice));
    }

    /// Room in the stream's own batch buffer for the next slices, to read them straight
    /// into it (no copy per slice): `room` gets how many (at least 1). Fill n <= room of
    /// them, then call push_filled(n).
    void* next_slices(std::size_t& room);
    /// Adds the n slices written at next_slices(), as n push_slice calls would (float
    /// slices with NaN or Inf are rejected with InputError, and none of the n is added).
    void push_filled(std::size_t n);

    /// Slices pushed so far.
    std::size_t slices() const;
    /// Counts of the nx × ny × slices() volume pushed so far (all zero before the first
    /// slice), as count_spans would give for it. SpanResult::slabs is the number of full
    /// batches counted so far; seconds the device time spent so far.
    SpanResult counts() const;
    /// The FD curve of one kind for the slices so far (levels >= 2), as fd_curve gives it.
    FdCurve curve(SpanKind kind) const;

    ValueType type() const;
    std::size_t nx() const;
    std::size_t ny() const;
    int levels() const;
    const IsovalueSet& isovalues() const;
    /// Slices per batch (one shared with the next batch).
    std::size_t batch_slices() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The local fractal dimension field (local.hpp) of a volume fed slice by slice in z order.
/// Output slice z depends on input slices up to z + k/2, so it is emitted as soon as slice
/// z + k/2 has arrived (and the rest at finish()): a delay of k/2 slices, or k/2 + batch - 1
/// when output slices are computed `batch` at a time. The stream keeps the input slices of
/// one window (batch + k + 2 slices) on the host and computes each batch of output slices on
/// that z-slab, so that every value equals the whole-volume field exactly.
class LocalStream {
public:
    /// Receives output slice z: the LD values (nx * ny floats, NaN where undefined) and the
    /// input slice z (nx * ny values of the stream's type). Both pointers are valid during
    /// the call only. A per-slice consumer (a targeted filter, a mesh colouring) plugs in here.
    using Sink = std::function<void(std::size_t z, const float* ld, const void* values)>;

    LocalStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, double iso, int window, Sink sink,
                std::size_t batch = 1);
    ~LocalStream();
    LocalStream(const LocalStream&) = delete;
    LocalStream& operator=(const LocalStream&) = delete;

    /// Adds the next input slice and emits every output slice it completes.
    void push_slice(const void* slice);
    template <class T> void push_slice(const T* slice) {
        if (value_type_of<T>::value != type()) throw std::logic_error("LocalStream::push_slice: type mismatch");
        push_slice(static_cast<const void*>(slice));
    }
    /// Ends the volume: emits the remaining output slices. No slice may follow.
    void finish();

    /// Input slice z' while the stream still holds it, else nullptr. During the sink's call
    /// for output slice z it holds every slice z' with |z' - z| <= k/2 in the volume, so a
    /// consumer with a neighbourhood of radius up to k/2 (a median or Gaussian filter) reads
    /// its input here.
    const void* input_slice(std::size_t z) const;
    std::size_t slices() const;   ///< input slices pushed
    std::size_t emitted() const;  ///< output slices emitted
    /// Input slices an output slice waits for after its own: k/2 + batch - 1.
    std::size_t delay() const;
    ValueType type() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The fractal-targeted filter (filter.hpp: the filter's value where LD(v) > h, the input
/// value elsewhere) of a volume fed slice by slice in z order: output slice z, in the input's
/// type, is emitted once input slice z + k/2 has arrived (and the rest at finish()), with the
/// same values as targeted_filter on the whole volume. Built on LocalStream; the filter's
/// radius must be at most k/2 (the median's is 1; a Gaussian's ceil(3 sigma)).
class TargetedFilterStream {
public:
    /// Receives output slice z (nx * ny values of the stream's type) and its LD slice. Both
    /// pointers are valid during the call only.
    using Sink = std::function<void(std::size_t z, const void* filtered, const float* ld)>;
    TargetedFilterStream(Context& ctx, std::size_t nx, std::size_t ny, ValueType type, const FilterSpec& spec,
                         double iso, double h, int window, Sink sink);
    ~TargetedFilterStream();
    TargetedFilterStream(const TargetedFilterStream&) = delete;
    TargetedFilterStream& operator=(const TargetedFilterStream&) = delete;
    void push_slice(const void* slice);
    /// Ends the volume: emits the remaining output slices.
    void finish();
    std::size_t slices() const;    ///< input slices pushed
    std::size_t emitted() const;   ///< output slices emitted
    std::size_t selected() const;  ///< vertices emitted so far with LD > h
    std::size_t changed() const;   ///< vertices emitted so far whose value changed

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace clfractal
