// Vertex clustering built slab by slab (docs/definitions.md §37).
#include "clfractal/mesh_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <omp.h>

#include "clfractal/error.hpp"
#include "clfractal/local.hpp"
#include "extract_scratch.hpp"

namespace clfractal {

namespace {

std::size_t mix(std::size_t h, std::uint64_t x) {
    return h ^ (std::size_t(x * 0x9e3779b97f4a7c15ull) + 0x7f4a7c15 + (h << 6) + (h >> 2));
}

}  // namespace

std::size_t MeshClusters::CellHash::operator()(const std::array<std::int64_t, 3>& c) const {
    return mix(mix(mix(0, std::uint64_t(c[0])), std::uint64_t(c[1])), std::uint64_t(c[2]));
}

std::size_t MeshClusters::TripleHash::operator()(const std::array<std::uint32_t, 3>& t) const {
    return mix(mix(mix(0, t[0]), t[1]), t[2]);
}

MeshClusters::MeshClusters(double cell) : cell_(cell) {
    if (!(cell > 0) || !std::isfinite(cell)) throw InputError("mesh clustering: the cell must be a positive number");
}

std::uint32_t MeshClusters::cluster_of(const std::array<std::int64_t, 3>& cell) {
    const auto [it, added] = id_.emplace(cell, std::uint32_t(n_.size()));
    if (added) {
        if (n_.size() >= std::numeric_limits<std::uint32_t>::max()) throw InputError("mesh clustering: too many clusters");
        cells_.push_back(cell), sum_.push_back({0, 0, 0}), ld_sum_.push_back(0), n_.push_back(0), ld_n_.push_back(0);
    }
    return it->second;
}

void MeshClusters::add_triangle(const std::array<std::uint32_t, 3>& u) {
    if (u[0] == u[1] || u[1] == u[2] || u[0] == u[2]) return;
    std::array<std::uint32_t, 3> sorted = u;
    std::sort(sorted.begin(), sorted.end());
    if (seen_.insert(sorted).second) triangles_.push_back(u);
}

void MeshClusters::add(const Mesh& part, std::uint64_t counted_from) {
    const bool has_ld = part.ld.size() == part.positions.size();
    if (counted_from && part.edge_points.size() != part.positions.size())
        throw std::invalid_argument("MeshClusters::add: counted_from needs the part's edge points");
    const std::size_t n = part.positions.size();
    std::vector<std::uint32_t> of(n);
    std::array<std::int64_t, 3> last{};
    // The cells met lately, direct-mapped by (x + 31 y + 977 z) mod 1024: a part's rows meet the
    // cells of the rows before, so most new cells are found here without the hash table's
    // lookup (the same ids: a cell is looked up once, on its first meeting, in order).
    constexpr std::size_t recent_size = 1024;
    std::array<std::array<std::int64_t, 3>, recent_size> recent_cell;
    std::array<std::uint32_t, recent_size> recent_id;
    recent_id.fill(std::numeric_limits<std::uint32_t>::max());
    const auto lookup = [&](const std::array<std::int64_t, 3>& cell) {
        const std::size_t k = std::size_t(cell[0] + 31 * cell[1] + 977 * cell[2]) % recent_size;
        if (recent_id[k] != std::numeric_limits<std::uint32_t>::max() && recent_cell[k] == cell) return recent_id[k];
        recent_cell[k] = cell;
        return recent_id[k] = cluster_of(cell);
    };
    for (std::size_t i = 0; i < n; ++i) {
        const auto& p = part.positions[i];
        const std::array<std::int64_t, 3> cell{std::int64_t(std::floor(p[0] / cell_)),
                                               std::int64_t(std::floor(p[1] / cell_)),
                                               std::int64_t(std::floor(p[2] / cell_))};
        // Vertices made one after the other mostly share a cell: look up only a new one.
        const std::uint32_t j = i && cell == last ? of[i - 1] : lookup(cell);
        last = cell;
        of[i] = j;
        if (counted_from && part.edge_points[i].w < counted_from) continue;  // added with the slab before
        for (int k = 0; k < 3; ++k) sum_[j][k] += p[k];
        ++n_[j];
        if (has_ld && !std::isnan(part.ld[i])) ld_sum_[j] += part.ld[i], ++ld_n_[j];
    }
    for (const auto& t : part.triangles) add_triangle({of[t[0]], of[t[1]], of[t[2]]});
    input_triangles_ += part.triangles.size();
}

MeshClusters MeshClusters::coarsened(std::uint32_t factor) const {
    if (factor < 1) throw std::invalid_argument("MeshClusters::coarsened: the factor must be at least 1");
    MeshClusters c(cell_ * factor);
    const auto down = [&](std::int64_t i) {  // floor division
        return i >= 0 ? i / factor : -((-i + std::int64_t(factor) - 1) / std::int64_t(factor));
    };
    std::vector<std::uint32_t> of(n_.size());
    for (std::size_t j = 0; j < n_.size(); ++j) {
        const std::uint32_t k = c.cluster_of({down(cells_[j][0]), down(cells_[j][1]), down(cells_[j][2])});
        of[j] = k;
        for (int a = 0; a < 3; ++a) c.sum_[k][a] += sum_[j][a];
        c.n_[k] += n_[j], c.ld_sum_[k] += ld_sum_[j], c.ld_n_[k] += ld_n_[j];
    }
    for (const auto& t : triangles_) c.add_triangle({of[t[0]], of[t[1]], of[t[2]]});
    c.input_triangles_ = input_triangles_;
    return c;
}

Mesh MeshClusters::mesh() const {
    Mesh m;
    m.positions.resize(n_.size());
    m.ld.resize(n_.size());
    m.colors.resize(n_.size());
    for (std::size_t j = 0; j < n_.size(); ++j) {
        for (int k = 0; k < 3; ++k) m.positions[j][k] = float(sum_[j][k] / n_[j]);
        m.ld[j] = ld_n_[j] ? float(ld_sum_[j] / ld_n_[j]) : NAN;
        const Rgb c = ld_colour(m.ld[j]);
        m.colors[j] = {c.r, c.g, c.b};
    }
    m.triangles = triangles_;
    return m;
}

MeshClusters cluster_isosurface(const Volume& v, double s, double cell, const Volume* ld, MeshMethod method,
                                std::size_t layers) {
    if (!std::isfinite(s)) throw InputError("isovalue must be a finite number");
    MeshClusters c(cell);
    const std::size_t plane = std::max<std::size_t>(1, v.dims().nx * v.dims().ny);
    if (layers == 0) layers = std::max<std::size_t>(1, (std::size_t(1) << 21) / plane);
    // The surface is extracted in parts of `layers / threads` cube layers, on every thread,
    // and the parts are added in z order (the clusters are one hash table): the same clusters
    // as one part after the other. Adding comes first whenever the next part is ready and no
    // thread adds; otherwise a thread extracts the next part, at most `threads` parts ahead of
    // the adding (memory: one slab's parts, as before; twice as many ahead raised the 384^3
    // phantom report's peak to 724 MiB in one run, over its 688 MiB bound). So the adding on
    // one thread overlaps the extraction of the parts after it on the others (before, every
    // thread waited for each slab's parts to be added: the 640^3 phantom report's four
    // clustered surfaces took 21.7 s for 29.1 CPU s).
    const std::size_t threads = std::min<std::size_t>(std::size_t(std::max(1, omp_get_max_threads())), layers);
    layers = std::max<std::size_t>(1, layers / threads);
    const std::size_t nz = v.dims().nz, parts = nz > 1 ? (nz - 1 + layers - 1) / layers : 0, ahead = threads;
    std::vector<Mesh> slot(ahead), spares;  // spares: added parts, their vectors to be filled again
    std::vector<char> ready(ahead, 0);
    std::vector<detail::ExtractScratch> scratch(threads);
    std::size_t next_extract = 0, next_add = 0;
    bool adding = false;
    std::exception_ptr failed;
    std::mutex m;
    std::condition_variable changed;
#pragma omp parallel num_threads(int(threads))
    {
        detail::ExtractScratch& mine = scratch[std::size_t(omp_get_thread_num()) % threads];
        std::unique_lock<std::mutex> lock(m);
        while (!failed && next_add < parts) {
            const std::size_t p = next_add % ahead;
            if (!adding && ready[p]) {
                adding = true;
                const std::size_t z0 = next_add * layers;
                lock.unlock();
                std::exception_ptr e;
                try {
                    // The vertices within slice z0 came with the part before (its last slice).
                    c.add(slot[p], z0 ? std::uint64_t(z0 + 1) * plane : 0);
                } catch (...) {
                    e = std::current_exception();
                }
                lock.lock();
                if (e && !failed) failed = e;
                spares.push_back(std::move(slot[p]));
                slot[p] = Mesh();
                ready[p] = 0, adding = false, ++next_add;
                changed.notify_all();
            } else if (next_extract < parts && next_extract < next_add + ahead) {
                const std::size_t q = next_extract++, z0 = q * layers;
                if (!spares.empty()) {
                    mine.spare = std::move(spares.back());
                    spares.pop_back();
                }
                lock.unlock();
                Mesh part;
                std::exception_ptr e;
                try {
                    part = detail::extract_isosurface_layers(v, s, z0, z0 + layers, method, mine);
                    if (ld) detail::interpolate_on_vertices(part, *ld, part.ld);
                } catch (...) {
                    e = std::current_exception();
                }
                lock.lock();
                if (e && !failed) failed = e;
                slot[q % ahead] = std::move(part), ready[q % ahead] = 1;
                changed.notify_all();
            } else {
                changed.wait(lock);
            }
        }
        changed.notify_all();
    }
    if (failed) std::rethrow_exception(failed);
    return c;
}

Mesh bounded_mesh(const MeshClusters& c, std::size_t triangles, std::uint32_t* factor) {
    if (triangles < 1) throw std::invalid_argument("bounded_mesh: the triangle budget must be at least 1");
    std::uint32_t f = 1;
    if (c.triangles() <= triangles) {
        if (factor) *factor = 1;
        return c.mesh();
    }
    for (;;) {
        ++f;
        MeshClusters coarse = c.coarsened(f);
        if (coarse.triangles() <= triangles) {
            if (factor) *factor = f;
            return coarse.mesh();
        }
    }
}

}  // namespace clfractal
