// The one configuration of the Khronos C++ bindings (CL/opencl.hpp) that clfractal's
// headers use: OpenCL 1.2 as target and minimum, exceptions enabled (the library converts
// cl::Error into DeviceError at its boundaries). Every clfractal header that needs the
// bindings includes this one. A program that includes <CL/opencl.hpp> itself before any
// clfractal header must define the same four macros first; otherwise nothing is needed.
#pragma once
#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_ENABLE_EXCEPTIONS
#define CL_HPP_ENABLE_EXCEPTIONS
#endif
#include <CL/opencl.hpp>
