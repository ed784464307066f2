// Neighbourhood gathering for the two sweeps: for every vertex v, which neighbours come
// before it in the join sweep (A's neighbourhood, (f(u), u) < (f(v), v)) and which in the
// split sweep (C's neighbourhood, (f(u), u) > (f(v), v)). Bit q < A_COUNT: the q-th offset
// of A's neighbourhood; bit A_COUNT + q: the q-th offset of C's. Offsets are enumerated
// dz, dy, dx = -1..1 (x fastest), exactly as the host enumerates them. Adjacency per set:
// ADJ_A, ADJ_C in {6, 14, 26}; A_COUNT + C_COUNT <= 32.
// Global size (nx rounded up to the work-group width, ny, nz). Built only with A_COUNT.
#if defined(A_COUNT) || defined(LABEL_A)
// Whether offset (dx, dy, dz) joins two vertices of a set whose adjacency is `adj`.
inline bool in_adjacency(int adj, int dx, int dy, int dz) {
    const int n = abs(dx) + abs(dy) + abs(dz);
    if (adj == 6) return n == 1;
    if (adj == 26) return true;
    return !(min(dx, min(dy, dz)) < 0 && max(dx, max(dy, dz)) > 0);  // 14: no mixed signs
}
#endif

#ifdef A_COUNT
__kernel void neighbour_masks(__global const T* restrict f, int nx, int ny, int nz,
                              __global uint* restrict mask) {
    const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
    if (x >= nx) return;
    const ulong v = (ulong)x + (ulong)nx * ((ulong)y + (ulong)ny * (ulong)z);
    const T fv = f[v];
    uint m = 0;
    int qa = 0, qc = A_COUNT;
#pragma unroll
    for (int dz = -1; dz <= 1; ++dz)
#pragma unroll
        for (int dy = -1; dy <= 1; ++dy)
#pragma unroll
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0 && dz == 0) continue;
                const bool in_a = in_adjacency(ADJ_A, dx, dy, dz), in_c = in_adjacency(ADJ_C, dx, dy, dz);
                if (!in_a && !in_c) continue;
                const bool inside = x + dx >= 0 && x + dx < nx && y + dy >= 0 && y + dy < ny &&
                                    z + dz >= 0 && z + dz < nz;
                bool lower = false;
                if (inside) {
                    const long o = (long)dx + (long)nx * ((long)dy + (long)ny * (long)dz);
                    const T fu = f[(ulong)((long)v + o)];
                    lower = fu < fv || (fu == fv && o < 0);
                    if (in_a && lower) m |= 1u << qa;
                    if (in_c && !lower) m |= 1u << qc;
                }
                qa += in_a;
                qc += in_c;
            }
    mask[v] = m;
}
#endif  // A_COUNT

// Labelling of A = {f < s} and C = {f >= s} at one isovalue s (count_components_at on the
// device): union-find over the runs of each set along x, in three kernels an isovalue.
//   label_runs   every vertex gets the index of the first vertex of its run (the run's root);
//   join_runs    each run is joined to the runs of the same set it touches in the rows before
//                it (dz = -1, or dz = 0 and dy = -1) under that set's adjacency (LABEL_A,
//                LABEL_C in {6, 14, 26}), by union-find on the run starts' labels;
//   count_roots  the roots left in A and in C: b0(A) and b0(C).
// Labels are vertex indices in uint (the host calls these kernels below 2^32 vertices). A
// label only ever falls, to a smaller index of the same component, so every run start's
// parent chain ends at its component's smallest run start, whatever order the unions take:
// the counts are deterministic. During join_runs only run starts' labels change, always
// through atomics (atomic_min to link, atomic_or(p, 0) to read), so there is no plain access
// to a label another work-item writes; the other labels are read plainly and never written.
// Launch: one work-item a row (y, z), row r = y + ny * z; global size rows rounded up to the
// work-group size (items past the rows return). Built with single_isovalue_options (iso_t).
#ifdef LABEL_A
inline bool in_a(T v, iso_t s) { return v < s; }

__kernel void label_runs(__global const T* restrict f, uint nx, uint rows, iso_t s, __global uint* restrict labels) {
    const uint r = get_global_id(0);
    if (r >= rows) return;
    const uint row = r * nx;  // below 2^32 vertices: no wrap
    uint start = row;
    bool set = in_a(f[row], s);
    for (uint x = 0; x < nx; ++x) {
        const bool here = in_a(f[row + x], s);
        if (here != set) start = row + x, set = here;
        labels[row + x] = start;
    }
}

// The label of run start x, read atomically (it may be changing).
inline uint label_of(volatile __global uint* labels, uint x) { return atomic_or(&labels[x], 0u); }

inline uint root_of(volatile __global uint* labels, uint x) {
    for (uint p = label_of(labels, x); p != x; p = label_of(labels, x)) x = p;
    return x;
}

// Joins the components of run starts a and b: the larger root is linked under the smaller by
// atomic_min. When another work-item linked that root first, atomic_min may have cut it from
// its new parent `old`, so the loop joins `old` with the smaller root in turn.
inline void unite(volatile __global uint* labels, uint a, uint b) {
    for (;;) {
        a = root_of(labels, a), b = root_of(labels, b);
        if (a == b) return;
        const uint lo = min(a, b), hi = max(a, b);
        const uint old = atomic_min(&labels[hi], lo);
        if (old == hi) return;
        a = lo, b = old;
    }
}

// The bits of in_a over the n <= 32 vertices from `at` (bit i: vertex at + i).
inline uint set_mask(__global const T* restrict f, uint at, uint n, iso_t s) {
    uint m = 0;
    for (uint i = 0; i < n; ++i) m |= (uint)in_a(f[at + i], s) << i;
    return m;
}

