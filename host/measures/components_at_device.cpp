// components(s) at a few isovalues labelled on the device (clfractal/components.hpp,
// count_components_at; kernels/components.cl label_runs, join_runs, count_roots), and the rule
// that chooses between it and the host labelling (components_at.cpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "clfractal/components.hpp"
#include "measures/components_slab.hpp"
#include "device/kernel_call.hpp"
#include "device/type_options.hpp"

namespace clfractal {

namespace {

// Whether the device labelling takes a volume of `vertices`: labels are vertex indices in 32
// bits, one buffer of 4 bytes a vertex within the device's largest allocation.
bool device_labelling_takes(const Context& ctx, std::size_t vertices) {
    return vertices > 0 && vertices < (std::size_t(1) << 32) && 4 * vertices <= ctx.max_alloc();
}

bool on_device(const Context& ctx, std::size_t vertices) {
    return ctx.tuning.labelling == LabellingPath::device && device_labelling_takes(ctx, vertices);
}

// Whether isovalue s puts every value of `type` in A or every one in C before any comparison:
// a float32 s that rounds to +-Inf (from half an ulp above the largest float on), as the host
// labelling decides (the volume holds finite values).
bool one_set_whatever_the_data(ValueType type, double s) {
    return type == ValueType::float32 && std::abs(s) >= 0x1.ffffffp127;
}

std::vector<std::int64_t> label_on_device(const DeviceVolume& v, const std::vector<double>& isovalues,
                                          Connectivity mode) {
    Context& ctx = v.context();
    const Dims d = v.dims();
    const int adj_a = mode == Connectivity::cube ? 6 : 14, adj_c = mode == Connectivity::cube ? 26 : 14;
    const std::string options = single_isovalue_options(v.type()) +
                                defines({{"LABEL_A", std::to_string(adj_a)}, {"LABEL_C", std::to_string(adj_c)}});
    const std::size_t rows = d.ny * d.nz, k = isovalues.size();
    std::vector<cl_uint> roots(2 * k, 0);
    with_cl_errors_finished(ctx, [&] {
        // label_runs(f, nx, rows, s, labels), join_runs(f, nx, ny, nz, s, labels),
        // count_roots(f, nx, rows, s, labels, roots, j).
        KernelCall<cl::Buffer, cl_uint, cl_uint, ScalarArg, cl::Buffer> runs(ctx, "components", "label_runs", options);
        KernelCall<cl::Buffer, cl_uint, cl_uint, cl_uint, ScalarArg, cl::Buffer> join(ctx, "components", "join_runs",
                                                                                   options);
        KernelCall<cl::Buffer, cl_uint, cl_uint, ScalarArg, cl::Buffer, cl::Buffer, cl_uint> count(
            ctx, "components", "count_roots", options);
        const std::size_t wg = std::max<std::size_t>(
            1, std::min({std::size_t(64), ctx.max_work_group(), runs.work_group_limit(), join.work_group_limit(),
                         count.work_group_limit()}));
        const cl::NDRange global((rows + wg - 1) / wg * wg), local(wg);
        Buffer<cl_uint> labels(ctx, v.vertices());
        Buffer<cl_uint> counts(ctx, 2 * k);
        counts.fill(ctx.queue(), 0u);
        for (std::size_t j = 0; j < k; ++j) {
            if (one_set_whatever_the_data(v.type(), isovalues[j])) continue;
            const ScalarArg s = isovalue_arg(v.type(), isovalues[j]);
            runs(global, local, v.buffer(), cl_uint(d.nx), cl_uint(rows), s, labels.get());
            join(global, local, v.buffer(), cl_uint(d.nx), cl_uint(d.ny), cl_uint(d.nz), s, labels.get());
            count(global, local, v.buffer(), cl_uint(d.nx), cl_uint(rows), s, labels.get(), counts.get(), cl_uint(j));
        }
        counts.read(ctx.queue(), roots.data(), 2 * k);
    });
    std::vector<std::int64_t> out(k);
    for (std::size_t j = 0; j < k; ++j) {
        const std::int64_t a = roots[2 * j], c = roots[2 * j + 1];
        out[j] = a > 0 && c > 0 ? a + c - 1 : 0;
    }
    return out;
}

}  // namespace

std::vector<std::int64_t> count_components_at(Context& ctx, const Volume& v, const std::vector<double>& isovalues,
                                              Connectivity mode) {
    if (!on_device(ctx, v.vertices())) return count_components_at(v, isovalues, mode);
    check_isovalues(isovalues);
    const DeviceVolume dv(ctx, v);
    return label_on_device(dv, isovalues, mode);
}

std::vector<std::int64_t> count_components_at(const DeviceVolume& v, const std::vector<double>& isovalues,
                                              Connectivity mode) {
    check_isovalues(isovalues);
    if (!on_device(v.context(), v.vertices())) return count_components_at(v.download(), isovalues, mode);
    return label_on_device(v, isovalues, mode);
}

std::int64_t count_components_at(Context& ctx, const Volume& v, double isovalue, Connectivity mode) {
    return count_components_at(ctx, v, std::vector<double>{isovalue}, mode).front();
}

std::int64_t count_components_at(const DeviceVolume& v, double isovalue, Connectivity mode) {
    return count_components_at(v, std::vector<double>{isovalue}, mode).front();
}

}  // namespace clfractal
