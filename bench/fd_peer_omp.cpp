// The end-to-end peer of `clfractal fd FILE` for uint8 volumes: a plain OpenMP C++ program that
// reads the file into memory and counts the intersected cubes of levels 0 and 1 for every
// isovalue once (docs/definitions.md §7 "Counts", §6 "Pyramid levels"), as a careful programmer
// would write it without the library: fread into an uninitialised buffer, per-thread difference
// histograms (four taken in turn along x) over x-rows with the column min/max of each row
// computed once (the loop of bench/baselines/span_openmp.cpp, the benchmarks' OpenMP baseline),
// level 1 gathered into its own grid.
//
//   fd_peer_omp FILE.nrrd|NAME_XxYxZ_uint8.raw|FILE.raw --dims XxYxZ --type uint8 [--csv F]
//
// NRRD: an attached header with `type: uchar`-like names, `encoding: raw`, three sizes; raw:
// the sizes from --dims (the whole file, no header; --type must be uint8), or else from the
// NAME_XxYxZ_uint8.raw naming (the sizes after the last underscore but one, so that
// "boston_teapot_256x256x178_uint8.raw" reads too). Prints the time and, with --csv, writes
// isovalue,count,count_sub for the isovalues min+1..max (clfractal's integer set: every
// integer of the value range) so that bench/fd_bench.sh checks both programs agree.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

[[noreturn]] void fail(const std::string& what) {
    std::cerr << "fd_peer_omp: error: " << what << "\n";
    std::exit(2);
}

struct Layout {
    std::size_t nx = 0, ny = 0, nz = 0;
    long offset = 0;
};

// "XxYxZ" into the layout's sizes; false when it is not three positive integers.
bool parse_dims(const std::string& text, Layout& l) {
    char x1 = 0, x2 = 0;
    std::istringstream in(text);
    in >> l.nx >> x1 >> l.ny >> x2 >> l.nz;
    return in && in.peek() == EOF && x1 == 'x' && x2 == 'x' && l.nx && l.ny && l.nz;
}

// The layout of `path`: its NRRD header, else `dims` (a raw file, data from byte 0), else
// its NAME_XxYxZ_uint8.raw name.
Layout parse(const std::string& path, const std::string& dims) {
    Layout l;
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path + ": cannot open");
    std::string line;
    std::getline(in, line);
    if (line.rfind("NRRD", 0) == 0) {
        bool uchar = false, raw = false;
        while (std::getline(in, line) && !line.empty()) {
            const std::size_t c = line.find(':');
            if (c == std::string::npos) continue;
            const std::string key = line.substr(0, c), value = line.substr(c + 1 + (line[c + 1] == ' '));
            if (key == "type") uchar = value == "unsigned char" || value == "uchar" || value == "uint8" || value == "uint8_t";
            if (key == "encoding") raw = value == "raw";
            if (key == "sizes") std::istringstream(value) >> l.nx >> l.ny >> l.nz;
        }
        if (!uchar || !raw || !l.nz) fail(path + ": expected a raw-encoded 3D unsigned char NRRD");
        l.offset = long(in.tellg());
        return l;
    }
    if (!dims.empty()) {
        if (!parse_dims(dims, l)) fail("--dims " + dims + ": expected XxYxZ");
        in.clear();
        in.seekg(0, std::ios::end);
        if (std::size_t(in.tellg()) != l.nx * l.ny * l.nz)
            fail(path + ": " + std::to_string(in.tellg()) + " bytes, not the " + std::to_string(l.nx * l.ny * l.nz) +
                 " of --dims " + dims + " uint8");
        return l;
    }
    const std::string name = path.substr(path.find_last_of('/') + 1);
    const std::string suffix = "_uint8.raw";
    const std::size_t end = name.size() >= suffix.size() ? name.size() - suffix.size() : 0;
    const std::size_t start = name.rfind('_', end ? end - 1 : 0);
    if (!end || name.compare(end, suffix.size(), suffix) != 0 || start == std::string::npos ||
        !parse_dims(name.substr(start + 1, end - start - 1), l))
        fail(path + ": not a NRRD file or a NAME_XxYxZ_uint8.raw file (or give --dims XxYxZ --type uint8)");
    return l;
}

