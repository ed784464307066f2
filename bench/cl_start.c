/* The least an OpenCL program pays before any work: platforms, the first platform's first
 * device, a context and a profiling queue on it, released, from process start to exit
 * (bench/startup_bench.sh times it beside clfractal). Prints the device's name; exit 1 when
 * any step fails. */
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <stdio.h>

int main(void) {
    cl_platform_id platform;
    cl_device_id device;
    cl_int err = CL_SUCCESS;
    char name[256] = "";
    if (clGetPlatformIDs(1, &platform, NULL) != CL_SUCCESS) return 1;
    if (clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, NULL) != CL_SUCCESS) return 1;
    cl_context context = clCreateContext(NULL, 1, &device, NULL, NULL, &err);
    if (err != CL_SUCCESS) return 1;
    cl_command_queue queue = clCreateCommandQueue(context, device, CL_QUEUE_PROFILING_ENABLE, &err);
    if (err != CL_SUCCESS) return 1;
    clGetDeviceInfo(device, CL_DEVICE_NAME, sizeof name - 1, name, NULL);
    printf("%s\n", name);
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
    return 0;
}
