// libFuzzer target, differential: the isosurface component counts of ComponentsAtStream, fed
// a volume in batches, must equal count_components_at on the whole volume (two different
// layouts of the z-seams that the labelling joins), for any type, connectivity and
// isovalue. The first 8 bytes choose nx, ny (1..16), the type, the connectivity, the batch
// size (1..8) and up to three isovalues (one byte each, spread over the type's range and
// beyond); the rest are the values (float data: small integers / 4, so that isovalues hit).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "clfractal/components.hpp"
#include "clfractal/error.hpp"

using namespace clfractal;

namespace {

// Isovalue from a byte: small values around 0 for most bytes, the type's extremes for a few.
double isovalue_of(std::uint8_t b, ValueType t) {
    if (b >= 250) return b == 255 ? type_max(t) : b == 254 ? type_min(t) : b == 253 ? 1e300 : b == 252 ? -1e300 : 0.5;
    return (double(b) - 125.0) / 4.0;
}

// One value of type t from the bytes at p (floats: a small integer / 4, always finite).
void put_value(ValueType t, const std::uint8_t* p, unsigned char* out) {
    if (t == ValueType::float32) {
        const float f = float(std::int8_t(p[0]) % 16) / 4.0f;
        std::memcpy(out, &f, sizeof f);
    } else if (t == ValueType::float64) {
        const double f = double(std::int8_t(p[0]) % 16) / 4.0;
        std::memcpy(out, &f, sizeof f);
    } else {
        std::memcpy(out, p, value_size(t));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 8) return 0;
    const std::size_t nx = data[0] % 16 + 1, ny = data[1] % 16 + 1;
    const ValueType t = all_value_types[data[2] % std::size(all_value_types)];
    const Connectivity mode = data[3] & 1 ? Connectivity::freudenthal : Connectivity::cube;
    const std::size_t batch = data[4] % 8 + 1;
    std::vector<double> at;
    for (int k = 5; k < 8; ++k)
        if (k == 5 || data[k] != 0) at.push_back(isovalue_of(data[k], t));
    const std::size_t vb = value_size(t), nz = std::min<std::size_t>(24, (size - 8) / (nx * ny * vb));
    if (nz == 0) return 0;
    Volume v(Dims{nx, ny, nz}, t);
    auto* out = static_cast<unsigned char*>(v.data());
    for (std::size_t i = 0; i < v.vertices(); ++i) put_value(t, data + 8 + i * vb, out + i * vb);
    // An isovalue either path refuses (InputError) must be refused by both.
    std::vector<std::int64_t> whole;
    bool refused = false;
    try {
        whole = count_components_at(v, at, mode);
    } catch (const InputError&) {
        refused = true;
    }
    try {
        ComponentsAtStream stream(nx, ny, t, at, mode);
        for (std::size_t z = 0; z < nz; z += batch)
            stream.push_slices(out + z * nx * ny * vb, std::min(batch, nz - z));
        if (refused || stream.slices() != nz || stream.counts() != whole) __builtin_trap();
    } catch (const InputError&) {
        if (!refused) __builtin_trap();
    }
    return 0;
}
