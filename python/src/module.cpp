// The `sdfkit` Python module: the engine's pipeline (files in, fields out), a session object for
// repeated computes on numpy meshes, smoothing, comparison and device listing.

#include "arrays.hpp"
#include "errors.hpp"
#include "pointcloud.hpp"
#include "session.hpp"

#include "sdfkit/backends.hpp"
#include "sdfkit/core/error.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/pipeline.hpp"
#include "sdfkit/post/compare.hpp"
#include "sdfkit/post/smooth.hpp"
#ifdef SDFKIT_PYTHON_HAS_DIFFUSE
#include "sdfkit/diffusion/diffuse_mesh.hpp"
#endif

#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace py = pybind11;
using namespace pybind11::literals;

namespace sdfkit::python {
namespace {

// "vertex" | "face".
SdfDomain parse_domain(const std::string& per) {
  if (per == "vertex") return SdfDomain::Vertex;
  if (per == "face") return SdfDomain::Face;
  throw InputError("per must be \"vertex\" or \"face\", got \"" + per + "\"");
}

// "paper" | "cgal".
FalseHitRule parse_rule(const std::string& rule) {
  if (rule == "paper") return FalseHitRule::Paper;
  if (rule == "cgal") return FalseHitRule::Cgal;
  throw InputError("false_hits must be \"paper\" or \"cgal\", got \"" + rule + "\"");
}

SdfOptions make_options(const std::string& per, int rays, float cone, const std::string& false_hits) {
  SdfOptions o;
  o.domain = parse_domain(per);
  o.rays = rays;
  o.cone_degrees = cone;
  o.false_hit = parse_rule(false_hits);
  validate_options(o);
  return o;
}

BackendConfig make_config(const std::string& backend, const std::string& device, int views, int resolution,
                          std::size_t memory_cap) {
  BackendConfig c;
  c.kind = parse_backend_kind(backend);
  c.device = device;
  if (views < 0) throw InputError("views must be >= 0 (0 = the backend's default), got " + std::to_string(views));
  if (resolution < 0)
    throw InputError("resolution must be >= 0 (0 = the backend's default), got " + std::to_string(resolution));
  c.views = views;
  c.resolution = resolution;
  c.memory_cap = memory_cap;
  return c;
}

py::dict timings_to_dict(const std::vector<StageTiming>& stages) {
  py::dict d;
  for (const StageTiming& s : stages) d[py::str(s.stage)] = s.milliseconds;
  return d;
}

const char* kModuleDoc = R"doc(Shape Diameter Function (Shapira et al. 2008) on the GPU.

Quick start::

    import numpy as np, sdfkit
    mesh = sdfkit.load("bunny.obj")                  # sdfkit.Asset
    s = sdfkit.Session("opencl")                     # keeps device, kernels, geometry
    s.set_mesh(mesh.vertices, mesh.faces)            # (V,3) float, (F,3) int
    sdf = s.compute(rays=30, cone=120.0)             # (V,) float32, model units
    mesh.write("bunny_sdf.glb", sdf)                 # back into the input's own vertex order
    s.update_positions(mesh.vertices * 2.0)          # same topology, new positions
    sdf2 = s.compute()                               # == 2 * sdf

