#include "cl_api.hpp"

#include "sdfkit/core/error.hpp"

#include <CL/cl_ext.h>

namespace sdfkit::cl::detail {

const char* status_name(cl_int status) {
  switch (status) {
#define SDFKIT_CL_CASE(code) \
  case code: return #code;
    SDFKIT_CL_CASE(CL_SUCCESS)
    SDFKIT_CL_CASE(CL_DEVICE_NOT_FOUND)
    SDFKIT_CL_CASE(CL_DEVICE_NOT_AVAILABLE)
    SDFKIT_CL_CASE(CL_COMPILER_NOT_AVAILABLE)
    SDFKIT_CL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    SDFKIT_CL_CASE(CL_OUT_OF_RESOURCES)
    SDFKIT_CL_CASE(CL_OUT_OF_HOST_MEMORY)
    SDFKIT_CL_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    SDFKIT_CL_CASE(CL_BUILD_PROGRAM_FAILURE)
    SDFKIT_CL_CASE(CL_INVALID_VALUE)
    SDFKIT_CL_CASE(CL_INVALID_DEVICE)
    SDFKIT_CL_CASE(CL_INVALID_CONTEXT)
    SDFKIT_CL_CASE(CL_INVALID_COMMAND_QUEUE)
    SDFKIT_CL_CASE(CL_INVALID_MEM_OBJECT)
    SDFKIT_CL_CASE(CL_INVALID_BUILD_OPTIONS)
    SDFKIT_CL_CASE(CL_INVALID_PROGRAM)
    SDFKIT_CL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    SDFKIT_CL_CASE(CL_INVALID_KERNEL_NAME)
    SDFKIT_CL_CASE(CL_INVALID_KERNEL)
    SDFKIT_CL_CASE(CL_INVALID_ARG_INDEX)
    SDFKIT_CL_CASE(CL_INVALID_ARG_VALUE)
    SDFKIT_CL_CASE(CL_INVALID_ARG_SIZE)
    SDFKIT_CL_CASE(CL_INVALID_KERNEL_ARGS)
    SDFKIT_CL_CASE(CL_INVALID_WORK_DIMENSION)
    SDFKIT_CL_CASE(CL_INVALID_WORK_GROUP_SIZE)
    SDFKIT_CL_CASE(CL_INVALID_WORK_ITEM_SIZE)
    SDFKIT_CL_CASE(CL_INVALID_GLOBAL_OFFSET)
    SDFKIT_CL_CASE(CL_INVALID_EVENT)
    SDFKIT_CL_CASE(CL_INVALID_OPERATION)
    SDFKIT_CL_CASE(CL_INVALID_BUFFER_SIZE)
    SDFKIT_CL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    SDFKIT_CL_CASE(CL_PLATFORM_NOT_FOUND_KHR)
#undef SDFKIT_CL_CASE
    default: return "unknown error";
  }
}

void check(cl_int status, const std::string& doing) {
  if (status == CL_SUCCESS) return;
  throw DeviceError("OpenCL failed while " + doing + ": " + status_name(status) + " (" +
                    std::to_string(status) + ")");
}

void Buffer::reserve(cl_context context, std::size_t bytes, cl_mem_flags flags,
                     const char* what) {
  if (bytes == 0) bytes = 16;
  if (mem_ && size_ >= bytes) return;
  mem_.reset();
  size_ = 0;
  cl_int status = CL_SUCCESS;
  cl_mem mem = clCreateBuffer(context, flags, bytes, nullptr, &status);
  check(status, std::string("allocating ") + std::to_string(bytes) + " bytes of device memory for " + what);
  mem_ = Handle<cl_mem, clReleaseMemObject>(mem);
  size_ = bytes;
}

std::string device_string(cl_device_id device, cl_device_info what) {
  std::size_t size = 0;
  check(clGetDeviceInfo(device, what, 0, nullptr, &size), "querying a device property");
  std::string s(size, '\0');
  check(clGetDeviceInfo(device, what, size, s.data(), nullptr), "querying a device property");
  while (!s.empty() && (s.back() == '\0' || s.back() == ' ')) s.pop_back();
  return s;
}

namespace {

std::string platform_string(cl_platform_id platform, cl_platform_info what) {
  std::size_t size = 0;
  check(clGetPlatformInfo(platform, what, 0, nullptr, &size), "querying a platform property");
  std::string s(size, '\0');
  check(clGetPlatformInfo(platform, what, size, s.data(), nullptr), "querying a platform property");
  while (!s.empty() && (s.back() == '\0' || s.back() == ' ')) s.pop_back();
  return s;
}

std::string type_name(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "GPU";
  if (type & CL_DEVICE_TYPE_CPU) return "CPU";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

}  // namespace

std::vector<FoundDevice> enumerate_devices() {
  cl_uint platform_count = 0;
  const cl_int status = clGetPlatformIDs(0, nullptr, &platform_count);
  // The ICD loader answers "no platform" with CL_PLATFORM_NOT_FOUND_KHR (or, on some loaders,
  // a success with zero platforms).
  if (status == CL_PLATFORM_NOT_FOUND_KHR || platform_count == 0) return {};
  check(status, "listing OpenCL platforms");
  std::vector<cl_platform_id> platforms(platform_count);
  check(clGetPlatformIDs(platform_count, platforms.data(), nullptr), "listing OpenCL platforms");

  std::vector<FoundDevice> found;
  for (cl_platform_id platform : platforms) {
    cl_uint count = 0;
    const cl_int s = clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 0, nullptr, &count);
    if (s == CL_DEVICE_NOT_FOUND || count == 0) continue;
    check(s, "listing the devices of an OpenCL platform");
    std::vector<cl_device_id> devices(count);
    check(clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, count, devices.data(), nullptr),
          "listing the devices of an OpenCL platform");
    const std::string pname = platform_string(platform, CL_PLATFORM_NAME);
    for (cl_device_id device : devices) {
      FoundDevice d;
      d.platform = platform;
      d.device = device;
      d.platform_name = pname;
      d.name = device_string(device, CL_DEVICE_NAME);
      d.vendor = device_string(device, CL_DEVICE_VENDOR);
      d.version = device_string(device, CL_DEVICE_VERSION);
      cl_device_type type = 0;
      check(clGetDeviceInfo(device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr),
            "querying a device's type");
      d.type = type_name(type);
      cl_ulong memory = 0;
      check(clGetDeviceInfo(device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(memory), &memory, nullptr),
            "querying a device's memory size");
      d.global_memory = static_cast<std::size_t>(memory);
      found.push_back(std::move(d));
    }
  }
  return found;
}

}  // namespace sdfkit::cl::detail
