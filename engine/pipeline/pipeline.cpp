#include "sdfkit/pipeline.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/orient.hpp"
#include "sdfkit/core/weld.hpp"
#include "sdfkit/io/solids.hpp"
#include "sdfkit/post/smooth.hpp"
#ifdef SDFKIT_HAS_VULKAN
#include "sdfkit/diffusion/diffuse_mesh.hpp"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

namespace sdfkit {
namespace {

class Stopwatch {
public:
  double lap_ms() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// The field of an asset of several solids (io/solids.hpp), on asset.mesh: each group's
// representative solid welded on its own and computed on `session`, the other solids of the
// group take its values times their scale. Where solids weld together in asset.mesh, the
// later solid's value is kept. The backend's stage timings are summed into `stages`.
SdfField compute_solids(Session& session, const io::Asset& asset, const io::SolidPlan& plan,
                        const SdfOptions& options, std::vector<StageTiming>& stages) {
  const bool per_vertex = options.domain == SdfDomain::Vertex;
  const std::size_t n_in = per_vertex ? asset.input_positions.size() : asset.input_triangles.size();
  std::vector<float> values(n_in, 0.0f);
  std::vector<std::uint32_t> kept(n_in, 0u);
  std::vector<std::uint8_t> filled(n_in, 0u);
  // Input vertex or triangle indices of a solid, in its own order.
  const auto points_of = [&](const io::Solid& s) {
    std::vector<std::uint32_t> out;
    for (const auto& [first, count] : per_vertex ? s.vertex_ranges : s.triangle_ranges)
      for (std::uint32_t k = 0; k < count; ++k) out.push_back(first + k);
    return out;
  };
  for (std::size_t g = 0; g < plan.representatives.size(); ++g) {
    const io::Solid& rep = plan.solids[plan.representatives[g]];
    std::vector<glm::vec3> positions;
    std::vector<Triangle> triangles;
    for (std::size_t r = 0; r < rep.vertex_ranges.size(); ++r) {
      const auto [vfirst, vcount] = rep.vertex_ranges[r];
      const auto [tfirst, tcount] = rep.triangle_ranges[r];
      const auto base = static_cast<std::uint32_t>(positions.size());
      positions.insert(positions.end(), asset.input_positions.begin() + vfirst,
                       asset.input_positions.begin() + vfirst + vcount);
      for (std::uint32_t t = tfirst; t < tfirst + tcount; ++t) {
        const Triangle& in = asset.input_triangles[t];
        triangles.push_back(Triangle{in[0] - vfirst + base, in[1] - vfirst + base, in[2] - vfirst + base});
      }
    }
    WeldResult welded = weld(positions, triangles, asset.weld_tolerance);
    orient_outward(welded.mesh);  // as load_asset did to the whole mesh (its warning said so)
    session.set_mesh(std::move(welded.mesh));
    const SdfField f = session.compute(options);
    accumulate_stages(stages, session.backend().last_timings());
    const std::vector<std::uint32_t> rep_points = points_of(rep);
    for (const io::Solid& s : plan.solids) {
      if (s.group != static_cast<int>(g)) continue;
      const std::vector<std::uint32_t> points = points_of(s);
      if (points.size() != rep_points.size()) throw Error(asset.path + ": instances of one mesh differ in size");
      for (std::size_t k = 0; k < points.size(); ++k) {
        const std::uint32_t from = per_vertex ? welded.input_to_welded[k] : static_cast<std::uint32_t>(k);
        values[points[k]] = static_cast<float>(s.scale * static_cast<double>(f.values[from]));
        kept[points[k]] = f.kept_rays.empty() ? 0u : f.kept_rays[from];
        filled[points[k]] = f.filled.empty() ? 0u : f.filled[from];
      }
    }
  }
  SdfField out;
  out.domain = options.domain;
  if (!per_vertex) {
    out.values = std::move(values);
    out.kept_rays = std::move(kept);
    out.filled = std::move(filled);
  } else {
    const std::size_t n = asset.mesh.positions.size();
    out.values.assign(n, 0.0f);
    out.kept_rays.assign(n, 0u);
    out.filled.assign(n, 0u);
    for (std::size_t v = 0; v < n_in; ++v) {
      const std::uint32_t w = asset.input_to_welded[v];
      out.values[w] = values[v];
      out.kept_rays[w] = kept[v];
      out.filled[w] = filled[v];
    }
  }
  out.filled_count = static_cast<std::size_t>(std::count(out.filled.begin(), out.filled.end(), std::uint8_t{1}));
  return out;
}

}  // namespace

std::string builtin_names() { return "sphere, torus, capsule, slab, tube (the paper's Figure 7 model)"; }

io::Asset load_input(const std::string& path, const io::LoadOptions& options) {
  static const std::string prefix = "builtin:";
  if (path.rfind(prefix, 0) != 0) return io::load_asset(path, options);
  const std::string name = path.substr(prefix.size());
  Mesh mesh;
  if (name == "sphere") mesh = shapes::icosphere(1.0f, 4);
  else if (name == "torus") mesh = shapes::torus(2.0f, 0.6f, 96, 48);
  else if (name == "capsule") mesh = shapes::capsule(0.5f, 3.0f, 64, 24);
  else if (name == "slab") mesh = shapes::box(10.0f, 10.0f, 1.0f, 20);
  else if (name == "tube") mesh = shapes::swept_tube().mesh;
  else throw InputError(path + ": unknown built-in shape (available: " + builtin_names() + ")");
  io::Asset asset;
  asset.path = path;
  asset.format = io::Format::Off;
  asset.input_positions = mesh.positions;
  asset.input_triangles = mesh.triangles;
  asset.weld_tolerance = io::weld_tolerance_for(options, mesh.positions);
  WeldResult welded = weld(mesh.positions, mesh.triangles, asset.weld_tolerance);
  asset.mesh = std::move(welded.mesh);  // built outward: nothing for orient_outward to do
  asset.input_to_welded = std::move(welded.input_to_welded);
  return asset;
}

FieldSummary summarize(std::span<const float> values) {
  FieldSummary s;
  if (values.empty()) return s;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  s.min = *lo;
  s.max = *hi;
  double sum = 0.0;
  for (float v : values) sum += v;
  s.mean = static_cast<float>(sum / static_cast<double>(values.size()));
  s.median = median_of(values);
  return s;
}

void validate(const ComputeRequest& r) {
  validate_options(r.sdf);
  if (r.smooth_rings < 0 || r.smooth_rings > 64)
    throw UsageError("--smooth must be between 0 and 64 rings, got " + std::to_string(r.smooth_rings));
  if (!(r.smooth_texture_px >= 0.0f) || !std::isfinite(r.smooth_texture_px) || r.smooth_texture_px > 1024.0f)
    throw UsageError("--smooth-texture must be a radius between 0 and 1024 texels");
  if (r.smooth_texture_px > 0.0f) {
#ifndef SDFKIT_HAS_VULKAN
    throw UsageError("--smooth-texture needs the Vulkan engine (this build has none)");
#endif
    if (r.smooth_rings > 0) throw UsageError("--smooth (k-ring) and --smooth-texture exclude each other");
    if (r.sdf.domain == SdfDomain::Face) throw UsageError("--smooth-texture needs per-vertex values (--per vertex)");
  }
  // io::LoadOptions::kDefaultWeld stands for the default tolerance (1e-6 of the bounding box).
  if (r.load.weld_tolerance != io::LoadOptions::kDefaultWeld &&
      (!(r.load.weld_tolerance >= 0.0f) || !std::isfinite(r.load.weld_tolerance)))
    throw UsageError("--weld-tolerance must be a finite number >= 0");
  check_backend_options(r.backend.kind, r.backend, r.sdf);
}

namespace {

// Where welding merged nothing, the input vertices and triangles equal the welded mesh's.
bool weld_is_identity(const io::Asset& a) {
  if (a.input_to_welded.size() != a.mesh.positions.size() || a.input_triangles.size() != a.mesh.triangles.size())
    return false;
  for (std::uint32_t v = 0; v < a.input_to_welded.size(); ++v)
    if (a.input_to_welded[v] != v) return false;
  return a.input_positions == a.mesh.positions && a.input_triangles == a.mesh.triangles;
}

// Validates, checks the output, and loads unless `preloaded`. The asset's mesh moves into the
// session (one copy, shared with the backend, which keeps it: Python's compute_file leaves the
// session holding the file's mesh). `lean`: the caller only writes the result (run_compute),
// so the asset does not get a copy of the mesh back (write_field takes the session's) and, as a
// PLY or txt output needs no input copy where welding merged nothing, drops that copy before
// the computation. At 13M triangles each copy is 230 MB at the peak. `own_session`: the session
// is this call's alone and goes with it (one-shot run_compute), so nothing will move its
// vertices: the backend drops what only update_positions needs (release_mesh; the OpenCL BVH's
// host triangle order, 51 MiB at 13M triangles) before the computation.
ComputeResult compute_impl(const ComputeRequest& request, io::Asset* preloaded, const SessionProvider& provider,
                           bool lean = false, bool own_session = false) {
  validate(request);
  ComputeResult out;
  ComputeReport& report = out.report;
  report.input = request.input;
  report.output = request.output;
  report.options = options_to_json(request);
  Stopwatch clock;

  // Fail on an unwritable output before spending the compute time.
  if (!request.output.empty()) io::check_output(request.output, request.sdf.domain);

  out.asset = preloaded ? std::move(*preloaded) : load_input(request.input, request.load);
  const io::Asset& asset = out.asset;
  report.stages.push_back({"load", clock.lap_ms()});
  for (StageTiming s : asset.load_stages) {
    s.nested = true;
    report.stages.push_back(s);
  }
  const auto sample = [&](const char* stage) { report.memory.push_back({stage, resident_memory()}); };
  sample("weld");
  report.input_vertices = asset.input_positions.size();
  report.input_faces = asset.input_triangles.size();
  report.welded_vertices = asset.mesh.positions.size();
  report.warnings = asset.warnings;

  Session& session = provider();
  report.backend = session.backend().name();
  report.device = session.backend().device_name();
  report.backend_choice = session.choice().reason;
  report.stages.push_back({"device", clock.lap_ms()});
  sample("device");
  const io::SolidPlan solids = io::plan_solids(asset);
  report.solids = solids.solids.size();
  report.sdf_computations = solids.representatives.size();
  double set_mesh_ms = 0, compute_ms = 0;
  const Mesh* mesh = &asset.mesh;  // the session's where the asset lent it
  std::vector<StageTiming> backend_stages;
  if (solids.solids.size() > 1) {
    out.field = compute_solids(session, asset, solids, request.sdf, backend_stages);
    sample("set_mesh");
    compute_ms = clock.lap_ms();
    if (backend_stages.empty()) backend_stages.push_back({"sdf", compute_ms});
    sample("sdf");
  } else {
    const bool ply_or_txt = request.output.empty() || io::format_from_path(request.output) == io::Format::Ply ||
                            io::format_from_path(request.output) == io::Format::Txt;
    if (lean && ply_or_txt && out.asset.format != io::Format::Gltf && out.asset.format != io::Format::Glb &&
        weld_is_identity(out.asset)) {
      out.asset.input_positions = std::vector<glm::vec3>();
      out.asset.input_triangles = std::vector<Triangle>();
      out.asset.input_to_welded = std::vector<std::uint32_t>();
    }
    session.set_mesh(std::move(out.asset.mesh));
    if (own_session) session.backend().release_mesh();
    set_mesh_ms = clock.lap_ms();
    sample("set_mesh");
    out.field = session.compute(request.sdf);
    // A copy for the result's asset, after the computation's peak; none when only writing.
    if (!lean) out.asset.mesh = session.mesh();
    mesh = &session.mesh();
    compute_ms = clock.lap_ms();
    sample("sdf");
    backend_stages = session.backend().last_timings();
  }
  SdfField& field = out.field;
  if (backend_stages.empty()) {
    report.stages.push_back({"prepare", set_mesh_ms});
    report.stages.push_back({"sdf", compute_ms});
  } else {
    for (const StageTiming& s : backend_stages) report.stages.push_back(s);
  }
  report.points = field.values.size();
  report.filled_points = field.filled_count;
  if (field.filled_count > 0)
    report.warnings.push_back(std::to_string(field.filled_count) + " of " +
                              std::to_string(field.values.size()) +
                              " points had no accepted ray and were filled from their neighbours (with the mean SDF "
                              "where none had a value: a vertex no triangle uses)");

  if (request.smooth_rings > 0) {
    SmoothOptions smooth;
    smooth.rings = request.smooth_rings;
    field.values = smooth_field(*mesh, field.domain, field.values, smooth);
    report.stages.push_back({"smooth", clock.lap_ms()});
    sample("smooth");
  }
#ifdef SDFKIT_HAS_VULKAN
  if (request.smooth_texture_px > 0.0f) {
    diffusion::TextureSmoothOptions t;
    t.diffuse.radius_px = request.smooth_texture_px;
    t.device = request.backend.device;
    field.values = diffusion::smooth_texture_space(*mesh, field.values, t).values;
    report.stages.push_back({"smooth_texture", clock.lap_ms()});
    sample("smooth_texture");
  }
#endif
  report.summary = summarize(field.values);
  return out;
}

}  // namespace

ComputeResult compute_asset(const ComputeRequest& request, const SessionProvider& provider) {
  return compute_impl(request, nullptr, provider);
}

ComputeResult compute_asset(const ComputeRequest& request, io::Asset asset, const SessionProvider& provider) {
  return compute_impl(request, &asset, provider);
}

namespace {

ComputeReport run_compute_impl(const ComputeRequest& request, const SessionProvider& provider, bool own_session) {
  Stopwatch clock;
  // Only the report leaves: the asset is written with the session's mesh (compute_impl, lean).
  Session* session = nullptr;
  ComputeResult r =
      compute_impl(request, nullptr, [&]() -> Session& { return *(session = &provider()); }, true, own_session);
  if (!request.output.empty()) {
    clock.lap_ms();
    const bool lent = r.asset.mesh.triangles.empty() && session != nullptr;
    io::write_field(request.output, r.asset, lent ? session->mesh() : r.asset.mesh, r.field, request.write);
    r.report.stages.push_back({"write", clock.lap_ms()});
    r.report.memory.push_back({"write", resident_memory()});
  }
  return std::move(r.report);
}

}  // namespace

ComputeReport run_compute(const ComputeRequest& request, const SessionProvider& provider) {
  return run_compute_impl(request, provider, false);
}

ComputeReport run_compute(const ComputeRequest& request, Session& session) {
  return run_compute(request, [&]() -> Session& { return session; });
}

ComputeReport run_compute(const ComputeRequest& request) {
  std::unique_ptr<Session> session;
  return run_compute_impl(request, [&]() -> Session& {
    session = std::make_unique<Session>(request.backend, request.sdf);
    return *session;
  }, true);
}

}  // namespace sdfkit
