// sdfkit-stm-bench: quality of the skeleton texture mapping (issue 13) on real meshes and the
// procedural skeleton models: per mesh, the skeleton (extracted with the Embree reference SDF),
// the charts by kind, the share of vertices in bone charts, the atlas share used, the area and
// angle distortion (area-weighted mean / p95 / max over all charts), the share of covered texels
// covered twice (folds) and the time of build_stm.
//
//   sdfkit-stm-bench [--models] [--atlas-size N] [--gutter G] [--png DIR] [MESH ...]
//
// --png DIR writes DIR/<name>-atlas.png: the atlas with the mesh's SDF (Figure 10).
#include "sdfkit/core/error.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/models.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

using namespace sdfkit;

namespace {

void run(const std::string& name, const Mesh& mesh, const diffusion::StmOptions& options, const std::string& png_dir) {
  reference::EmbreeBackend backend;
  const auto t0 = std::chrono::steady_clock::now();
  const skeleton::Skeleton s = skeleton::extract(mesh, &backend, {}, {});
  const double skel_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const diffusion::Stm stm = diffusion::build_stm(mesh, s, options);
  const diffusion::StmQuality& q = stm.quality;
  // Bone charts alone (area weighted over their faces).
  double bone_area = 0, bone_ad = 0, bone_gd = 0;
  for (const diffusion::ChartQuality& c : q.charts)
    if (c.kind == diffusion::Chart::Kind::Bone)
      bone_area += c.area, bone_ad += c.area * c.area_distortion.mean, bone_gd += c.area * c.angle_distortion.mean;
  std::printf("| %s | %zu | %zu | %u / %u / %u | %.1f %% | %.1f %% / %.1f %% | %.2f / %.2f / %.1f | %.2f / %.2f / %.1f | %.2f / %.2f | %.2f %% | %llu | %.2f | %.3f |\n",
              name.c_str(), mesh.positions.size(), s.nodes.size(), q.bone_charts, q.joint_charts, q.sheet_charts,
              100.0 * q.bone_vertex_share, 100.0 * q.atlas_used, 100.0 * q.atlas_covered, q.area_distortion.mean, q.area_distortion.p95,
              q.area_distortion.max, q.angle_distortion.mean, q.angle_distortion.p95, q.angle_distortion.max,
              bone_area > 0 ? bone_ad / bone_area : 0.0, bone_area > 0 ? bone_gd / bone_area : 0.0, 100.0 * q.overlap,
              static_cast<unsigned long long>(q.duplicated_triangles), skel_s, q.seconds);
  std::fflush(stdout);
  if (!png_dir.empty()) {
    std::vector<float> values = s.sdf;
    if (values.size() != mesh.positions.size()) {
      values.assign(mesh.positions.size(), 0.0f);
      for (std::size_t v = 0; v < values.size(); ++v) values[v] = static_cast<float>(stm.mapping.vertex_chart[v] % 7);
    }
    diffusion::write_atlas_png(stm.mapping, mesh, values, (std::filesystem::path(png_dir) / (name + "-atlas.png")).string());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Skeleton texture mapping quality (issue 13)");
  std::vector<std::string> meshes;
  bool models = false;
  diffusion::StmOptions options;
  std::string png_dir;
  app.add_option("meshes", meshes, "Mesh files (closed)")->check(CLI::ExistingFile);
  app.add_flag("--models", models, "Also the procedural skeleton models (star, genus 2, C and S plates)");
  app.add_option("--atlas-size", options.atlas_size, "Atlas size in texels")->check(CLI::Range(16, 16384));
  app.add_option("--gutter", options.gutter, "Gutter in texels")->check(CLI::Range(0, 64));
  app.add_option("--png", png_dir, "Write <name>-atlas.png (coloured by the SDF) into this directory")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);
  if (meshes.empty() && !models) {
    std::fprintf(stderr, "error: give mesh files or --models\n");
    return 2;
  }
  std::printf("atlas %u², gutter %u. Distortion: area σ1σ2, angle σ1/σ2 (area-weighted mean / p95 / max over all charts' "
              "faces); bone: mean over bone charts.\n\n",
              options.atlas_size, options.gutter);
  std::printf("| mesh | vertices | nodes | charts bone / joint / sheet | vertices in bone charts | atlas in rectangles / covered | area distortion | "
              "angle distortion | bone area / angle | overlap | duplicated triangles | skeleton s | build_stm s |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  try {
    for (const std::string& path : meshes)
      run(std::filesystem::path(path).stem().string(), io::load_asset(path).mesh, options, png_dir);
    if (models) {
      namespace m = skeleton::models;
      run("star", m::five_armed_star().mesh, options, png_dir);
      run("genus2", m::genus2().mesh, options, png_dir);
      run("c_plate", m::c_shape().mesh, options, png_dir);
      run("s_plate", m::s_shape().mesh, options, png_dir);
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
