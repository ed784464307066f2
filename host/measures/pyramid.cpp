#include "clfractal/pyramid.hpp"

#include "device/type_options.hpp"
#include "measures/pyramid_kernel.hpp"

namespace clfractal {

Dims level_dims(const Dims& d, int level) {
    Dims r = d;
    for (int l = 0; l < level; ++l) r = Dims{(r.nx - 1) / 2 + 1, (r.ny - 1) / 2 + 1, (r.nz - 1) / 2 + 1};
    return r;
}

Volume subsample(const Volume& v) {
    const Dims d = v.dims(), s = level_dims(d, 1);
    Volume out(s, v.type(), v.name);
    out.spacing = {2 * v.spacing[0], 2 * v.spacing[1], 2 * v.spacing[2]};
    visit(out, [&](auto* dst) {
        using T = std::remove_pointer_t<decltype(dst)>;
        const T* src = v.as<T>();
#pragma omp parallel for
        for (long long z = 0; z < (long long)s.nz; ++z)
            for (std::size_t y = 0; y < s.ny; ++y)
                for (std::size_t x = 0; x < s.nx; ++x)
                    dst[x + s.nx * (y + s.ny * std::size_t(z))] = src[2 * x + d.nx * (2 * y + d.ny * 2 * std::size_t(z))];
    });
    return out;
}

void subsample(Context& ctx, const cl::Buffer& src, ValueType type, const Dims& d, const cl::Buffer& dst) {
    const Dims s = level_dims(d, 1);
    SubsampleKernel k(ctx, "pyramid", "subsample", type_options(type));
    k(cl::NDRange(s.nx, s.ny, s.nz), cl::NullRange, src, int(d.nx), int(d.ny), dst, int(s.nx), int(s.ny));
}

DeviceVolume subsample(const DeviceVolume& v) {
    DeviceVolume out = DeviceVolume::allocate(v.context(), level_dims(v.dims(), 1), v.type());
    out.spacing = {2 * v.spacing[0], 2 * v.spacing[1], 2 * v.spacing[2]};
    out.name = v.name;
    with_cl_errors([&] { subsample(v.context(), v.buffer(), v.type(), v.dims(), out.buffer()); });
    return out;
}

}  // namespace clfractal
