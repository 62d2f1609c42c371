#pragma once
// Errors raised by the engine. Every error carries one sentence a user understands;
// the CLI prints it on one line and exits non-zero.

#include <stdexcept>
#include <string>

namespace sdfkit {

class Error : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Input that cannot be used: a malformed file, NaN coordinates, an empty mesh.
class InputError : public Error {
public:
  using Error::Error;
};

// Options that do not fit together or do not apply: an option the chosen backend would ignore,
// an out-of-range value, a malformed argument. The CLI exits 2 for it (1 for other errors).
class UsageError : public InputError {
public:
  using InputError::InputError;
};

// A device or platform problem: no Vulkan device, no OpenCL platform, a failed kernel build.
class DeviceError : public Error {
public:
  using Error::Error;
};

}  // namespace sdfkit
