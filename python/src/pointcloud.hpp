#pragma once
// sdfkit.pointcloud_skeleton, sdfkit.compress_animation and sdfkit.synthetic_worm (issue 14).
#include <pybind11/pybind11.h>

namespace sdfkit::python {
void bind_pointcloud(pybind11::module_& m);
}
