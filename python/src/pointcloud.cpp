// Point-cloud skeletons and skinning compression on numpy arrays (issue 14).

#include "pointcloud.hpp"

#include "arrays.hpp"

#include "sdfkit/backends.hpp"
#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"
#include "sdfkit/pointcloud/skinning.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

namespace py = pybind11;
using namespace pybind11::literals;

namespace sdfkit::python {
namespace {

std::unique_ptr<SdfBackend> backend_for(const std::string& backend, const std::string& device) {
  BackendConfig c;
  c.kind = parse_backend_kind(backend);
  c.device = device;
  return make_backend(c);
}

py::array_t<float> rows(const std::vector<glm::vec3>& v) {
  py::array_t<float> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) m(static_cast<py::ssize_t>(i), d) = v[i][d];
  return a;
}

py::dict polyline_dict(const pointcloud::Polyline& line) {
  std::vector<glm::vec3> pos;
  std::vector<float> radius;
  for (const auto& n : line.nodes) {
    pos.push_back(n.position);
    radius.push_back(n.radius);
  }
  return py::dict("nodes"_a = rows(pos), "radius"_a = to_numpy(std::move(radius)));
}

pointcloud::Linkage parse_linkage(const std::string& s) {
  if (s == "average") return pointcloud::Linkage::Average;
  if (s == "single") return pointcloud::Linkage::Single;
  throw InputError("linkage must be \"average\" or \"single\", got \"" + s + "\"");
}

// (F, V, 3) frames.
std::vector<std::vector<glm::vec3>> to_frames(const py::handle& array) {
  auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a) throw py::type_error("frames must be a numeric array of shape (F, V, 3)");
  if (a.ndim() != 3 || a.shape(2) != 3) throw InputError("frames must have shape (F, V, 3)");
  std::vector<std::vector<glm::vec3>> out(static_cast<std::size_t>(a.shape(0)));
  auto r = a.unchecked<3>();
  for (py::ssize_t f = 0; f < a.shape(0); ++f) {
    out[static_cast<std::size_t>(f)].resize(static_cast<std::size_t>(a.shape(1)));
    for (py::ssize_t i = 0; i < a.shape(1); ++i) {
      const glm::vec3 p(r(f, i, 0), r(f, i, 1), r(f, i, 2));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw InputError("frames: a coordinate is not finite");
      out[static_cast<std::size_t>(f)][static_cast<std::size_t>(i)] = p;
    }
  }
  return out;
}

}  // namespace

