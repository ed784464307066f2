// clfractal devices: the OpenCL platforms and devices, the chosen one marked.
#include <iostream>

#include "clfractal/device.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;

namespace cli {

namespace {

int cmd_devices() {
    auto all = list_devices();
    if (all.empty()) {
        std::cout << "no OpenCL devices (install an ICD, e.g. pocl-opencl-icd)\n";
        return 1;
    }
    for (auto& d : all)
        std::cout << (d.chosen ? "* " : "  ") << d.platform << " / " << d.name << "  [" << d.type << ", "
                  << d.compute_units << " CUs, " << (d.global_mem >> 20) << " MiB, max alloc "
                  << (d.max_alloc >> 20) << " MiB]\n";
    std::cout << "(* = chosen; set CLFRACTAL_DEVICE=<name substring> or CLFRACTAL_DEVICE_TYPE=cpu|gpu)\n";
    return 0;
}

struct DevicesArgs {};

void setup_devices(CLI::App*, DevicesArgs&) {}

}  // namespace

Command devices_command() {
    // It lists the platforms itself; the shared context is not what it prints.
    return without_device(command<DevicesArgs>("devices", "list OpenCL platforms and devices, marking the chosen one",
                                               setup_devices, [](const DevicesArgs&) { return cmd_devices(); }));
}

}  // namespace cli
