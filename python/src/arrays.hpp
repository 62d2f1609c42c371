#pragma once
// NumPy arrays in and out of the engine's types. Input arrays may have any integer or floating
// dtype numpy can cast; shapes are checked here and every problem is an sdfkit::InputError
// (Python: sdfkit.InputError, a ValueError) naming the argument, or a TypeError for a dtype that
// is not numeric at all.

#include "sdfkit/core/mesh.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace sdfkit::python {

namespace py = pybind11;

// (V, 3) positions as float32 (model units). `what` names the argument in messages.
std::vector<glm::vec3> to_positions(const py::handle& array, const char* what);

// (F, 3) vertex indices as uint32. Integer dtypes, or floats holding whole numbers. Negative or
// larger-than-uint32 indices are rejected here; indices >= V by validate_mesh.
std::vector<Triangle> to_triangles(const py::handle& array, const char* what);

// A 1-D array of float32 values; non-finite values are rejected.
std::vector<float> to_values(const py::handle& array, const char* what);

// A mesh from (V, 3) vertices and (F, 3) faces, checked by validate_mesh (indices in range,
// finite coordinates, at least one triangle), each piece wound outward (orient_outward, with a
// logged warning when faces were flipped).
Mesh to_mesh(const py::handle& vertices, const py::handle& faces, const char* what);

// Moves a vector into a 1-D numpy array that owns it (no copy).
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& values) {
  auto owned = std::make_unique<std::vector<T>>(std::move(values));
  const auto size = static_cast<py::ssize_t>(owned->size());
  T* data = owned->data();
  py::capsule owner(owned.get(), [](void* p) { delete static_cast<std::vector<T>*>(p); });
  owned.release();
  return py::array_t<T>({size}, {static_cast<py::ssize_t>(sizeof(T))}, data, owner);
}

// A read-only (rows, columns) view of `data`, kept alive by `base` (the object that owns the
// memory). columns == 0 gives a 1-D view of `rows` elements.
template <class T>
py::array_t<T> readonly_view(const T* data, std::size_t rows, std::size_t columns, py::handle base) {
  py::array_t<T> out;
  if (columns == 0) {
    out = py::array_t<T>({static_cast<py::ssize_t>(rows)}, {static_cast<py::ssize_t>(sizeof(T))}, data, base);
  } else {
    out = py::array_t<T>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(columns)},
                         {static_cast<py::ssize_t>(columns * sizeof(T)), static_cast<py::ssize_t>(sizeof(T))},
                         data, base);
  }
  out.attr("setflags")(py::arg("write") = false);
  return out;
}

}  // namespace sdfkit::python
