// A scanner pipeline: slices arrive one at a time (here from a simulated scanner), are
// fed to a SpanStream, and every few slices the isovalues whose isosurface is noisy so far
// (edge dimension above 2.3, thesis chapter 3) are flagged, long before the scan ends.
// Memory stays a few slices whatever the scan's length.
//
//   scanner_pipeline [N]       (an N x N x N scan, default 96)
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "clfractal/stream.hpp"

namespace {

// The simulated scanner: a ramp along z (values 0..200) plus a bright, smooth-edged sphere, and
// detector noise of +-15 on the values above 150 only, so that those isovalues are noisy.
void scan_slice(int n, int z, std::vector<std::uint8_t>& out) {
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double dx = x - n / 2.0, dy = y - n / 2.0, dz = z - n / 2.0;
            const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
            double v = 200.0 * z / n + 40.0 * std::fmin(1.0, std::fmax(0.0, 0.5 + (n / 3.0 - r) / 4.0));
            if (v > 150) v += std::rand() % 31 - 15;
            out[x + n * y] = std::uint8_t(std::fmin(255.0, std::fmax(0.0, v)));
        }
}

}  // namespace

int main(int argc, char** argv) {
    using namespace clfractal;
    const int n = argc > 1 ? std::atoi(argv[1]) : 96;
    if (n < 8) {
        std::fprintf(stderr, "scanner_pipeline: N must be at least 8\n");
        return 2;
    }
    try {
        Context& ctx = Context::shared();
        // Every uint8 isovalue 1..255, cubes and edges, levels 0 and 1.
        SpanStream stream(ctx, n, n, ValueType::uint8, IsovalueSet::integers(1, 255));
        std::vector<std::uint8_t> slice(std::size_t(n) * n);
        std::srand(7);
        for (int z = 0; z < n; ++z) {
            scan_slice(n, z, slice);
            stream.push_slice(slice.data());
            if ((z + 1) % 32 != 0 && z + 1 != n) continue;

            // The edge dimension of the slices so far; flag isovalues with enough edges.
            const FdCurve f = stream.curve(SpanKind::edges);
            int noisy = 0, first = -1, last = -1;
            for (std::size_t j = 0; j < f.fd.size(); ++j)
                if (f.counts[1][j] >= 100 && f.fd[j] > 2.3) {
                    ++noisy;
                    if (first < 0) first = int(f.isovalues.value(j));
                    last = int(f.isovalues.value(j));
                }
            std::printf("after %3zu slices: %3d noisy isovalues", stream.slices(), noisy);
            if (noisy) std::printf(" (%d .. %d)", first, last);
            std::printf("\n");
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "scanner_pipeline: %s\n", e.what());
        return 1;
    }
}
