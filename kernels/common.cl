// Shared by every kernel family (prepended to each program).
//
// Value types come in through -DT=uchar|ushort|short|float. Integer data is binned
// by value (-DINTEGER_VALUES), float data against a sorted isovalue list.

#ifndef T
#define T uchar
#endif

// Index of the first isovalue greater than v: the bin where a span starting (or
// ending) at v begins (or stops) to be intersected, since s intersects [a, b]
// iff a < s <= b (DESIGN §1).
//  - integer data: isovalue j is vmin + j, so the first one > v is v - vmin + 1,
//    clamped to [0, niso] for values outside the isovalue range;
//  - float data: upper bound of v in the sorted list iso[0..niso).
inline int first_isovalue_above(T v, int vmin, __global const float* iso, int niso) {
#ifdef INTEGER_VALUES
    return clamp((int)v - vmin + 1, 0, niso);
#else
    int lo = 0, hi = niso;
    while (lo < hi) {
        int mid = (lo + hi) >> 1;
        if (iso[mid] > v) hi = mid; else lo = mid + 1;
    }
    return lo;
#endif
}
