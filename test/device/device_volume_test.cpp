// DeviceVolume (device_volume.hpp): one upload, zero-copy where the device shares host
// memory and the pointer is aligned, a copy otherwise; a pipeline that uploads its volume once.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "clfractal/advice.hpp"
#include "clfractal/components.hpp"
#include "clfractal/fd4.hpp"
#include "clfractal/pyramid.hpp"
#include "clfractal/device_volume.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/mesh.hpp"
#include "clfractal/noise.hpp"
#include "clfractal/smooth.hpp"
#include "clfractal/span.hpp"
#include "clfractal/synthetic.hpp"
#include "components_labelling.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

namespace {

bool same_bytes(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

}  // namespace

TEST_SUITE("device") {

TEST_CASE("a DeviceVolume is one upload and downloads what was uploaded") {
    testutil::TuningGuard guard;
    Volume v = testutil::random_volume({13, 7, 5}, ValueType::int16, -300, 300, 3);
    v.spacing = {0.5, 2, 3};
    v.name = "random";
    for (bool zero_copy : {true, false}) {
        CAPTURE(zero_copy);
        ctx().tuning.zero_copy = zero_copy;
        const std::uint64_t before = ctx().uploads();
        const DeviceVolume d(ctx(), v);
        CHECK(ctx().uploads() == before + 1);
        CHECK(d.dims() == v.dims());
        CHECK(d.type() == v.type());
        CHECK(d.spacing == v.spacing);
        CHECK(d.name == v.name);
        CHECK(d.bytes() == v.size_bytes());
        const bool aligned = reinterpret_cast<std::uintptr_t>(v.data()) % ctx().mem_base_align() == 0;
        CHECK(d.in_host_memory() == (zero_copy && aligned));
        const Volume back = d.download();
        CHECK(same_bytes(back, v));
        CHECK(back.spacing == v.spacing);
        CHECK(ctx().uploads() == before + 1);  // downloads are not uploads
    }
}

TEST_CASE("zero-copy honours the device's base-address alignment, else copies") {
    testutil::TuningGuard guard;
    ctx().tuning.zero_copy = true;
    const std::size_t align = ctx().mem_base_align();
    const Dims d{9, 4, 3};
    // Host memory at an aligned address and one byte past it.
    std::unique_ptr<unsigned char[]> raw(new unsigned char[d.vertices() + 2 * align]);
    unsigned char* base = raw.get() + (align - reinterpret_cast<std::uintptr_t>(raw.get()) % align) % align;
    for (std::size_t i = 0; i < d.vertices() + 1; ++i) base[i] = static_cast<unsigned char>(i * 7 + 1);
    for (std::size_t offset : {std::size_t(0), std::size_t(1)}) {
        CAPTURE(offset);
        const DeviceVolume dv(ctx(), base + offset, d, ValueType::uint8);
        CHECK(dv.in_host_memory() == (offset == 0 || align == 1));
        Volume back = dv.download();
        CHECK(std::memcmp(back.data(), base + offset, d.vertices()) == 0);
    }
    // A result written in place into an aligned target, copied into an unaligned one.
    for (std::size_t offset : {std::size_t(0), std::size_t(1)}) {
        CAPTURE(offset);
        std::memset(base, 0, d.vertices() + 1);
        const Volume values = testutil::random_volume(d, ValueType::uint8, 0, 255, 9);
        const DeviceVolume src(ctx(), values);
        const DeviceVolume out = DeviceVolume::output(ctx(), base + offset, d, ValueType::uint8);
        ctx().queue().enqueueCopyBuffer(src.buffer(), out.buffer(), 0, 0, src.bytes());
        out.download(base + offset);
        CHECK(std::memcmp(src.download().data(), base + offset, d.vertices()) == 0);
    }
}

TEST_CASE("filter, LD, smooth and mesh on a 256^3 volume upload it once, results as the Volume path") {
    SyntheticOptions o;
    o.size = 256;
    o.noise = 20;
    const Volume v = make_synthetic("sphere", o);
    const double iso = 128, h = 2.5;
    const FilterSpec median = FilterSpec::median();

    const std::uint64_t before = ctx().uploads();
    const DeviceVolume dv(ctx(), v);
    const DeviceVolume filtered = targeted_filter(dv, median, iso, h);
    const DeviceVolume ld = local_fractal_dimension(filtered, iso);
    const SmoothResult smoothed = smooth_isosurface(filtered, iso, h);
    Mesh mesh = extract_isosurface(smoothed.volume, iso);
    color_by_ld(mesh, ld);
    const IsoCounts counts = intersected_counts(filtered, iso);
    CHECK(ctx().uploads() - before == 1);

    // The same through the Volume overloads (each uploads its input).
    const TargetedResult f = targeted_filter(ctx(), v, median, iso, h);
    const Volume ld_host = local_fractal_dimension(ctx(), f.volume, iso);
    const SmoothResult s = smooth_isosurface(ctx(), f.volume, iso, h);
    Mesh mesh_host = extract_isosurface(s.volume, iso);
    color_by_ld(mesh_host, ld_host);
    CHECK(ctx().uploads() - before > 2);

    CHECK(same_bytes(filtered.download(), f.volume));
    CHECK(same_bytes(ld.download(), ld_host));
    CHECK(same_bytes(smoothed.volume, s.volume));
    CHECK(smoothed.edges_lowered == s.edges_lowered);
    CHECK(mesh.positions == mesh_host.positions);
    CHECK(mesh.triangles == mesh_host.triangles);
    CHECK(mesh.colors == mesh_host.colors);
    CHECK(!mesh.triangles.empty());
    const IsoCounts host_counts = intersected_counts(ctx(), f.volume, iso);
    CHECK(counts.cubes == host_counts.cubes);
    CHECK(counts.edges == host_counts.edges);
    CHECK(counts.cubes > 0);
}

TEST_CASE("span counts and components of a DeviceVolume equal the Volume overloads, in slabs too") {
    testutil::TuningGuard guard;
    const Volume v = testutil::random_volume({17, 11, 23}, ValueType::uint8, 0, 40, 5);
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    SpanOptions opt;
    opt.kinds = {SpanKind::cubes, SpanKind::edges};
    opt.levels = 3;
    const SpanResult host = count_spans(ctx(), v, iso, opt);
    const DeviceVolume dv(ctx(), v);
    const std::uint64_t before = ctx().uploads();
    for (std::size_t slab : {std::size_t(0), std::size_t(5), std::size_t(9)}) {
        CAPTURE(slab);
        opt.slab_slices = slab;
        const SpanResult dev = count_spans(dv, iso, opt);
        for (std::size_t k = 0; k < 2; ++k) CHECK(dev.curves[k].counts == host.curves[k].counts);
        if (slab) CHECK(dev.slabs > 1);
    }
    const ComponentCurve c = count_components(dv, iso);
    CHECK(ctx().uploads() == before);
    CHECK(c.components == count_components(ctx(), v, iso).components);
}

TEST_CASE("D4, LD4, the pyramid, the noise estimate and components at S of a DeviceVolume: no upload, same results") {
    testutil::TuningGuard guard;
    for (ValueType t : {ValueType::uint8, ValueType::int16, ValueType::float32}) {
        CAPTURE(value_type_name(t));
        Volume v = testutil::random_volume({13, 10, 9}, t, -20, 60, 11);
        v.spacing = {0.5, 1.0, 2.0};
        const IsovalueSet iso = IsovalueSet::for_volume(v, 32);
        for (bool fp64 : {true, false}) {  // bins on the device, or the host's bin indices
            CAPTURE(fp64);
            ctx().tuning.use_fp64 = fp64;
            const DeviceVolume dv(ctx(), v);
            const std::uint64_t before = ctx().uploads();
            const Fd4Result d4 = fractal_dimension_4d(dv, 0);
            const Volume ld4 = local_fractal_dimension_4d(dv, 0, 4).download();
            const Volume sub = subsample(dv).download();
            const NoiseEstimate noise = estimate_noise(dv, iso, 0.0);
            const std::int64_t comp = count_components_at(dv, 20.5);
            CHECK(ctx().uploads() == before);
            const Fd4Result want = fractal_dimension_4d(ctx(), v, 0);
            CHECK(d4.i4 == want.i4);
            CHECK(d4.i4_sub == want.i4_sub);
            CHECK(d4.q == want.q);
            const Volume want_ld4 = local_fractal_dimension_4d(ctx(), v, 0, 4);
            CHECK(std::memcmp(ld4.data(), want_ld4.data(), want_ld4.size_bytes()) == 0);
            CHECK(ld4.spacing == v.spacing);
            const Volume want_sub = subsample(v);
            REQUIRE(sub.dims() == want_sub.dims());
            CHECK(std::memcmp(sub.data(), want_sub.data(), want_sub.size_bytes()) == 0);
            CHECK(sub.spacing == want_sub.spacing);
            const NoiseEstimate want_noise = estimate_noise(ctx(), v, iso, 0.0);
            CHECK(noise.edges == want_noise.edges);
            CHECK(noise.used == want_noise.used);
            for (std::size_t j = 0; j < iso.size(); ++j) {
                CHECK((noise.ratio[j] == want_noise.ratio[j] || (std::isnan(noise.ratio[j]) && std::isnan(want_noise.ratio[j]))));
                CHECK((noise.mean_span[j] == want_noise.mean_span[j] ||
                       (std::isnan(noise.mean_span[j]) && std::isnan(want_noise.mean_span[j]))));
            }
            CHECK(comp == count_components_at(ctx(), v, 20.5));
            CHECK(comp == count_components_by_labelling(v, 20.5));
        }
    }
}

}  // TEST_SUITE

TEST_SUITE("device") {

TEST_CASE("named enums: one name table, round trip, unknown names refused with the choices") {
    const auto round_trip = [](auto tag) {
        using E = decltype(tag);
        const std::vector<E> all = all_variants<E>();
        CHECK(all.size() >= 2);
        for (E v : all) CHECK(parse_variant<E>(variant_name(v)) == v);
        CHECK_THROWS_AS(parse_variant<E>("no-such-variant"), InputError);
    };
    round_trip(SpanVariant{});
    round_trip(SatVariant{});
    round_trip(LocalVariant{});
    round_trip(FilterVariant{});
    round_trip(Connectivity{});
    round_trip(MeshMethod{});
    round_trip(NoiseKind{});
    round_trip(SmoothVariant{});
    CHECK(std::string(variant_name(SpanVariant::private_histograms)) == "private");
    CHECK_THROWS_WITH(parse_variant<FilterVariant>("tile"), doctest::Contains("rows, vertices, tiled"));
    // The named functions of the other enums are the same tables.
    CHECK(std::string(connectivity_name(Connectivity::freudenthal)) == "freudenthal");
    CHECK(std::string(noise_kind_name(NoiseKind::gaussian)) == "gaussian");
    CHECK(std::string(smooth_variant_name(SmoothVariant::plain)) == "plain");
    CHECK(std::string(variant_name(MeshMethod::marching_tetrahedra)) == "mt");
    CHECK(parse_mesh_method("marching-cubes") == MeshMethod::marching_cubes);
    CHECK(all_variants<MeshMethod>().size() == 2);
    CHECK_THROWS_WITH_AS(parse_connectivity("six"), "--connectivity 'six': expected one of cube, freudenthal",
                         InputError);
    CHECK_THROWS_WITH_AS(parse_noise_kind("pink"), "--noise 'pink': expected one of uniform, gaussian", InputError);
    CHECK_THROWS_WITH_AS(parse_smooth_variant("blocky"), "--variant 'blocky': expected one of plain, gaussian",
                         InputError);
    CHECK_THROWS_WITH_AS(parse_mesh_method("dual"),
                         "--method 'dual': expected one of mc, marching-cubes, mt, marching-tetrahedra", InputError);
}

}  // TEST_SUITE

TEST_CASE("the targeted filter of a volume already on the device: no upload, same result and counts") {
    testutil::TuningGuard guard;
    SyntheticOptions opt;
    opt.size = 20;
    opt.type = ValueType::uint8;
    const Volume v = make_synthetic("noisy-sphere", opt);
    const DeviceVolume dv(ctx(), v);
    for (const FilterSpec& spec : {FilterSpec::median(), FilterSpec::gaussian(1.0)}) {
        CAPTURE(int(spec.kind));
        const std::uint64_t before = ctx().uploads();
        const TargetedResult got = targeted_filter(dv, v, spec, 128.0, 2.2, 6);
        CHECK(ctx().uploads() == before);
        const TargetedResult want = targeted_filter(ctx(), v, spec, 128.0, 2.2, 6);
        CHECK(ctx().uploads() == before + 1);
        CHECK(got.selected == want.selected);
        CHECK(got.changed == want.changed);
        CHECK(got.selected > 0);
        CHECK(std::memcmp(got.volume.data(), want.volume.data(), want.volume.size_bytes()) == 0);
    }
    opt.size = 18;
    const Volume other = make_synthetic("noisy-sphere", opt);
    CHECK_THROWS_AS(targeted_filter(dv, other, FilterSpec::median(), 128.0, 2.2, 6), InputError);
}