void bind_pointcloud(py::module_& m) {
  m.def(
      "pointcloud_skeleton",
      [](const py::handle& points, int segments, float threshold, int nodes, int neighbours, int up_axis,
         const std::string& linkage, int rays, const std::string& backend, const std::string& device) {
        const std::vector<glm::vec3> pts = to_positions(points, "points");
        pointcloud::SkeletonOptions o;
        o.segments = segments;
        o.threshold = threshold;
        o.neighbours = neighbours;
        o.up_axis = up_axis;
        o.linkage = parse_linkage(linkage);
        o.sdf.rays = rays;
        if (segments > 0 && threshold > 0.0f) throw InputError("segments and threshold exclude each other");
        pointcloud::validate_options(o);
        pointcloud::SkeletonResult r;
        {
          py::gil_scoped_release release;
          auto b = backend_for(backend, device);
          r = pointcloud::point_cloud_skeleton(pts, *b, o);
        }
        py::dict d = polyline_dict(r.polyline);
        d["normals"] = rows(r.normals);
        d["sdf"] = to_numpy(std::vector<float>(r.sdf));
        d["shifted"] = rows(r.shifted);
        d["threshold"] = r.threshold;
        d["exact"] = r.exact;
        d["ambiguous"] = to_numpy(std::vector<std::uint32_t>(r.ambiguous));
        py::dict times;
        for (const auto& t : r.times) times[py::str(t.step)] = t.milliseconds;
        d["milliseconds"] = times;
        if (nodes > 0) d["subdivided"] = polyline_dict(pointcloud::resample(r.polyline, nodes));
        return d;
      },
      "points"_a, "segments"_a = 0, "threshold"_a = 0.0f, "nodes"_a = 0, "neighbours"_a = pointcloud::kDefaultNeighbours,
      "up_axis"_a = 1, "linkage"_a = "average", "rays"_a = pointcloud::SkeletonOptions{}.sdf.rays, "backend"_a = "auto",
      "device"_a = "",
      "The linear skeleton of an unoriented (N, 3) point cloud: a dict with 'nodes' (M, 3) ordered end to end, "
      "'radius' (M,), the oriented 'normals', per-point 'sdf' and 'shifted' points, 'threshold', 'exact' (segments "
      "found exactly), 'ambiguous' normals, per-step 'milliseconds', and 'subdivided' when nodes > 0.");
  m.def(
      "compress_animation",
      [](const py::handle& frames, const std::string& output, int bones, double frame_time, const py::object& skeleton_points,
         const std::string& rotation, const std::string& backend, const std::string& device) {
        const auto all = to_frames(frames);
        std::vector<std::vector<glm::vec3>> skel = all;
        if (!skeleton_points.is_none()) {
          const auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(skeleton_points);
          if (!idx || idx.ndim() != 1) throw InputError("skeleton_points must be a 1-D array of point indices");
          for (std::size_t f = 0; f < all.size(); ++f) {
            skel[f].clear();
            for (py::ssize_t k = 0; k < idx.shape(0); ++k) {
              const std::int64_t i = idx.at(k);
              if (i < 0 || static_cast<std::size_t>(i) >= all[f].size()) throw InputError("skeleton_points: index out of range");
              skel[f].push_back(all[f][static_cast<std::size_t>(i)]);
            }
          }
        }
        if (rotation != "procrustes" && rotation != "polyline")
          throw InputError("rotation must be \"procrustes\" or \"polyline\"");
        pointcloud::CompressionOptions o;
        o.bones = bones;
        o.frame_time = frame_time;
        o.rotation = rotation == "polyline" ? pointcloud::CompressionOptions::Rotation::Polyline
                                            : pointcloud::CompressionOptions::Rotation::Procrustes;
        pointcloud::CompressionReport r;
        {
          py::gil_scoped_release release;
          auto b = backend_for(backend, device);
          const pointcloud::Compression c = pointcloud::compress_animation(all, skel, *b, o);
          const std::size_t bytes = pointcloud::write_skinned_glb(c.animation, output);
          double length = 0.0;
          for (const auto& l : c.bones_per_frame) length += l.length();
          length /= static_cast<double>(c.bones_per_frame.size());
          r = pointcloud::measure_compression(all, pointcloud::play_skinned_glb(output), bytes, c.animation.bone_count(), length);
        }
        return py::dict("frames"_a = r.frames, "points"_a = r.points, "bones"_a = r.bones, "raw_bytes"_a = r.raw_bytes,
                        "compressed_bytes"_a = r.compressed_bytes, "compression_ratio"_a = r.ratio,
                        "body_length"_a = r.body_length, "rmse"_a = r.rmse, "max_error"_a = r.max_error,
                        "rmse_percent_of_length"_a = r.rmse_percent, "max_error_percent_of_length"_a = r.max_percent,
                        "kg_error"_a = r.kg_error);
      },
      "frames"_a, "output"_a, "bones"_a = 16, "frame_time"_a, "skeleton_points"_a = py::none(), "rotation"_a = "procrustes",
      "backend"_a = "auto", "device"_a = "",
      "Compresses (F, V, 3) frames (the same points in every frame) into a skinned, animated .glb at `output`; "
      "returns the report measured by playing the file back (sizes, ratio, RMSE, max and KG error).");
  m.def(
      "play_skinned_glb", [](const std::string& path) {
        const auto frames = pointcloud::play_skinned_glb(path);
        py::array_t<float> a({static_cast<py::ssize_t>(frames.size()), static_cast<py::ssize_t>(frames.empty() ? 0 : frames[0].size()), py::ssize_t{3}});
        auto w = a.mutable_unchecked<3>();
        for (std::size_t f = 0; f < frames.size(); ++f)
          for (std::size_t i = 0; i < frames[f].size(); ++i)
            for (int d = 0; d < 3; ++d) w(static_cast<py::ssize_t>(f), static_cast<py::ssize_t>(i), d) = frames[f][i][d];
        return a;
      },
      "path"_a, "Plays a skinned .glb back as a viewer does: (keyframes, V, 3) positions.");
  m.def(
      "synthetic_worm",
      [](float length, float radius, float amplitude, float waves, float phase, float noise, std::size_t points, std::uint32_t seed) {
        pointcloud::WormShape s{length, radius, amplitude, waves, phase, noise, points, seed};
        const pointcloud::SyntheticWorm w = pointcloud::synthetic_worm(s);
        std::vector<glm::vec3> mid;
        for (const auto& n : w.midline.nodes) mid.push_back(n.position);
        return py::make_tuple(rows(w.points), rows(mid));
      },
      "length"_a = 150.0f, "radius"_a = 5.0f, "amplitude"_a = 20.0f, "waves"_a = 1.0f, "phase"_a = 0.0f, "noise"_a = 0.05f,
      "points"_a = 2000, "seed"_a = 1,
      "A synthetic worm: (points (N, 3), exact midline (201, 3)) of a closed tube of varying radius along a sine wave.");
}

}  // namespace sdfkit::python
