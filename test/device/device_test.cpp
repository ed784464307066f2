// The device layer: listing, errors with names and build logs, buffers, launch checks.
#include <doctest/doctest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

#include "clfractal/device.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/span.hpp"
#include "device/kernel_call.hpp"
#include "device/program_cache.hpp"
#include "device/type_options.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::ctx;

TEST_SUITE("device") {

TEST_CASE("devices are listed and exactly one is chosen") {
    auto all = list_devices();
    REQUIRE(!all.empty());
    int chosen = 0;
    for (auto& d : all) chosen += d.chosen;
    CHECK(chosen == 1);
    MESSAGE("running on " << ctx().description());
}

TEST_CASE("CLFRACTAL_DEVICE that matches nothing is a clear error") {
    const char* old = std::getenv("CLFRACTAL_DEVICE");
    std::string saved = old ? old : "";
    setenv("CLFRACTAL_DEVICE", "no-such-device-xyz", 1);
    CHECK_THROWS_WITH_AS(choose_device(), doctest::Contains("no-such-device-xyz"), DeviceError);
    if (old) setenv("CLFRACTAL_DEVICE", saved.c_str(), 1);
    else unsetenv("CLFRACTAL_DEVICE");
    setenv("CLFRACTAL_DEVICE_TYPE", "quantum", 1);
    CHECK_THROWS_AS(choose_device(), DeviceError);
    setenv("CLFRACTAL_DEVICE_TYPE", "cpu", 1);
}

TEST_CASE("error names and build logs") {
    CHECK(std::string(cl_error_name(CL_OUT_OF_RESOURCES)) == "CL_OUT_OF_RESOURCES");
    CHECK_THROWS_WITH_AS(check_cl(CL_INVALID_KERNEL_ARGS, "clEnqueueNDRangeKernel"),
                         "clEnqueueNDRangeKernel: CL_INVALID_KERNEL_ARGS (-52)", DeviceError);
    CHECK_NOTHROW(check_cl(CL_SUCCESS, "anything"));
    // A type that does not exist makes the build fail: the message carries the options
    // and the compiler's log.
    try {
        ctx().program("span", " -DT=no_such_type");
        FAIL("the build should have failed");
    } catch (const DeviceError& e) {
        std::string m = e.what();
        CHECK(m.find("kernels/span.cl") != std::string::npos);
        CHECK(m.find("-DT=no_such_type") != std::string::npos);
        CHECK(m.find("CL_BUILD_PROGRAM_FAILURE") != std::string::npos);
        CHECK(m.find("no_such_type") != m.rfind("no_such_type"));  // also named in the log
    }
    CHECK_THROWS_AS(ctx().program("no_such_family", ""), DeviceError);
    CHECK_THROWS_AS(ctx().kernel("copy", "no_such_kernel", ""), DeviceError);
}

TEST_CASE("program binaries across processes: stored, loaded, checked, rebuilt when corrupt, disabled by 'off'") {
    namespace fs = std::filesystem;
    const std::string dir = fs::temp_directory_path() / ("clfractal_program_cache_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const char* before = std::getenv("CLFRACTAL_PROGRAM_CACHE");
    const std::string saved = before ? before : "";
    ::setenv("CLFRACTAL_PROGRAM_CACHE", dir.c_str(), 1);
    CHECK(detail::program_cache_dir() == dir);

    // The entry format on its own: the binary back for its key only; truncation, a flipped
    // byte or a foreign key read as absent.
    const std::vector<unsigned char> bytes = {1, 2, 3, 250, 0, 7};
    detail::store_program_binary(dir, "key one", bytes);
    CHECK(detail::load_program_binary(dir, "key one") == bytes);
    CHECK(!detail::load_program_binary(dir, "key two"));
    const std::string file = detail::program_cache_file(dir, "key one");
    std::string whole;
    {
        std::ifstream in(file, std::ios::binary);
        whole.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    for (std::size_t cut : {std::size_t(0), std::size_t(10), whole.size() - 1}) {
        std::ofstream(file, std::ios::binary | std::ios::trunc).write(whole.data(), std::streamsize(cut));
        CHECK(!detail::load_program_binary(dir, "key one"));
    }
    std::string flipped = whole;
    flipped[whole.size() - 10] ^= 1;  // a byte of the binary
    std::ofstream(file, std::ios::binary | std::ios::trunc).write(flipped.data(), std::streamsize(flipped.size()));
    CHECK(!detail::load_program_binary(dir, "key one"));
    fs::remove_all(dir);

    // Contexts as new processes: the first stores, the second loads (the entries are not
    // rewritten: same inodes), garbage entries are rebuilt and replaced; same counts throughout.
    const Volume v = testutil::random_volume({19, 11, 7}, ValueType::uint8, 0, 255, 5);
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    auto counts = [&] {
        Context fresh(ctx().device());
        return count_spans(fresh, v, iso).get(SpanKind::cubes).counts;
    };
    auto entries = [&] {
        std::map<std::string, ino_t> m;
        for (const auto& e : fs::directory_iterator(dir)) {
            struct stat st {};
            ::stat(e.path().c_str(), &st);
            m[e.path().filename().string()] = st.st_ino;
        }
        return m;
    };
    const auto want = count_spans(ctx(), v, iso).get(SpanKind::cubes).counts;
    CHECK(counts() == want);
    const auto stored = entries();
    REQUIRE(!stored.empty());
    for (const auto& [name, inode] : stored) CHECK(name.size() == 36);  // 32 hex digits + ".bin": no temporaries
    CHECK(counts() == want);
    CHECK(entries() == stored);
    for (const auto& [name, inode] : stored) std::ofstream(dir + "/" + name, std::ios::trunc) << "not a binary";
    CHECK(counts() == want);
    const auto rebuilt = entries();
    CHECK(rebuilt.size() == stored.size());
    for (const auto& [name, inode] : rebuilt) CHECK(fs::file_size(dir + "/" + name) > 100);
    CHECK(counts() == want);
    CHECK(entries() == rebuilt);

    ::setenv("CLFRACTAL_PROGRAM_CACHE", "off", 1);
    CHECK(detail::program_cache_dir().empty());
    fs::remove_all(dir);
    CHECK(counts() == want);
    CHECK(!fs::exists(dir));
    if (before) ::setenv("CLFRACTAL_PROGRAM_CACHE", saved.c_str(), 1);
    else ::unsetenv("CLFRACTAL_PROGRAM_CACHE");
}

TEST_CASE("programs are cached per (family, options)") {
    const cl::Program& a = ctx().program("copy", "");
    const cl::Program& b = ctx().program("copy", "");
    CHECK(a() == b());
    const cl::Program& c = ctx().program("copy", " -DUNUSED=1");
    CHECK(a() != c());
}

TEST_CASE("typed buffers round trip and the copy kernel copies") {
    std::vector<cl_uint> host(4 * 1000);
    for (std::size_t i = 0; i < host.size(); ++i) host[i] = cl_uint(i * 2654435761u);
    Buffer<cl_uint> src(ctx(), host.size()), dst(ctx(), host.size());
    CHECK(src.size() == host.size());
    CHECK(src.bytes() == host.size() * 4);
    src.write(ctx().queue(), host.data(), host.size());
    cl::Kernel k = ctx().kernel("copy", "copy_uint4", "");
    k.setArg(0, src.get());
    k.setArg(1, dst.get());
    ctx().launch(k, cl::NDRange(1000));
    CHECK(dst.to_host(ctx().queue()) == host);
    Buffer<cl_uint> moved = std::move(dst);
    CHECK(moved.size() == host.size());
}

TEST_CASE("launch sizes are checked before enqueueing") {
    cl::Kernel k = ctx().kernel("copy", "copy_uint4", "");
    Buffer<cl_uint> b(ctx(), 4 * 64);
    k.setArg(0, b.get());
    k.setArg(1, b.get());
    CHECK_THROWS_WITH_AS(ctx().launch(k, cl::NDRange(60), cl::NDRange(16)), doctest::Contains("not a multiple"),
                         DeviceError);
    CHECK_THROWS_WITH_AS(ctx().launch(k, cl::NDRange(1 << 20), cl::NDRange(1 << 20)),
                         doctest::Contains("CL_KERNEL_WORK_GROUP_SIZE"), DeviceError);
}

TEST_CASE("local memory and allocation limits are checked before the device sees them") {
    // A local histogram larger than the device's local memory: refused by the launch path
    // with the limit's name (the device would answer CL_OUT_OF_RESOURCES or worse).
    cl::Kernel k = ctx().kernel("span", "count_cubes_atomic", type_options(ValueType::uint8) + " -DINTEGER_VALUES");
    Buffer<cl_uchar> vol(ctx(), 8);
    Buffer<float> iso(ctx(), 1);
    Buffer<cl_int> partial(ctx(), 16);
    k.setArg(0, vol.get());
    for (cl_uint i : {1u, 2u, 3u}) k.setArg(i, 2);
    k.setArg(4, cl_long(0));
    k.setArg(5, iso.get());
    k.setArg(6, 1);
    k.setArg(7, 2);
    k.setArg(8, partial.get());
    k.setArg(9, cl::Local(ctx().local_mem() + 4096));
    CHECK_THROWS_WITH_AS(ctx().launch(k, cl::NDRange(1), cl::NDRange(1)), doctest::Contains("CL_DEVICE_LOCAL_MEM_SIZE"),
                         DeviceError);
    CHECK_THROWS_WITH_AS(create_buffer(ctx(), CL_MEM_READ_WRITE, ctx().max_alloc() + 1),
                         doctest::Contains("CL_DEVICE_MAX_MEM_ALLOC_SIZE"), DeviceError);
}

TEST_CASE("compute times count every kernel's execution and lie within the call's wall time") {
    // A fresh context: its first launches compile; that compilation is not compute time, but
    // the kernels' own execution (their profiling events) is, so a one-slab call whose work
    // is all first launches reports a compute time >= the kernels' time and <= its wall time.
    Context fresh(ctx().device());
    for (int call = 0; call < 2; ++call) {
        const Volume v = testutil::random_volume({97, 90, 83}, ValueType::uint8, 0, 255, 7 + call);
        const IsovalueSet iso = IsovalueSet::for_volume(v);
        const double k0 = fresh.kernel_seconds();
        const auto t0 = std::chrono::steady_clock::now();
        const SpanResult r = count_spans(fresh, v, iso, SpanOptions{{SpanKind::cubes, SpanKind::edges}, 3, 0});
        const double wall = seconds_since(t0), kernels = fresh.kernel_seconds() - k0;
        CAPTURE(call); CAPTURE(r.seconds); CAPTURE(kernels); CAPTURE(wall);
        CHECK(kernels > 0);
        CHECK(r.seconds >= kernels * 0.99);
        CHECK(r.seconds <= wall);
    }
}

TEST_CASE("without cl_khr_fp64: one clear error naming the extension and --as float32") {
    // This device has the extension (PoCL CPU); clearing Tuning::allow_fp64 makes it behave
    // as one without it.
    testutil::TuningGuard guard;
    REQUIRE(ctx().has_fp64());
    const clfractal::Volume f64 = testutil::random_volume({6, 5, 4}, clfractal::ValueType::float64, -9, 9, 1);
    const clfractal::Volume i32 = testutil::random_volume({6, 5, 4}, clfractal::ValueType::int32, -9, 9, 2);
    CHECK(clfractal::count_spans(ctx(), f64, clfractal::IsovalueSet::for_volume(f64)).curves.size() == 1);
    ctx().tuning.allow_fp64 = false;
    const auto clear = [](auto&& f) {
        try {
            f();
        } catch (const clfractal::InputError& e) {
            const std::string m = e.what();
            return m.find("cl_khr_fp64") != std::string::npos && m.find("--as float32") != std::string::npos &&
                   m.find(ctx().description()) != std::string::npos && m.find('\n') == std::string::npos;
        }
        return false;
    };
    // Programs already built and cached for float64 are refused as well.
    CHECK(clear([&] { clfractal::count_spans(ctx(), f64, clfractal::IsovalueSet::for_volume(f64)); }));
    CHECK(clear([&] { clfractal::local_fractal_dimension(ctx(), f64, 0.5, 4); }));
    CHECK(clear([&] { clfractal::median_filter(ctx(), f64); }));
    // int32 and uint32 filters accumulate in double; their median and counts need no fp64.
    CHECK(clear([&] { clfractal::gaussian_filter(ctx(), i32, 1.0); }));
    CHECK(clfractal::median_filter(ctx(), i32).type() == clfractal::ValueType::int32);
    CHECK(clfractal::count_spans(ctx(), i32, clfractal::IsovalueSet::for_volume(i32)).curves.size() == 1);
    // A wide int32 range compares against float64 isovalues: double again.
    clfractal::Volume wide = i32;
    wide.as<std::int32_t>()[0] = 2000000000;
    CHECK(clear([&] { clfractal::count_spans(ctx(), wide, clfractal::IsovalueSet::for_volume(wide)); }));
    // Converted on read (--as float32), everything runs.
    const clfractal::Volume f32 = clfractal::convert_volume(f64, clfractal::ValueType::float32);
    CHECK(clfractal::count_spans(ctx(), f32, clfractal::IsovalueSet::for_volume(f32)).curves.size() == 1);
}

}  // TEST_SUITE("device")
