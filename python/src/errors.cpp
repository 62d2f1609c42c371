#include "errors.hpp"

#include "sdfkit/core/error.hpp"

#include <string>

namespace sdfkit::python {
namespace {

// The exception classes live as long as the interpreter: the module holds a reference, and
// these borrowed pointers are only used while it is loaded.
PyObject* g_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_device_error = nullptr;

PyObject* new_exception(pybind11::module_& m, const char* name, const char* doc, pybind11::tuple bases) {
  const std::string qualified = std::string("sdfkit.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw pybind11::error_already_set();
  m.add_object(name, pybind11::reinterpret_steal<pybind11::object>(type));
  return type;
}

}  // namespace

void register_errors(pybind11::module_& m) {
  namespace py = pybind11;
  g_error = new_exception(m, "Error", "Base class of every error raised by the sdfkit engine.",
                          py::make_tuple(py::handle(PyExc_Exception)));
  g_input_error = new_exception(
      m, "InputError",
      "Input that cannot be used: a missing or malformed file, an array of the wrong shape, NaN "
      "coordinates, an index out of range, an option out of range.",
      py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)));
  g_device_error = new_exception(
      m, "DeviceError",
      "A device or platform problem: no Vulkan/OpenCL device, no device matching the selector, a "
      "failed kernel build.",
      py::make_tuple(py::handle(g_error), py::handle(PyExc_RuntimeError)));

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(g_input_error, e.what());
    } catch (const DeviceError& e) {
      PyErr_SetString(g_device_error, e.what());
    } catch (const Error& e) {
      PyErr_SetString(g_error, e.what());
    }
  });
}

}  // namespace sdfkit::python
