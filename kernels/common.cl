// Shared by every kernel family (prepended to each program).
//
// Value types come in through -DT=uchar|char|ushort|short|uint|int|float|double (the
// OpenCL names of include/clfractal/volume.hpp's type table). Span counting bins integer
// data by value (-DINTEGER_VALUES) and everything else against a sorted isovalue list of
// ISO_T = float (float32 data) or double (-DISO_DOUBLE: float64 data, and int32/uint32 data
// whose range holds more than 65,536 integers; int and uint convert to double exactly).
// Programs that use double are built with -DFP64, and only for devices with cl_khr_fp64
// (Context::program says so clearly otherwise).

#ifdef FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif

#ifndef T
#define T uchar
#endif

#ifdef ISO_DOUBLE
typedef double ISO_T;
#else
typedef float ISO_T;
#endif

// iso_t: the type one isovalue s is compared in, a < s <= b in the data's own type
// (docs/definitions.md §3 "Exact comparisons"): integer data with the integer ceil(s) as a long
// (for integers a, b and a real s, a < s <= b iff a < ceil(s) <= b; long holds every int32 and
// uint32 value); float32 data with s rounded to float; float64 data with s as a double.
#if defined(INTEGER_VALUES)
typedef long iso_t;
#elif defined(ISO_DOUBLE)
typedef double iso_t;
#else
typedef float iso_t;
#endif

// Index of the first isovalue greater than v: the bin where a span starting (or
// ending) at v begins (or stops) to be intersected, since s intersects [a, b]
// iff a < s <= b (docs/definitions.md §4 "Span and intersection").
//  - integer data: isovalue j is vmin + j, so the first one > v is v - vmin + 1,
//    clamped to [0, niso] for values outside the isovalue range; in int with -DNARROW_BINS
//    (8/16-bit data and |vmin| <= 2^20, which the host checks: no int overflows), twice the
//    lanes of a vector as in long;
//  - other data: upper bound of v in the sorted list iso[0..niso), compared as ISO_T
//    (exact: ISO_T holds every value of T).
inline int first_isovalue_above(T v, long vmin, __global const ISO_T* iso, int niso) {
#if defined(INTEGER_VALUES) && defined(NARROW_BINS)
    return clamp((int)v - (int)vmin + 1, 0, niso);
#elif defined(INTEGER_VALUES)
    return (int)clamp((long)v - vmin + 1, 0L, (long)niso);
#else
    int lo = 0, hi = niso;
    while (lo < hi) {
        int mid = (lo + hi) >> 1;
        if (iso[mid] > v) hi = mid; else lo = mid + 1;
    }
    return lo;
#endif
}
