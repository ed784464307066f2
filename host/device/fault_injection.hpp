// Test-only fault injection on one Context: the N-th buffer allocation, kernel enqueue or
// program build fails as the device would. Private to the library and its tests.
#pragma once
#include <cstdint>

#include "clfractal/device.hpp"

namespace clfractal {

/// Device operations a test can make fail: buffer allocations (create_buffer), kernel
/// enqueues (Context::launch) and program builds (Context::program).
enum class FaultSite { allocation = 0, enqueue = 1, build = 2 };

/// Counts the operations of each site and makes the `fail_at`-th one of `site` (1-based;
/// 0 = never) fail with CL_MEM_OBJECT_ALLOCATION_FAILURE, CL_OUT_OF_RESOURCES or
/// CL_BUILD_PROGRAM_FAILURE.
struct FaultPlan {
    FaultSite site = FaultSite::allocation;
    std::uint64_t fail_at = 0;
    std::uint64_t seen[3] = {0, 0, 0};  ///< operations of each site since the plan was set
};

/// Sets the plan of `ctx` (counts restart at 0); FaultPlan{} switches it off.
void set_fault_plan(Context& ctx, const FaultPlan& plan);
/// The plan of `ctx` with its counts so far.
FaultPlan fault_plan(const Context& ctx);
/// Counts one operation of `site` and throws DeviceError when the plan says it fails:
/// called by the one allocation, launch and build path.
void fault_point(Context& ctx, FaultSite site);

}  // namespace clfractal
