#pragma once
// The engine's errors as Python exceptions, messages unchanged:
//   sdfkit.Error(Exception)                  any sdfkit::Error
//   sdfkit.InputError(Error, ValueError)     sdfkit::InputError: bad files, arrays, options
//   sdfkit.DeviceError(Error, RuntimeError)  sdfkit::DeviceError: no device, kernel build failed

#include <pybind11/pybind11.h>

namespace sdfkit::python {

// Adds Error, InputError and DeviceError to `m` and registers the C++ -> Python translation.
void register_errors(pybind11::module_& m);

}  // namespace sdfkit::python