// The first vertex of the run holding vertex u at column xx: u itself, else the label
// label_runs gave it (a vertex that starts no run: never changed).
inline uint run_start(__global const T* restrict f, volatile __global uint* labels, uint u, uint xx, iso_t s) {
    return xx == 0 || in_a(f[u - 1], s) != in_a(f[u], s) ? u : ((__global const uint*)labels)[u];
}

// The rows before this one that the offsets reach, q = 0..3: (dy, dz) = (-1, -1), (0, -1),
// (1, -1), (-1, 0); offset k = 3 q + dx + 1. The row and those rows are taken 32 vertices at a
// time as bit masks (in A or not), each row read once. For each offset and set, the
// vertices x where this row and the neighbour at x + dx are both in the set ("contacts")
// are one mask; a contact whose x - 1 is a contact too joins the same two runs again (this
// row's x - 1 and x are in one run, and so are the neighbour's), so only the first contact
// of each stretch unites.
__kernel void join_runs(__global const T* restrict f, uint nx, uint ny, uint nz, iso_t s,
                        volatile __global uint* labels) {
    const uint r = get_global_id(0);
    if (r >= ny * nz) return;
    const int y = (int)(r % ny), z = (int)(r / ny);
    const uint row = r * nx;
    // Bit k of reach[1] (A) and reach[0] (C): offset k is in that set's adjacency.
    uint reach[2] = {0, 0};
    bool inside[4];
    uint qrow[4], last_bit[4], here[4];
    for (int q = 0; q < 4; ++q) {
        const int dy = q == 3 ? -1 : q - 1, dz = q == 3 ? 0 : -1;
        for (int dx = -1; dx <= 1; ++dx) {
            reach[1] |= (uint)in_adjacency(LABEL_A, dx, dy, dz) << (3 * q + dx + 1);
            reach[0] |= (uint)in_adjacency(LABEL_C, dx, dy, dz) << (3 * q + dx + 1);
        }
        inside[q] = y + dy >= 0 && y + dy < (int)ny && z + dz >= 0;
        qrow[q] = inside[q] ? ((uint)(z + dz) * ny + (uint)(y + dy)) * nx : 0;
        last_bit[q] = 0;  // the word before's bit 31: the vertex before this word
        here[q] = inside[q] ? set_mask(f, qrow[q], min(32u, nx), s) : 0;
    }
    uint carry_a = 0, carry_c = 0;  // bit k: offset k's contact at the last vertex of the word before
    for (uint x0 = 0; x0 < nx; x0 += 32) {
        const uint n = min(32u, nx - x0);
        const uint valid = n == 32 ? 0xffffffffu : (1u << n) - 1;
        const uint own = set_mask(f, row + x0, n, s);
        uint next_a = 0, next_c = 0;
        for (int q = 0; q < 4; ++q) {
            if (!inside[q]) continue;
            const uint c = here[q];
            const uint after = x0 + 32 < nx ? set_mask(f, qrow[q] + x0 + 32, min(32u, nx - x0 - 32), s) : 0;
            // The vertex after this word, read again rather than taken from `after`: LLVM
            // turns (c >> 1 | after << 31) into a funnel shift (llvm.fshr), which Oclgrind
            // cannot run; the same for c << 1 with the word before, hence last_bit.
            const uint first_after = x0 + 32 < nx && in_a(f[qrow[q] + x0 + 32], s);
            for (int dx = -1; dx <= 1; ++dx) {
                const int k = 3 * q + dx + 1;
                // Bit b of `at`: the neighbour x0 + b + dx in A; `ok`: it exists.
                const uint at = dx < 0 ? c << 1 | last_bit[q] : dx > 0 ? c >> 1 | first_after << 31 : c;
                const uint ok = dx < 0 ? (x0 == 0 ? valid & ~1u : valid) : dx > 0 ? (x0 + n < nx ? valid : valid >> 1) : valid;
                const uint ca = own & at & ok & (0u - (reach[1] >> k & 1));
                const uint cc = ~own & ~at & ok & (0u - (reach[0] >> k & 1));
                uint fresh = (ca & ~(ca << 1 | (carry_a >> k & 1))) | (cc & ~(cc << 1 | (carry_c >> k & 1)));
                next_a |= (ca >> 31) << k;
                next_c |= (cc >> 31) << k;
                for (; fresh; fresh &= fresh - 1) {
                    const uint x = x0 + 31 - clz(fresh & (0u - fresh));  // the lowest bit
                    const uint u = qrow[q] + (uint)((int)x + dx);
                    unite(labels, run_start(f, labels, row + x, x, s), run_start(f, labels, u, (uint)((int)x + dx), s));
                }
            }
            last_bit[q] = c >> 31;
            here[q] = after;
        }
        carry_a = next_a, carry_c = next_c;
    }
}

// roots[2 j] += the roots of A in the rows, roots[2 j + 1] += those of C.
__kernel void count_roots(__global const T* restrict f, uint nx, uint rows, iso_t s,
                          __global const uint* restrict labels, volatile __global uint* roots, uint j) {
    const uint r = get_global_id(0);
    if (r >= rows) return;
    const uint row = r * nx;
    uint a = 0, c = 0;
    for (uint v = row; v < row + nx; ++v)
        if (labels[v] == v) {
            if (in_a(f[v], s)) ++a;
            else ++c;
        }
    if (a) atomic_add(&roots[2 * j], a);
    if (c) atomic_add(&roots[2 * j + 1], c);
}
#endif  // LABEL_A
