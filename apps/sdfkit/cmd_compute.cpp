#include "commands.hpp"

#include "sdfkit/core/error.hpp"

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

namespace sdfkit::cli {

void add_sdf_options(CLI::App& cmd, SdfCliOptions& o, const std::string& views_flag) {
  cmd.add_option("--backend", o.backend,
                 "auto | vulkan | opencl (auto: a GPU backend on a GPU; without one, OpenCL over a CPU rasterizer; "
                 "backend options narrow it: see `sdfkit devices`)")
      ->check(CLI::IsMember({"auto", "vulkan", "opencl"}, CLI::ignore_case));
  cmd.add_option("--device", o.backend_config.device,
                 "Device index or name substring (default: env SDFKIT_VK_DEVICE / SDFKIT_CL_DEVICE)");
  cmd.add_option("--per", o.per, "vertex | face")->check(CLI::IsMember({"vertex", "face"}));
  cmd.add_option("--rays", o.sdf.rays, "Rays per point (OpenCL ray casting; the vulkan backend's samples are its --views cameras)")->check(CLI::Range(1, 1024));
  cmd.add_option("--cone", o.sdf.cone_degrees, "Full cone aperture in degrees")->check(CLI::Range(1.0, 180.0));
  cmd.add_option("--false-hits", o.false_hits,
                 "paper: drop hits facing the start normal | cgal: keep hits where the ray leaves the solid")
      ->check(CLI::IsMember({"paper", "cgal"}));
  cmd.add_option(views_flag, o.backend_config.views, "Camera directions (Vulkan depth peeling)")
      ->check(CLI::Range(1, 4096));
  cmd.add_option("--resolution", o.backend_config.resolution, "Framebuffer size in pixels (Vulkan)")
      ->check(CLI::Range(16, 8192));
  cmd.add_option("--peel-mode", o.backend_config.vulkan_mode,
                 "Vulkan: layers (the paper's depth peeling) | lists (per-pixel fragment lists)")
      ->check(CLI::IsMember({"layers", "lists"}));
  cmd.add_option("--memory-cap", o.backend_config.memory_cap, "Device memory cap in bytes (OpenCL)");
  cmd.add_option("--accel", o.backend_config.accel, "OpenCL acceleration structure: bvh (default) | octree")
      ->check(CLI::IsMember({"bvh", "octree"}));
  cmd.add_flag("--profile", o.backend_config.profile, "Time each pass on the device");
  cmd.add_option("--weld-tolerance", o.load.weld_tolerance, "Weld positions closer than this (model units; default 1e-6 of the bounding box, 0 = bitwise-equal only)")
      ->check(CLI::NonNegativeNumber);
  add_asset_options(cmd, o.load);
}

void add_output_options(CLI::App& cmd, SdfCliOptions& o, bool smoothing) {
  if (smoothing)
    cmd.add_option("--smooth", o.smooth, "k-ring Gaussian smoothing of the result (rings, 0 = off)")
        ->check(CLI::Range(0, 64));
  if (smoothing)
    cmd.add_option("--smooth-texture", o.smooth_texture,
                   "Texture-space diffusion of the result: Gaussian sigma in texels of a 2048² skeleton texture "
                   "mapping (0 = off; per-vertex results, Vulkan)")
        ->check(CLI::NonNegativeNumber);
  cmd.add_flag("--normalize", o.write.normalized, "Write values normalised to [0, 1]");
  cmd.add_flag("--no-color", o.no_color, "Do not write COLOR_0 / PLY colours");
}

void finish_sdf_options(SdfCliOptions& o) {
  o.sdf.domain = o.per == "face" ? SdfDomain::Face : SdfDomain::Vertex;
  o.sdf.false_hit = o.false_hits == "cgal" ? FalseHitRule::Cgal : FalseHitRule::Paper;
  o.backend_config.kind = parse_backend_kind(o.backend);
  o.write.color = !o.no_color;
  validate(o.request());
}

ComputeRequest SdfCliOptions::request() const {
  ComputeRequest r;
  r.load = load;
  r.sdf = sdf;
  r.write = write;
  r.smooth_rings = smooth;
  r.smooth_texture_px = smooth_texture;
  r.backend = backend_config;
  return r;
}

std::string backend_line(const ComputeReport& r) {
  return "backend " + r.backend + " on " + r.device + (r.backend_choice.empty() ? "" : " (" + r.backend_choice + ")");
}

void add_compute_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compute", "Compute the SDF of a mesh and write it");
  struct Args {
    std::string input, output, json;
    bool quiet = false;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("MESH", a->input, "Mesh file (.gltf .glb .obj .off .ply) or builtin:NAME")->required();
  cmd->add_option("-o,--output", a->output, "Output file: .glb .gltf (_SDF attribute), .ply (quality), .txt")
      ->required();
  cmd->add_option("--json", a->json, "Also write a JSON report of the run to this file");
  cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
  add_sdf_options(*cmd, a->sdf);
  add_output_options(*cmd, a->sdf, true);
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    ComputeRequest req = a->sdf.request();
    req.input = a->input;
    req.output = a->output;
    const ComputeReport r = run_compute(req);
    if (!a->json.empty()) {
      const std::string text = report_to_json(r);
      io::write_file_atomically(a->json, [&](std::ostream& os) { os << text << '\n'; });
    }
    if (a->quiet) return;
    std::printf("%s: %zu vertices, %zu faces (%zu welded vertices) -> %s\n", r.input.c_str(),
                r.input_vertices, r.input_faces, r.welded_vertices, r.output.c_str());
    std::printf("%s\n", backend_line(r).c_str());
    for (const StageTiming& s : r.stages)
      std::printf("  %-16s %10.1f ms%s\n", s.stage.c_str(), s.milliseconds, s.nested ? " (device pass, counted in its stage)" : "");
    std::printf("  %-16s %10.1f ms\n", "total", total_milliseconds(r.stages));
    std::printf("SDF min %g  median %g  mean %g  max %g (model units); %zu of %zu points filled\n",
                r.summary.min, r.summary.median, r.summary.mean, r.summary.max, r.filled_points, r.points);
    for (const std::string& w : r.warnings) std::fprintf(stderr, "sdfkit: warning: %s\n", w.c_str());
  });
}

}  // namespace sdfkit::cli
