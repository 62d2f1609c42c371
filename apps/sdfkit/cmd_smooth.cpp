// sdfkit smooth: k-ring Gaussian smoothing of a result file, written like compute's output, or
// (--texture-space) diffusion through a skeleton texture mapping on a Vulkan device (issue 13).
// Also the result loading shared by render and compare.
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/field.hpp"
#include "sdfkit/post/smooth.hpp"
#ifdef SDFKIT_CLI_HAS_RENDER
#include "sdfkit/diffusion/diffuse_mesh.hpp"
#endif

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <memory>

namespace sdfkit::cli {

void check_png_name(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (!lower.ends_with(".png")) throw UsageError(path + ": pictures are written as PNG (use a .png name)");
}

ResultValues load_or_compute(const std::string& input, const SdfCliOptions* sdf, const io::LoadOptions& load) {
  ResultValues r;
  io::Asset asset;
  if (input.starts_with("builtin:")) {
    if (!sdf) throw InputError(input + ": a generated shape holds no values");
    asset = load_input(input, load);
  } else {
    io::FieldFile f = io::read_field(input, sdf ? io::ValuesRequired::No : io::ValuesRequired::Yes, load);
    asset = std::move(f.asset);
    if (!f.values.empty()) {
      r.domain = f.domain;
      r.values = io::welded_values(asset, f.domain, f.values);
    }
  }
  if (r.values.empty()) {
    // The same road as `sdfkit compute`: validation, the backend contract and choice, the
    // session's own mesh, smoothing.
    ComputeRequest request = sdf->request();
    request.input = input;
    std::unique_ptr<Session> session;
    ComputeResult c = compute_asset(request, std::move(asset), [&]() -> Session& {
      session = std::make_unique<Session>(request.backend, request.sdf);
      return *session;
    });
    r.asset = std::move(c.asset);
    r.domain = c.field.domain;
    r.values = std::move(c.field.values);
    r.report = std::move(c.report);
    r.computed = true;
    return r;
  }
  r.asset = std::move(asset);
  if (sdf && sdf->smooth > 0) {
    SmoothOptions so;
    so.rings = sdf->smooth;
    r.values = smooth_field(r.asset.mesh, r.domain, r.values, so);
  }
  return r;
}

void add_smooth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("smooth", "k-ring Gaussian smoothing of a result file, or texture-space diffusion (--texture-space)");
  struct Args {
    std::string input, output;
    SmoothOptions smooth;
    bool texture = false;
    float radius = 0.0f;
    std::uint32_t steps = 0;
    bool no_stretch = false, no_conserve = false;
    std::uint32_t atlas_size = 2048;
    std::string atlas_png, skeleton, device;
    io::LoadOptions load;
    io::WriteOptions write;
    bool no_color = false, quiet = false;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("RESULT", a->input, "A result: .glb/.gltf with _SDF, .ply with quality")->required();
  cmd->add_option("-o,--output", a->output, "Output file: .glb .gltf (per vertex), .ply, .txt")->required();
  cmd->add_option("--rings,-k", a->smooth.rings, "Rings K: each point averages its neighbours up to K edges away")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--sigma", a->smooth.sigma,
                  "Gaussian sigma in model units (default: K * mean edge length / 2; with --texture-space, "
                  "converted per chart by its scale)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--texture-space", a->texture,
                "Diffuse through a skeleton texture mapping on a Vulkan device instead (needs --radius or --sigma)");
  cmd->add_option("--radius", a->radius, "--texture-space: the Gaussian's sigma in atlas texels, every chart")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--steps", a->steps,
                  "--texture-space: the blur as N successive blurs of width / sqrt(N), each from the values the "
                  "last read back, so the kernel carries on across chart borders (0 = as many as the mapping's "
                  "reach needs, 1 = one blur, the paper's)")
      ->check(CLI::Range(0u, diffusion::kMaxSteps));
  cmd->add_flag("--no-stretch", a->no_stretch,
                "--texture-space with --sigma: one blur width in texels per chart (its mean scale) instead of one per "
                "texel from the map's local stretch");
  cmd->add_flag("--no-conserve", a->no_conserve,
                "--texture-space: keep the blur's own read-back instead of restoring the field's integral over each "
                "connected piece within its range there (as heat flow keeps it)");
  cmd->add_option("--atlas-size", a->atlas_size, "--texture-space: atlas side in texels (default 2048)")
      ->check(CLI::Range(16, 16384));
  cmd->add_option("--atlas-png", a->atlas_png, "--texture-space: also write the diffused field in the atlas as PNG");
  cmd->add_option("--skeleton", a->skeleton,
                  "--texture-space: skeleton JSON written by `sdfkit skeleton` for this mesh (default: extracted "
                  "from the geometry)");
  cmd->add_option("--device", a->device, "--texture-space: Vulkan device (index or name)");
  cmd->add_option("--threads", a->smooth.threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--normalize", a->write.normalized, "Write values normalised to [0, 1]");
  cmd->add_flag("--no-color", a->no_color, "Do not write COLOR_0 / PLY colours");
  cmd->add_option("--weld-tolerance", a->load.weld_tolerance, "Weld positions closer than this (model units; default 1e-6 of the bounding box, 0 = bitwise-equal only)")
      ->check(CLI::NonNegativeNumber);
  add_asset_options(*cmd, a->load);
  cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
  cmd->callback([a, cmd] {
    a->write.color = !a->no_color;
    const auto given = [cmd](const char* name) { return cmd->get_option(name)->count() > 0; };
    if (a->texture) {
      for (const char* k : {"--rings", "--threads"})
        if (given(k)) throw UsageError(std::string(k) + " is k-ring smoothing's; --texture-space takes --radius or --sigma");
      if (given("--radius") == given("--sigma"))
        throw UsageError("--texture-space needs exactly one of --radius (texels) and --sigma (model units)");
      if (a->no_stretch && given("--radius"))
        throw UsageError("--no-stretch needs --sigma (a radius in texels is one width everywhere already)");
      if (!a->atlas_png.empty()) check_png_name(a->atlas_png);
    } else {
      for (const char* k : {"--radius", "--steps", "--no-stretch", "--no-conserve", "--atlas-size", "--atlas-png", "--skeleton", "--device"})
        if (given(k)) throw UsageError(std::string(k) + " needs --texture-space");
    }
    // An output that cannot hold the values is refused before the work, not after it: the
    // extension before loading, per-face values to glTF once the result says what it holds.
    io::check_output(a->output, SdfDomain::Vertex);
    const ResultValues r = load_or_compute(a->input, nullptr, a->load);
    io::check_output(a->output, r.domain);
    if (a->texture) {
#ifdef SDFKIT_CLI_HAS_RENDER
      if (r.domain != SdfDomain::Vertex)
        throw InputError(a->input + ": texture-space diffusion needs per-vertex values (this result is per face)");
      diffusion::TextureSmoothOptions t;
      t.diffuse.radius_px = a->radius;
      t.diffuse.sigma = a->radius > 0.0f ? 0.0f : a->smooth.sigma;
      t.diffuse.steps = a->steps;
      t.diffuse.stretch = !a->no_stretch;
      t.diffuse.conserve = !a->no_conserve;
      t.stm.atlas_size = a->atlas_size;
      t.device = a->device;
      skeleton::Skeleton skel;
      if (!a->skeleton.empty()) {
        skel = diffusion::read_skeleton_json(a->skeleton);
        t.skeleton = &skel;
      }
      const auto start = std::chrono::steady_clock::now();
      const diffusion::TextureSmoothResult d = diffusion::smooth_texture_space(r.asset.mesh, r.values, t);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      SdfField field;
      field.domain = r.domain;
      field.values = d.values;
      field.kept_rays.assign(field.values.size(), 0);
      field.filled.assign(field.values.size(), 0);
      if (!a->atlas_png.empty()) diffusion::write_atlas_png(d.stm.mapping, r.asset.mesh, d.values, a->atlas_png);
      // A glTF output carries the mapping as TEXCOORD_1 (the atlas PNG is its texture). Only a
      // fresh glTF can: a glTF input's primitives would have to be split at the chart borders.
      io::WriteOptions write = a->write;
      const io::Format out_format = io::format_from_path(a->output);
      const bool gltf_out = out_format == io::Format::Gltf || out_format == io::Format::Glb;
      const bool gltf_in = r.asset.format == io::Format::Gltf || r.asset.format == io::Format::Glb;
      std::string texcoord_note;
      if (gltf_out && !gltf_in && r.asset.input_triangles.size() == r.asset.mesh.face_count())
        write.texcoord1 = diffusion::gltf_corner_uv(d.stm.mapping, r.asset.mesh);
      else if (gltf_out)
        texcoord_note = gltf_in ? "; no TEXCOORD_1: the input is a glTF asset"
                                : "; no TEXCOORD_1: the input's triangles are not the welded mesh's";
      io::write_field(a->output, r.asset, field, write);
      char scale[64];
      if (a->radius > 0.0f) std::snprintf(scale, sizeof scale, "radius %g px", static_cast<double>(a->radius));
      else std::snprintf(scale, sizeof scale, "sigma %g", static_cast<double>(a->smooth.sigma));
      if (!a->quiet)
        std::printf("%s: %zu vertex values diffused in texture space (%zu charts on a %u² atlas, %s) in %.1f ms "
                    "(skeleton %.2f s, mapping %.2f s, diffusion %.1f ms in %u step%s) -> %s%s%s\n",
                    a->input.c_str(), field.values.size(), d.stm.mapping.charts.size(), d.stm.mapping.size,
                    scale, ms, d.skeleton_seconds, d.mapping_seconds, d.diffusion.timings.total, d.diffusion.steps,
                    d.diffusion.steps == 1 ? "" : "s", a->output.c_str(),
                    write.texcoord1.empty() ? "" : " (the mapping as TEXCOORD_1)", texcoord_note.c_str());
      return;
#else
      throw UsageError("--texture-space needs the Vulkan engine (built with SDFKIT_WITH_VULKAN=OFF)");
#endif
    }
    const auto start = std::chrono::steady_clock::now();
    SdfField field;
    field.domain = r.domain;
    field.values = smooth_field(r.asset.mesh, r.domain, r.values, a->smooth);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    field.kept_rays.assign(field.values.size(), 0);
    field.filled.assign(field.values.size(), 0);
    io::write_field(a->output, r.asset, field, a->write);
    if (!a->quiet)
      std::printf("%s: %zu %s values smoothed over %d rings in %.1f ms -> %s\n", a->input.c_str(),
                  field.values.size(), r.domain == SdfDomain::Vertex ? "vertex" : "face", a->smooth.rings, ms,
                  a->output.c_str());
  });
}

}  // namespace sdfkit::cli
