#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <iostream>

#include "clfractal/device.hpp"

int main(int argc, char** argv) {
    // Every suite shares the process-wide context, so programs compile once per run
    // (and PoCL's on-disk cache, POCL_CACHE_DIR, keeps them across runs).
    try {
        std::cerr << "device: " << clfractal::Context::shared().description() << "\n";
    } catch (const std::exception& e) {
        std::cerr << "no OpenCL device: " << e.what() << "\n";
        return 1;
    }
    doctest::Context ctx(argc, argv);
    return ctx.run();
}