    report = sdfkit.compute_file("in.glb", "out.glb", rays=30, smooth=2)  # the CLI's JSON as a dict

Errors: sdfkit.InputError (a ValueError) for unusable input, sdfkit.DeviceError (a RuntimeError)
for device problems, both subclasses of sdfkit.Error.)doc";

void bind_asset(py::module_& m) {
  py::class_<io::Asset, std::shared_ptr<io::Asset>>(m, "Asset", R"doc(A loaded mesh file (see sdfkit.load).

The arrays are read-only views owned by the Asset:
  vertices        (V, 3) float32  welded positions: what the engine computes on
  faces           (F, 3) uint32   triangles as indices into `vertices`
  input_vertices  (N, 3) float32  every vertex of the file in file order (glTF: node transforms applied)
  input_faces     (F, 3) uint32   the same triangles as indices into `input_vertices`
  input_to_welded (N,)   uint32   input vertex -> welded vertex; per-vertex values for the file's
                                  own vertices are values[asset.input_to_welded]
Polygons are fan-triangulated; triangle order is the file's.)doc")
      .def_property_readonly("vertices", [](py::object self) {
        const auto& a = self.cast<const io::Asset&>();
        return readonly_view(reinterpret_cast<const float*>(a.mesh.positions.data()), a.mesh.positions.size(), 3, self);
      })
      .def_property_readonly("faces", [](py::object self) {
        const auto& a = self.cast<const io::Asset&>();
        return readonly_view(reinterpret_cast<const std::uint32_t*>(a.mesh.triangles.data()), a.mesh.triangles.size(), 3, self);
      })
      .def_property_readonly("input_vertices", [](py::object self) {
        const auto& a = self.cast<const io::Asset&>();
        return readonly_view(reinterpret_cast<const float*>(a.input_positions.data()), a.input_positions.size(), 3, self);
      })
      .def_property_readonly("input_faces", [](py::object self) {
        const auto& a = self.cast<const io::Asset&>();
        return readonly_view(reinterpret_cast<const std::uint32_t*>(a.input_triangles.data()), a.input_triangles.size(), 3, self);
      })
      .def_property_readonly("input_to_welded", [](py::object self) {
        const auto& a = self.cast<const io::Asset&>();
        return readonly_view(a.input_to_welded.data(), a.input_to_welded.size(), 0, self);
      })
      .def_readonly("path", &io::Asset::path)
      .def_property_readonly("format", [](const io::Asset& a) { return std::string(io::format_name(a.format)); })
      .def_readonly("warnings", &io::Asset::warnings, "Things skipped or changed while loading.")
      .def(
          "write",
          [](const io::Asset& a, const std::string& path, const py::handle& values, const std::string& per,
             bool color, bool normalize) {
            SdfField field;
            field.domain = parse_domain(per);
            field.values = to_values(values, "values");
            py::gil_scoped_release unlocked;
            io::WriteOptions options;
            options.color = color;
            options.normalized = normalize;
            io::write_field(path, a, field, options);
          },
          "path"_a, "values"_a, py::kw_only(), "per"_a = "vertex", "color"_a = true, "normalize"_a = false,
          R"doc(Writes a field computed on this asset's welded mesh, atomically; format by extension.

values: (V,) per welded vertex (per="vertex") or (F,) per face (per="face"), model units.
.gltf/.glb (per-vertex only): a glTF input is written back whole with _SDF, _SDF_NORMALIZED and
(color=True) COLOR_0 on every triangle primitive; other inputs get a fresh glTF.
.ply: `float quality` per vertex or face (normalize=True: [0, 1]), colours with color=True.
.txt: one value per line, in the file's vertex (or face) order.)doc")
      .def("__repr__", [](const io::Asset& a) {
        return "<sdfkit.Asset '" + a.path + "': " + std::to_string(a.input_positions.size()) + " vertices (" +
               std::to_string(a.mesh.positions.size()) + " welded), " + std::to_string(a.mesh.triangles.size()) +
               " faces>";
      });

  m.def(
      "load",
      [](const std::string& path, std::optional<float> weld_tolerance, bool allow_external_paths,
         std::uint64_t max_triangles, std::uint64_t max_file_size) {
        if (weld_tolerance && !(*weld_tolerance >= 0.0f))
          throw InputError("weld_tolerance must be >= 0, got " + std::to_string(*weld_tolerance));
        const io::LoadOptions options{weld_tolerance.value_or(io::LoadOptions::kDefaultWeld), allow_external_paths,
                                      max_triangles, max_file_size};
        py::gil_scoped_release unlocked;
        return std::make_shared<io::Asset>(load_input(path, options));
      },
      "path"_a, "weld_tolerance"_a = py::none(), py::kw_only(), "allow_external_paths"_a = false,
      "max_triangles"_a = io::kDefaultMaxTriangles, "max_file_size"_a = io::kDefaultMaxFileSize,
      R"doc(Loads a mesh file (.gltf .glb .obj .off .ply) or a built-in shape ("builtin:sphere",
"builtin:torus", "builtin:capsule", "builtin:slab", "builtin:tube") and returns an sdfkit.Asset.

Positions closer than weld_tolerance (model units; 0 = bitwise-equal only; None = 1e-6 of the
bounding box, which merges seam duplicates that differ by float rounding) are welded into one
vertex. Raises sdfkit.InputError "<path>: <problem>" for a missing or malformed file.

Assets are untrusted (SECURITY.md): a glTF's external buffers and images are read only from
inside its own directory unless allow_external_paths=True; an asset with more than
max_triangles triangles, or a file larger than max_file_size bytes, is refused before it is
read (0 = no limit).)doc");
}

void bind_session(py::module_& m) {
  py::class_<Session>(m, "Session", R"doc(A backend session: device context, compiled kernels and uploaded geometry
kept between calls, for computing the SDF of many meshes, or of one mesh whose vertices move.

Session(backend="auto", device="", views=0, resolution=0, memory_cap=0)
  backend     "auto" (a GPU backend on a GPU; without a GPU OpenCL, even when a CPU rasterizer
              such as lavapipe offers Vulkan; views/resolution narrow it to Vulkan, memory_cap
              to OpenCL), "vulkan" or "opencl"
  device      device index or name substring ("" = env SDFKIT_VK_DEVICE / SDFKIT_CL_DEVICE, else the best)
  views, resolution  Vulkan depth peeling: camera directions and framebuffer size (0 = defaults)
  memory_cap  OpenCL: device memory cap in bytes (0 = default)
Raises sdfkit.DeviceError when no device is usable. A session may be shared between threads;
calls on it run one at a time, with the GIL released while they compute.)doc")
      .def(py::init([](const std::string& backend, const std::string& device, int views, int resolution,
                       std::size_t memory_cap) {
             const BackendConfig config = make_config(backend, device, views, resolution, memory_cap);
             py::gil_scoped_release unlocked;
             return std::make_unique<Session>(config);
           }),
           "backend"_a = "auto", "device"_a = "", "views"_a = 0, "resolution"_a = 0, "memory_cap"_a = 0)
      .def_property_readonly("name", &Session::name, "The backend's name (\"opencl\", \"vulkan\").")
      .def_property_readonly("device", &Session::device, "The device's description.")
      .def_property_readonly("choice", &Session::choice,
                             "Why this backend runs: \"requested\", or the automatic choice's reason.")
      .def_property_readonly("vertex_count", &Session::vertex_count, "Vertices of the current mesh (0 = none).")
      .def_property_readonly("face_count", &Session::face_count, "Faces of the current mesh (0 = none).")
      .def_property_readonly(
          "last_timings", [](const Session& s) { return timings_to_dict(s.last_timings()); },
          "Milliseconds per stage of the last set_mesh, update_positions or compute call: the backend's own "
          "stages and \"total\", the wall time of the whole call.")
      .def_property_readonly(
          "last_kept_rays", [](const Session& s) { return to_numpy(s.last_kept_rays()); },
          "(N,) uint32: rays kept per point by the last compute(); 0 where the value was filled from neighbours.")
      .def(
          "set_mesh",
          [](Session& s, const py::handle& vertices, const py::handle& faces) {
            Mesh mesh = to_mesh(vertices, faces, "set_mesh");
            py::gil_scoped_release unlocked;
            s.set_mesh(std::move(mesh));
          },
          "vertices"_a, "faces"_a,
          R"doc(Uploads a mesh, replacing the previous one.

vertices: (V, 3) positions, any real or integer dtype (converted to float32), model units.
faces:    (F, 3) vertex indices (integers, or floats holding whole numbers), counter-clockwise
          seen from outside; faces wound otherwise are flipped for the computation (each piece
          coherent and outward, with a logged warning). Raises sdfkit.InputError for another shape, NaN/Inf coordinates,
          negative or out-of-range indices, or no faces.)doc")
      .def(
          "set_mesh",
          [](Session& s, const io::Asset& asset) {
            py::gil_scoped_release unlocked;
            s.set_mesh(asset.mesh);
          },
          "asset"_a, "Uploads the welded mesh of a loaded sdfkit.Asset.")
      .def(
          "update_positions",
          [](Session& s, const py::handle& vertices) {
            std::vector<glm::vec3> positions = to_positions(vertices, "vertices");
            py::gil_scoped_release unlocked;
            s.update_positions(std::move(positions));
          },
          "vertices"_a,
          "Moves the vertices of the current mesh: (V, 3) with the same V; the faces stay. Cheaper than set_mesh.")
      .def(
          "compute",
          [](Session& s, const std::string& per, int rays, float cone, const std::string& false_hits) {
            const SdfOptions options = make_options(per, rays, cone, false_hits);
            SdfField field;
            {
              py::gil_scoped_release unlocked;
              field = s.compute(options);
            }
            return to_numpy(std::move(field.values));
          },
          py::kw_only(), "per"_a = "vertex", "rays"_a = kDefaultRays, "cone"_a = kDefaultConeDegrees,
          "false_hits"_a = "paper",
          R"doc(The SDF of the current mesh: a (V,) (per="vertex") or (F,) (per="face") float32 array in
model units, finite everywhere (points without an accepted ray are filled from their neighbours,
or with the mean where none has a value; see last_kept_rays).

rays        rays per point (>= 1; ray casting: OpenCL. On a Vulkan session a value other than the
            default is refused with InputError: its samples are its cameras, set by views)
cone        full cone aperture in degrees, (0, 180]
false_hits  "paper": drop hits whose normal faces the start normal; "cgal": keep only hits where
            the ray leaves the solid)doc")
      .def("__repr__", [](const Session& s) {
        return "<sdfkit.Session " + s.name() + " on " + s.device() + ">";
      });
}

void bind_functions(py::module_& m) {
  m.def(
      "compute_file",
      [](const std::string& input, const std::optional<std::string>& output, Session* session,
         const std::string& backend, const std::string& device, int views, int resolution, std::size_t memory_cap,
         const std::string& per, int rays, float cone, const std::string& false_hits, int smooth, bool normalize,
         bool color, std::optional<float> weld_tolerance, bool allow_external_paths, std::uint64_t max_triangles,
         std::uint64_t max_file_size) {
        ComputeRequest request;
        request.input = input;
        request.output = output.value_or("");
        request.sdf = make_options(per, rays, cone, false_hits);
        if (smooth < 0) throw InputError("smooth must be >= 0 rings (0 = off), got " + std::to_string(smooth));
        request.smooth_rings = smooth;
        request.write.color = color;
        request.write.normalized = normalize;
        if (weld_tolerance && !(*weld_tolerance >= 0.0f))
          throw InputError("weld_tolerance must be >= 0, got " + std::to_string(*weld_tolerance));
        request.load.weld_tolerance = weld_tolerance.value_or(io::LoadOptions::kDefaultWeld);
        request.load.allow_external_paths = allow_external_paths;
        request.load.max_triangles = max_triangles;
        request.load.max_file_size = max_file_size;
        request.backend = make_config(backend, device, views, resolution, memory_cap);
        if (session && (request.backend.kind != BackendKind::Auto || !device.empty() || views || resolution || memory_cap))
          throw InputError("compute_file: pass either session or backend options (backend, device, views, "
                           "resolution, memory_cap), not both");
        ComputeReport report;
        {
          py::gil_scoped_release unlocked;
          if (session) {
            report = session->with_session([&](sdfkit::Session& s) { return run_compute(request, s); });
          } else {
            report = run_compute(request);  // the session opens after the input loaded
          }
        }
        return py::dict(py::module_::import("json").attr("loads")(report_to_json(report)));
      },
      "input"_a, "output"_a = py::none(), py::kw_only(), "session"_a = nullptr, "backend"_a = "auto",
      "device"_a = "", "views"_a = 0, "resolution"_a = 0, "memory_cap"_a = 0, "per"_a = "vertex",
      "rays"_a = kDefaultRays, "cone"_a = kDefaultConeDegrees, "false_hits"_a = "paper", "smooth"_a = 0,
      "normalize"_a = false, "color"_a = true, "weld_tolerance"_a = py::none(),
      "allow_external_paths"_a = false, "max_triangles"_a = io::kDefaultMaxTriangles,
      "max_file_size"_a = io::kDefaultMaxFileSize,
      R"doc(What `sdfkit compute INPUT -o OUTPUT` does: load, compute, optionally smooth, write
atomically. Returns the JSON report (`sdfkit compute --json`) as a dict: input, output, ok,
counts {input_vertices, input_faces, welded_vertices, points, filled_points}, backend, device,
backend_choice (why that backend), options (every option of the run),
time_ms {stage: ms}, total_ms, summary {min, median, mean, max}, warnings.

input   mesh file or "builtin:NAME"; output: .glb/.gltf/.ply/.txt, or None to write nothing
session an sdfkit.Session to reuse (its mesh is replaced), else a backend is opened from
        backend/device/views/resolution/memory_cap (only after the input loaded)
per, rays, cone, false_hits  as in Session.compute
smooth  k-ring Gaussian smoothing (rings, 0 = off); normalize: write [0, 1] values to .txt/.ply
color   write colours (glTF COLOR_0, PLY rgb); weld_tolerance, allow_external_paths,
        max_triangles, max_file_size: as in sdfkit.load)doc");

  m.def(
      "smooth",
      [](const py::handle& vertices, const py::handle& faces, const py::handle& values, int rings,
         const std::string& per, float sigma) {
        const Mesh mesh = to_mesh(vertices, faces, "smooth");
        const SdfDomain domain = parse_domain(per);
        const std::vector<float> v = to_values(values, "values");
        const std::size_t expected = domain == SdfDomain::Vertex ? mesh.positions.size() : mesh.triangles.size();
        if (v.size() != expected)
          throw InputError("smooth: " + std::to_string(v.size()) + " values for " + std::to_string(expected) +
                           (domain == SdfDomain::Vertex ? " vertices" : " faces"));
        if (!(sigma >= 0.0f)) throw InputError("smooth: sigma must be >= 0, got " + std::to_string(sigma));
        SmoothOptions options;
        options.rings = rings;
        options.sigma = sigma;
        std::vector<float> out;
        {
          py::gil_scoped_release unlocked;
          out = smooth_field(mesh, domain, v, options);
        }
        return to_numpy(std::move(out));
      },
      "vertices"_a, "faces"_a, "values"_a, py::kw_only(), "rings"_a = 2, "per"_a = "vertex", "sigma"_a = 0.0f,
      R"doc(k-ring Gaussian smoothing of a per-vertex (per="vertex", (V,)) or per-face ((F,)) field:
each point becomes the mean of the points up to `rings` edges away, weighted by
exp(-d^2 / (2 sigma^2)); sigma = rings * mean edge length / 2 when 0. Returns float32.)doc");

#ifdef SDFKIT_PYTHON_HAS_DIFFUSE
  // Issue 13: texture-space diffusion through a skeleton texture mapping.
  m.def(
      "diffuse",
      [](const py::handle& vertices, const py::handle& faces, const py::handle& values, float radius, float sigma,
         std::uint32_t steps, bool stretch, bool conserve, std::uint32_t atlas_size, const std::string& device) {
        const Mesh mesh = to_mesh(vertices, faces, "diffuse");
        const std::vector<float> v = to_values(values, "values");
        diffusion::TextureSmoothOptions options;
        options.diffuse.radius_px = radius;
        options.diffuse.sigma = sigma;
        options.diffuse.steps = steps;
        options.diffuse.stretch = stretch;
        options.diffuse.conserve = conserve;
        options.stm.atlas_size = atlas_size;
        options.device = device;
        std::vector<float> out;
        {
          py::gil_scoped_release unlocked;
          out = diffusion::smooth_texture_space(mesh, v, options).values;
        }
        return to_numpy(std::move(out));
      },
      "vertices"_a, "faces"_a, "values"_a, py::kw_only(), "radius"_a = 0.0f, "sigma"_a = 0.0f, "steps"_a = 0u,
      "stretch"_a = true, "conserve"_a = true, "atlas_size"_a = 2048u, "device"_a = "",
      R"doc(Texture-space diffusion of a per-vertex field (V,) (the paper's section 4.1): the mesh's
skeleton (from its geometry), a skeleton texture mapping into an atlas_size^2 atlas, and a
Gaussian blur there on a Vulkan device, read back per vertex. Exactly one of radius (the
Gaussian's sigma in atlas texels) and sigma (model units) > 0. steps: the blur as that many
successive blurs of width / sqrt(steps), each from the values the last read back, so the kernel
carries on across chart borders (0: as many as the mapping's reach needs; 1: one blur, the
paper's; at most 256). stretch (with sigma): each texel's blur width follows the map's local
stretch (False: one width per chart, its mean scale). conserve: the result keeps the field's
integral over each connected piece and its range there, as heat flow does (False: the blur's own
read-back). Returns float32.)doc");
#endif

  m.def(
      "compare",
      [](const py::handle& a, const py::handle& b) {
        const std::vector<float> va = to_values(a, "a"), vb = to_values(b, "b");
        if (va.size() != vb.size())
          throw InputError("compare: a has " + std::to_string(va.size()) + " values, b has " +
                           std::to_string(vb.size()));
        if (va.empty()) throw InputError("compare: no values");
        const FieldComparison c = compare_fields(va, vb);
        return py::dict("points"_a = c.points, "pearson"_a = c.pearson, "median_relative"_a = c.median_relative,
                        "p95_relative"_a = c.p95_relative, "max_relative"_a = c.max_relative,
                        "median_signed_relative"_a = c.median_signed_relative, "median_signed"_a = c.median_signed);
      },
      "a"_a, "b"_a,
      R"doc(Compares field a with reference b (same length): {points, pearson, median_relative,
p95_relative, max_relative (of |a - b| / |b|, points with b == 0 skipped), median_signed_relative,
median_signed (model units)}.)doc");

  m.def(
      "devices",
      [] {
        std::vector<DeviceListing> listing;
        {
          py::gil_scoped_release unlocked;
          listing = list_all_devices();
        }
        py::list out;
        for (const DeviceListing& d : listing)
          out.append(py::dict("backend"_a = d.backend, "description"_a = d.description, "usable"_a = d.usable,
                              "reason"_a = d.reason, "gpu"_a = d.gpu));
        return out;
      },
      "Every device of every built backend: [{backend, description, usable, reason, gpu}] (`sdfkit devices`).");

  m.def(
      "backends",
      [] {
        std::vector<std::string> out;
        for (BackendKind k : built_backends()) out.emplace_back(to_string(k));
        return out;
      },
      "The backends this build contains, e.g. [\"vulkan\", \"opencl\"].");
}

}  // namespace
}  // namespace sdfkit::python

PYBIND11_MODULE(sdfkit, m) {
  m.doc() = sdfkit::python::kModuleDoc;
  m.attr("__version__") = SDFKIT_VERSION;
  sdfkit::python::register_errors(m);
  sdfkit::python::bind_asset(m);
  sdfkit::python::bind_session(m);
  sdfkit::python::bind_functions(m);
  sdfkit::python::bind_pointcloud(m);
}
