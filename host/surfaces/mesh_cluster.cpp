// Vertex clustering built slab by slab (docs/definitions.md §37).
#include "clfractal/mesh_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
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
    for (std::size_t i = 0; i < n; ++i) {
        const auto& p = part.positions[i];
        const std::array<std::int64_t, 3> cell{std::int64_t(std::floor(p[0] / cell_)),
                                               std::int64_t(std::floor(p[1] / cell_)),
                                               std::int64_t(std::floor(p[2] / cell_))};
        // Vertices made one after the other mostly share a cell: look up only a new one.
        const std::uint32_t j = i && cell == last ? of[i - 1] : cluster_of(cell);
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
    // Each slab of `layers` cube layers is extracted in parts of a thread each, then the parts
    // are added in z order on one thread (the clusters are one hash table): the same clusters,
    // and at most one slab's mesh in memory, as one slab after the other.
    const std::size_t threads = std::min<std::size_t>(std::size_t(std::max(1, omp_get_max_threads())), layers);
    const std::size_t slab = layers;
    layers = std::max<std::size_t>(1, slab / threads);
    std::vector<Mesh> parts(threads);
    std::vector<detail::ExtractScratch> scratch(threads);
    std::exception_ptr failed;
    for (std::size_t z = 0; z + 1 < v.dims().nz; z += threads * layers) {
#pragma omp parallel for schedule(static, 1)
        for (std::size_t t = 0; t < threads; ++t) {
            const std::size_t z0 = z + t * layers;
            parts[t] = Mesh();
            if (z0 + 1 >= v.dims().nz) continue;
            try {
                parts[t] = detail::extract_isosurface_layers(v, s, z0, z0 + layers, method, scratch[t]);
                if (ld) parts[t].ld = interpolate_on_vertices(parts[t], *ld);
            } catch (...) {
#pragma omp critical(cluster_isosurface_failure)
                if (!failed) failed = std::current_exception();
            }
        }
        if (failed) std::rethrow_exception(failed);
        for (std::size_t t = 0; t < threads; ++t) {
            const std::size_t z0 = z + t * layers;
            if (z0 + 1 >= v.dims().nz) break;
            // The vertices within slice z0 came with the slab before (its last slice).
            c.add(parts[t], z0 ? std::uint64_t(z0 + 1) * plane : 0);
        }
    }
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
