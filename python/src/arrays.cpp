#include "arrays.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/core/orient.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace sdfkit::python {
namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// np.asarray(obj), checked to hold numbers (bool, integer or floating dtype).
py::array as_numeric_array(const py::handle& obj, const char* what, const char* expected) {
  py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error(std::string(what) + " must be an array of " + expected);
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u' && kind != 'f')
    throw py::type_error(std::string(what) + " must be an array of " + expected + ", got dtype " +
                         py::str(a.dtype()).cast<std::string>());
  return a;
}

void require_rows_of_three(const py::array& a, const char* what, const char* expected) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InputError(std::string(what) + " must have shape " + expected + ", got " + shape_text(a));
}

}  // namespace

std::vector<glm::vec3> to_positions(const py::handle& array, const char* what) {
  const py::array any = as_numeric_array(array, what, "numbers of shape (V, 3)");
  require_rows_of_three(any, what, "(V, 3)");
  using F32 = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const F32 a = F32::ensure(any);
  if (!a) throw py::error_already_set();
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  std::vector<glm::vec3> out(static_cast<std::size_t>(a.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
  return out;
}

std::vector<Triangle> to_triangles(const py::handle& array, const char* what) {
  const py::array any = as_numeric_array(array, what, "integer vertex indices of shape (F, 3)");
  require_rows_of_three(any, what, "(F, 3)");
  const bool floating = any.dtype().kind() == 'f';
  using I64 = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
  using F64 = py::array_t<double, py::array::c_style | py::array::forcecast>;
  const std::size_t rows = static_cast<std::size_t>(any.shape(0));
  std::vector<Triangle> out(rows);
  // Checks one index (read as a double: exact for integers up to 2^53, far above the limit).
  auto store = [&](std::size_t i, double index) {
    const std::size_t row = i / 3, column = i % 3;
    const std::string where = std::string(what) + "[" + std::to_string(row) + ", " + std::to_string(column) + "]";
    if (!(index == std::floor(index)))  // also rejects NaN and Inf
      throw InputError(where + " is not a whole number (" + std::to_string(index) + ")");
    if (index < 0)
      throw InputError(where + " is a negative vertex index (" + std::to_string(static_cast<long long>(index)) + ")");
    if (index > static_cast<double>(std::numeric_limits<std::uint32_t>::max()))
      throw InputError(where + " is too large for a 32-bit vertex index");
    out[row][column] = static_cast<std::uint32_t>(index);
  };
  if (floating) {
    const F64 a = F64::ensure(any);
    if (!a) throw py::error_already_set();
    for (std::size_t i = 0; i < rows * 3; ++i) store(i, a.data()[i]);
  } else {
    const I64 a = I64::ensure(any);
    if (!a) throw py::error_already_set();
    for (std::size_t i = 0; i < rows * 3; ++i) store(i, static_cast<double>(a.data()[i]));
  }
  return out;
}

std::vector<float> to_values(const py::handle& array, const char* what) {
  const py::array any = as_numeric_array(array, what, "numbers of shape (N,)");
  if (any.ndim() != 1) throw InputError(std::string(what) + " must be one-dimensional, got shape " + shape_text(any));
  using F32 = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const F32 a = F32::ensure(any);
  if (!a) throw py::error_already_set();
  std::vector<float> out(a.data(), a.data() + a.shape(0));
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      throw InputError(std::string(what) + "[" + std::to_string(i) + "] is not finite (NaN or Inf)");
  return out;
}

Mesh to_mesh(const py::handle& vertices, const py::handle& faces, const char* what) {
  Mesh mesh;
  mesh.positions = to_positions(vertices, "vertices");
  mesh.triangles = to_triangles(faces, "faces");
  validate_mesh(mesh, what);
  // As a loaded file's mesh is (load_asset): the SDF needs every piece wound outward.
  if (const std::string w = orient_outward(mesh).summary(); !w.empty()) log_warning(std::string(what) + ": " + w);
  return mesh;
}

}  // namespace sdfkit::python
