#pragma once
// Thin owning wrappers over the OpenCL C API (private to sdfkit_opencl): move-only handles that
// release on destruction, one error check that turns a cl_int into a DeviceError with a
// sentence, and device enumeration across platforms.

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include <string>
#include <utility>
#include <vector>

namespace sdfkit::cl::detail {

// The symbolic name of an OpenCL status code ("CL_OUT_OF_RESOURCES"), or "unknown error".
const char* status_name(cl_int status);

// Throws DeviceError("OpenCL failed while <doing>: CL_... (code)") when status != CL_SUCCESS.
void check(cl_int status, const std::string& doing);

// A move-only owner of one OpenCL object; Release is its clRelease* function.
template <typename T, cl_int (*Release)(T)>
class Handle {
public:
  Handle() = default;
  explicit Handle(T raw) : raw_(raw) {}
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : raw_(std::exchange(other.raw_, nullptr)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      raw_ = std::exchange(other.raw_, nullptr);
    }
    return *this;
  }
  T get() const { return raw_; }
  explicit operator bool() const { return raw_ != nullptr; }
  void reset() {
    if (raw_) Release(raw_);
    raw_ = nullptr;
  }

private:
  T raw_ = nullptr;
};

using Context = Handle<cl_context, clReleaseContext>;
using Queue = Handle<cl_command_queue, clReleaseCommandQueue>;
using Program = Handle<cl_program, clReleaseProgram>;
using Kernel = Handle<cl_kernel, clReleaseKernel>;
using Event = Handle<cl_event, clReleaseEvent>;

// A device buffer that remembers its size; grows (reallocates) only when asked for more.
class Buffer {
public:
  Buffer() = default;
  // Makes sure the buffer holds at least `bytes` (> 0); keeps the old one when it is big enough.
  void reserve(cl_context context, std::size_t bytes, cl_mem_flags flags, const char* what);
  cl_mem get() const { return mem_.get(); }
  std::size_t size() const { return size_; }
  void reset() {
    mem_.reset();
    size_ = 0;
  }

private:
  Handle<cl_mem, clReleaseMemObject> mem_;
  std::size_t size_ = 0;
};

// One device as found by enumeration.
struct FoundDevice {
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  std::string platform_name, name, vendor, version, type;
  std::size_t global_memory = 0;
};

// Every device of every platform, in platform order. Empty when the ICD loader finds no
// platform; throws DeviceError only for other failures.
std::vector<FoundDevice> enumerate_devices();

std::string device_string(cl_device_id device, cl_device_info what);

}  // namespace sdfkit::cl::detail
