// Device faults (FaultPlan): the N-th buffer allocation, kernel enqueue or program build
// fails; walked over every step of fd, local, filter, components, noise, the noise level and a stream. Each
// run ends with a clean DeviceError naming the injected fault or with the fault-free result;
// never a crash or another exception (an InputError is about the input, which is valid here). A failed allocation is recovered from: fd, local, noise, the noise
// level and the filters' slab path retry with smaller slabs, components with its host steps. Leaks are
// left to the sanitizer build, which runs this suite too.
#include <doctest/doctest.h>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "clfractal/components.hpp"
#include "clfractal/filter.hpp"
#include "clfractal/local.hpp"
#include "clfractal/noise.hpp"
#include "clfractal/noise_level.hpp"
#include "clfractal/span.hpp"
#include "clfractal/stream.hpp"
#include "test_util.hpp"
#include "device/fault_injection.hpp"

using namespace clfractal;

namespace {

const char* site_name(FaultSite s) {
    return s == FaultSite::allocation ? "allocation" : s == FaultSite::enqueue ? "enqueue" : "build";
}

// The results of one operation as bytes, so that any two runs compare exactly.
using Run = std::function<std::vector<unsigned char>(Context&)>;

template <class T> std::vector<unsigned char> bytes_of(const T* p, std::size_t n) {
    const auto* b = reinterpret_cast<const unsigned char*>(p);
    return std::vector<unsigned char>(b, b + n * sizeof(T));
}

std::vector<unsigned char> bytes_of(const Volume& v) {
    return bytes_of(static_cast<const unsigned char*>(v.data()), v.size_bytes());
}

std::vector<unsigned char> bytes_of(const SpanResult& r) {
    std::vector<unsigned char> out;
    for (const SpanCurves& c : r.curves)
        for (const auto& level : c.counts) {
            const auto b = bytes_of(level.data(), level.size());
            out.insert(out.end(), b.begin(), b.end());
        }
    return out;
}

// A context like the shared one (same device, same tuning), with its own program cache.
struct FreshContext : Context {
    FreshContext() : Context(testutil::ctx().device()) { tuning = testutil::ctx().tuning; }
};

// Walks n = 1, 2, ... over every operation of `site` that `run` makes. Allocation and
// enqueue faults hit a context whose programs are built (as on every call after the first);
// build faults a fresh one.
void walk(const std::string& what, const Run& run, FaultSite site) {
    CAPTURE(what);
    const std::string site_text = site_name(site);
    CAPTURE(site_text);
    FreshContext plain;
    const std::vector<unsigned char> want = run(plain);
    FreshContext counted;
    if (site != FaultSite::build) run(counted);
    set_fault_plan(counted, FaultPlan{site, 0});
    run(counted);
    const std::uint64_t steps = fault_plan(counted).seen[int(site)];
    CHECK(steps > 0);
    std::uint64_t failed = 0, recovered = 0;
    for (std::uint64_t n = 1; n <= steps; ++n) {
        CAPTURE(n);
        FreshContext c;
        if (site != FaultSite::build) run(c);
        set_fault_plan(c, FaultPlan{site, n});
        try {
            const std::vector<unsigned char> got = run(c);
            CHECK(got == want);
            ++recovered;
        } catch (const DeviceError& e) {
            ++failed;
            CHECK(std::string(e.what()).find("injected fault") != std::string::npos);
        } catch (const InputError& e) {
            // No fault makes the (valid) input bad: the message says which step claimed it did.
            FAIL_CHECK("InputError after a device fault: " << e.what());
        }
        // The context works again once the fault is gone.
        set_fault_plan(c, FaultPlan{});
        CHECK(run(c) == want);
    }
    // Every failed allocation of fd, local, components and noise is recovered from (smaller
    // slabs, or the host steps), as are those of the filters' slab path; every other fault
    // is an error.
    if (site != FaultSite::allocation || what == "stream") CHECK(failed == steps);
    else if (what == "filter") CHECK(recovered > 0);
    else CHECK(recovered == steps);
    MESSAGE(what << ": " << site_text << " faults 1.." << steps << ", " << failed << " clean errors, " << recovered
                 << " correct results");
}

}  // namespace

TEST_SUITE("faults") {

TEST_CASE("every device step of fd, local, filter, components, noise, noise level and a stream fails cleanly or recovers") {
    const Volume v = testutil::random_volume({11, 9, 7}, ValueType::uint8, 0, 20, 31);
    const IsovalueSet iso = IsovalueSet::for_volume(v);
    const std::vector<std::pair<std::string, Run>> runs = {
        {"fd", [&](Context& c) {
             SpanOptions opt;
             opt.kinds = {SpanKind::cubes, SpanKind::edges};
             return bytes_of(count_spans(c, v, iso, opt));
         }},
        {"local", [&](Context& c) { return bytes_of(local_fractal_dimension(c, v, 10.5, 4)); }},
        {"filter", [&](Context& c) {
             auto out = bytes_of(targeted_filter(c, v, FilterSpec::median(), 10.5, 2.2, 4).volume);
             const auto g = bytes_of(apply_filter(c, v, FilterSpec::gaussian(1)));
             out.insert(out.end(), g.begin(), g.end());
             return out;
         }},
        {"components", [&](Context& c) {
             const ComponentCurve k = count_components(c, v, iso);
             return bytes_of(k.components.data(), k.components.size());
         }},
        {"noise", [&](Context& c) {
             NoiseOptions opt;
             opt.amplitude = 3;
             opt.keep_type = true;
             return bytes_of(add_noise(c, v, opt));
         }},
        {"noise level", [&](Context& c) {
             const NoiseBlocks b = noise_blocks(c, v, 4);
             auto out = bytes_of(b.sum_squares.data(), b.sum_squares.size());
             const auto n = bytes_of(b.count.data(), b.count.size());
             out.insert(out.end(), n.begin(), n.end());
             return out;
         }},
        {"stream", [&](Context& c) {
             SpanStream s(c, v.dims().nx, v.dims().ny, v.type(), iso, 2);
             const std::size_t plane = v.dims().nx * v.dims().ny;
             for (std::size_t z = 0; z < v.dims().nz; ++z) s.push_slice(v.as<std::uint8_t>() + z * plane);
             return bytes_of(s.counts());
         }},
    };
    for (const auto& [what, run] : runs)
        for (FaultSite site : {FaultSite::allocation, FaultSite::enqueue, FaultSite::build}) walk(what, run, site);
}

}  // TEST_SUITE