// Difference histogram of the cubes of the nx × ny × nz grid `v`: +1 at a + 1 and -1 at
// b + 1 for each cube with span [a, b] (258 bins). Per x-row: the column min/max of the
// four vertex rows (vectorised), the cube spans, then the scattered histogram updates.
void count_cubes(const std::uint8_t* v, std::size_t nx, std::size_t ny, std::size_t nz, std::vector<std::int64_t>& out) {
    out.assign(258, 0);
    const std::size_t slice = nx * ny;
#pragma omp parallel
    {
        std::vector<std::int64_t> hist(4 * 258, 0);  // four taken in turn along x
        std::vector<std::uint8_t> cmn(nx), cmx(nx);
        std::vector<int> lo(nx), hi(nx);
#pragma omp for schedule(static)
        for (long long r = 0; r < (long long)((ny - 1) * (nz - 1)); ++r) {
            const std::size_t y = std::size_t(r) % (ny - 1), z = std::size_t(r) / (ny - 1);
            const std::uint8_t* __restrict p00 = v + z * slice + y * nx;
            const std::uint8_t* __restrict p10 = p00 + nx;
            const std::uint8_t* __restrict p01 = p00 + slice;
            const std::uint8_t* __restrict p11 = p01 + nx;
            std::uint8_t* __restrict mn = cmn.data();
            std::uint8_t* __restrict mx = cmx.data();
            for (std::size_t x = 0; x < nx; ++x) {
                mn[x] = std::min(std::min(p00[x], p10[x]), std::min(p01[x], p11[x]));
                mx[x] = std::max(std::max(p00[x], p10[x]), std::max(p01[x], p11[x]));
            }
            int* __restrict l = lo.data();
            int* __restrict u = hi.data();
            for (std::size_t x = 0; x + 1 < nx; ++x) {
                l[x] = std::min(mn[x], mn[x + 1]) + 1;
                u[x] = std::max(mx[x], mx[x + 1]) + 1;
            }
            std::int64_t* __restrict h0 = hist.data();
            std::int64_t* __restrict h1 = h0 + 258;
            std::int64_t* __restrict h2 = h1 + 258;
            std::int64_t* __restrict h3 = h2 + 258;
            std::size_t x = 0;
            for (; x + 4 < nx; x += 4) {
                if (l[x] != u[x]) ++h0[l[x]], --h0[u[x]];
                if (l[x + 1] != u[x + 1]) ++h1[l[x + 1]], --h1[u[x + 1]];
                if (l[x + 2] != u[x + 2]) ++h2[l[x + 2]], --h2[u[x + 2]];
                if (l[x + 3] != u[x + 3]) ++h3[l[x + 3]], --h3[u[x + 3]];
            }
            for (; x + 1 < nx; ++x)
                if (l[x] != u[x]) ++h0[l[x]], --h0[u[x]];
        }
#pragma omp critical
        for (std::size_t i = 0; i < 258; ++i) out[i] += hist[i] + hist[258 + i] + hist[516 + i] + hist[774 + i];
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::string path, dims, type = "uint8", csv_path;
    bool usage = argc < 2;
    for (int i = 1; i < argc && !usage; ++i) {
        const std::string arg = argv[i];
        const bool value = i + 1 < argc;
        if (arg == "--csv" && value) csv_path = argv[++i];
        else if (arg == "--dims" && value) dims = argv[++i];
        else if (arg == "--type" && value) type = argv[++i];
        else if (path.empty() && arg.rfind("--", 0) != 0) path = arg;
        else usage = true;
    }
    if (usage || path.empty()) {
        std::cerr << "usage: fd_peer_omp FILE.nrrd|NAME_XxYxZ_uint8.raw|FILE.raw --dims XxYxZ --type uint8 [--csv F]\n";
        return 2;
    }
    if (type != "uint8") fail("--type " + type + ": only uint8 is counted");
    const auto t0 = std::chrono::steady_clock::now();
    const Layout l = parse(path, dims);
    const std::size_t n = l.nx * l.ny * l.nz;
    std::unique_ptr<std::uint8_t[]> v(new std::uint8_t[n]);
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f || std::fseek(f, l.offset, SEEK_SET) != 0 || std::fread(v.get(), 1, n, f) != n)
        fail(path + ": cannot read " + std::to_string(n) + " bytes");
    std::fclose(f);
    const auto t1 = std::chrono::steady_clock::now();
    if (l.nx < 3 || l.ny < 3 || l.nz < 3) fail(path + ": every axis needs at least 3 vertices");

    std::vector<std::int64_t> h0, h1;
    count_cubes(v.get(), l.nx, l.ny, l.nz, h0);
    // Level 1: the vertices with even coordinates, gathered into a grid of their own.
    const std::size_t mx = (l.nx - 1) / 2 + 1, my = (l.ny - 1) / 2 + 1, mz = (l.nz - 1) / 2 + 1;
    std::unique_ptr<std::uint8_t[]> sub(new std::uint8_t[mx * my * mz]);
#pragma omp parallel for schedule(static)
    for (long long z = 0; z < (long long)mz; ++z)
        for (std::size_t y = 0; y < my; ++y)
            for (std::size_t x = 0; x < mx; ++x)
                sub[(std::size_t(z) * my + y) * mx + x] = v[(2 * std::size_t(z) * l.ny + 2 * y) * l.nx + 2 * x];
    count_cubes(sub.get(), mx, my, mz, h1);
    const auto t2 = std::chrono::steady_clock::now();
    // The value range, for the isovalue set (clfractal counts every integer of it).
    std::uint8_t lo = 255, hi = 0;
#pragma omp parallel for reduction(min : lo) reduction(max : hi)
    for (long long i = 0; i < (long long)n; ++i) {
        lo = std::min(lo, v[std::size_t(i)]);
        hi = std::max(hi, v[std::size_t(i)]);
    }
    std::int64_t c0 = 0, c1 = 0, total0 = 0;
    std::ostringstream csv;
    csv << "isovalue,count,count_sub\n";
    for (int s = 0; s <= 256; ++s) {
        c0 += h0[std::size_t(s)];
        c1 += h1[std::size_t(s)];
        if (s >= lo && s <= hi) {
            csv << s << "," << c0 << "," << c1 << "\n";
            total0 += c0;
        }
    }
    const auto t3 = std::chrono::steady_clock::now();
    if (!csv_path.empty()) std::ofstream(csv_path) << csv.str();
    auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    std::cout << "read " << sec(t0, t1) << " s, count " << sec(t1, t2) << " s, range " << sec(t2, t3)
              << " s, threads " << omp_get_max_threads() << ", sum of I(s) " << total0 << "\n";
    return 0;
}
