// The fractal dimension curve of one volume counted by several MPI ranks: each rank counts
// its own z-part on its own device, and the int64 histograms are summed with MPI_Reduce.
//
//   mpirun -np 2 ./mpi_fd [N]
//
// Here every rank builds the same synthetic noisy sphere and counts only its part; a
// scanner or a simulation would hand each rank just the slices of its part (see
// tools/clfractal_mpi for a rank reading only its slices of a file).
#include <mpi.h>

#include <clfractal/fd.hpp>
#include <clfractal/span.hpp>
#include <clfractal/synthetic.hpp>

#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace clfractal;

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int status = 0;
    try {
        SyntheticOptions o;
        o.size = argc > 1 ? std::size_t(std::atoi(argv[1])) : 96;
        const Volume v = make_synthetic("noisy-sphere", o);
        const IsovalueSet iso = IsovalueSet::for_volume(v);  // same on every rank
        const int levels = 2;

        // Rank r counts part r: it starts at a multiple of 2^(levels-1) and shares its
        // last slice with the next part.
        const auto parts = split_slices(v.dims().nz, levels, std::size_t(size));
        std::vector<std::uint64_t> mine(levels * iso.size(), 0), total(mine.size());
        if (std::size_t(rank) < parts.size()) {
            SpanOptions opt{{SpanKind::edges}, levels, 0};
            opt.z_begin = parts[rank].first;
            opt.z_end = parts[rank].second;
            const SpanResult r = count_spans(Context::shared(), v, iso, opt);
            for (int l = 0; l < levels; ++l)
                for (std::size_t j = 0; j < iso.size(); ++j) mine[l * iso.size() + j] = r.curves[0].counts[l][j];
            std::printf("rank %d: slices %zu..%zu\n", rank, parts[rank].first, parts[rank].second - 1);
        }
        MPI_Reduce(mine.data(), total.data(), int(mine.size()), MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);

        if (rank == 0) {
            SpanResult sum;
            sum.isovalues = iso;
            SpanCurves c;
            c.kind = SpanKind::edges;
            for (int l = 0; l < levels; ++l) {
                c.level_dims.push_back(level_dims(v.dims(), l));
                c.counts.emplace_back(total.begin() + l * iso.size(), total.begin() + (l + 1) * iso.size());
            }
            sum.curves.push_back(c);
            const FdCurve f = fd_curve(Context::shared(), sum, SpanKind::edges);
            const FdSummary s = summarize(f.fd, f.counts[0], f.counts[1]);
            // The same curve from one process, to show that nothing is lost at the seams.
            const SpanResult whole = count_spans(Context::shared(), v, iso, {{SpanKind::edges}, levels, 0});
            const bool same = whole.curves[0].counts == c.counts;
            std::printf("%d ranks: edge dimension mean %.4f over %zu isovalues; %s the single-process counts\n", size,
                        s.mean, s.defined, same ? "equal to" : "DIFFERENT FROM");
            status = same ? 0 : 1;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mpi_fd (rank %d): %s\n", rank, e.what());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Finalize();
    return status;
}
