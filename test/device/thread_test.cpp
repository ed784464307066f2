// Several threads calling the library at once through the C ABI, each with its own context
// and all on one shared context: every curve equals the reference counts, and each thread's
// last-error message is its own. Run under TSan in the sanitizer stage
// (docs/reliability.md), with PoCL's own reports suppressed by name (sanitizer/tsan.supp).
#include <doctest/doctest.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "clfractal/clfractal.h"
#include "reference/span_reference.hpp"
#include "test_util.hpp"

using namespace clfractal;

namespace {

struct Case {
    Volume volume;
    int type;
    std::vector<std::uint64_t> level0, level1;  // reference box counts
};

Case make_case(ValueType t, int c_type, std::uint32_t seed) {
    Case c{testutil::random_volume({15, 11, 9}, t, 0, 60, seed), c_type, {}, {}};
    const IsovalueSet iso = IsovalueSet::for_volume(c.volume, 32);
    c.level0 = ref::cubes_brute(c.volume, iso);
    c.level1 = ref::cubes_brute(ref::level(c.volume, 1), iso);
    return c;
}

/// One round: a volume, its curve, every count against the reference. Returns "" or what differed.
std::string round_trip(clf_context* ctx, const Case& c) {
    const Dims d = c.volume.dims();
    clf_volume* v = nullptr;
    if (clf_volume_create(c.volume.data(), d.nx, d.ny, d.nz, c.type, &v) != CLF_OK) return clf_last_error();
    clf_curve_options o;
    clf_curve_options_default(&o);
    o.bins = c.type == CLF_FLOAT32 ? 32 : 0;
    clf_curve* curve = nullptr;
    std::string problem;
    if (clf_curve_compute(ctx, v, &o, &curve) != CLF_OK) problem = clf_last_error();
    else if (clf_curve_size(curve) != c.level0.size()) problem = "curve size";
    else
        for (std::size_t j = 0; j < c.level0.size() && problem.empty(); ++j)
            if (clf_curve_count(curve, 0, j) != c.level0[j] || clf_curve_count(curve, 1, j) != c.level1[j])
                problem = "count differs at isovalue " + std::to_string(j);
    clf_curve_destroy(curve);
    clf_volume_destroy(v);
    return problem;
}

}  // namespace

TEST_SUITE("threads") {

TEST_CASE("threads with their own and with a shared context give the reference counts") {
    const std::vector<Case> cases = {make_case(ValueType::uint8, CLF_UINT8, 1),
                                     make_case(ValueType::uint16, CLF_UINT16, 2),
                                     make_case(ValueType::float32, CLF_FLOAT32, 3)};
    constexpr int threads = 4, rounds = 6;
    clf_context* shared = nullptr;
    REQUIRE(clf_context_create("", &shared) == CLF_OK);
    for (bool own : {false, true}) {
        CAPTURE(own);
        std::vector<std::string> problems(threads);
        std::atomic<int> done{0};
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back([&, t] {
                clf_context* ctx = shared;
                if (own && clf_context_create("", &ctx) != CLF_OK) {
                    problems[t] = clf_last_error();
                    return;
                }
                for (int r = 0; r < rounds && problems[t].empty(); ++r) {
                    problems[t] = round_trip(ctx, cases[std::size_t(t + r) % cases.size()]);
                    // Each thread's last error is its own.
                    clf_volume* none = nullptr;
                    const int bad = 100 + t;
                    clf_volume_create(&bad, 1, 1, 1, bad, &none);
                    if (std::string(clf_last_error()).find(std::to_string(bad)) == std::string::npos)
                        problems[t] = "last error of another thread: " + std::string(clf_last_error());
                    ++done;
                }
                if (own) clf_context_destroy(ctx);
            });
        for (auto& th : pool) th.join();
        for (int t = 0; t < threads; ++t) CHECK_MESSAGE(problems[t].empty(), "thread ", t, ": ", problems[t]);
        CHECK(done == threads * rounds);
    }
    clf_context_destroy(shared);
}

}  // TEST_SUITE
