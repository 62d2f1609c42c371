// sdfkit compare --diffusion (compare_diffusion.hpp).
#include "compare_diffusion.hpp"

#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/diffusion/heat.hpp"
#include "sdfkit/io/field.hpp"
#include "sdfkit/post/compare.hpp"
#include "sdfkit/post/smooth.hpp"
#ifdef SDFKIT_CLI_HAS_RENDER
#include "sdfkit/diffusion/diffuse.hpp"
#include "sdfkit/diffusion/seams.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/skeleton/skeleton.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <nlohmann/json.hpp>
#endif

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

namespace sdfkit::cli {
#ifdef SDFKIT_CLI_HAS_RENDER
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

struct Row {
  double sigma = 0.0, sigma_edges = 0.0;
  std::string method;  // heat | k-ring | texture
  int rings = 0;       // k-ring's K
  double pearson = 0.0, median_relative = 0.0, rms = 0.0, ms = 0.0;
  double seam = 0.0;   // seam ratio over the texture space's charts at this sigma (diffusion/seams.hpp)
};

void fill_agreement(Row& row, std::span<const float> a, std::span<const float> heat) {
  const FieldComparison c = compare_fields(a, heat);
  row.pearson = c.pearson;
  row.median_relative = c.median_relative;
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (static_cast<double>(a[i]) - heat[i]) * (static_cast<double>(a[i]) - heat[i]);
  row.rms = std::sqrt(s / static_cast<double>(std::max<std::size_t>(a.size(), 1)));
}

}  // namespace

void compare_diffusion(const DiffusionCompareArgs& a) {
  // The values on their welded mesh, per vertex.
  io::Asset asset;
  std::vector<float> values;
  if (io::format_from_path(a.input) == io::Format::Txt) {
    if (a.mesh.empty()) throw UsageError(a.input + ": values in a .txt need --mesh");
    asset = load_input(a.mesh, a.load);
    const std::vector<float> raw = io::read_values_txt(a.input);
    if (io::domain_of_count(asset, raw.size(), a.input) != SdfDomain::Vertex)
      throw InputError(a.input + ": diffusion compares per-vertex values (these are per face)");
    values = io::welded_values(asset, SdfDomain::Vertex, raw);
  } else {
    ResultValues r = load_or_compute(a.input, nullptr, a.load);
    if (r.domain != SdfDomain::Vertex)
      throw InputError(a.input + ": diffusion compares per-vertex values (this result is per face)");
    asset = std::move(r.asset);
    values = std::move(r.values);
  }
  const Mesh& mesh = asset.mesh;
  for (float v : values)
    if (!std::isfinite(v)) throw InputError(a.input + ": the values are not all finite (fill the field first)");
  const double edge = mean_edge_length(mesh);
  if (!(edge > 0.0)) throw InputError(a.input + ": the mesh has no edges");
  std::vector<std::pair<double, double>> sigmas;  // model units, edges
  for (double s : a.sigmas) sigmas.emplace_back(s, s / edge);
  for (double e : a.sigma_edges) sigmas.emplace_back(e * edge, e);

  // The skeleton once (given or extracted), one device; the mapping per sigma, as
  // smooth_texture_space builds it: with the overlap band kBandSigmas · sigma the blur needs.
  auto t = Clock::now();
  skeleton::Skeleton skel;
  if (!a.skeleton.empty()) skel = diffusion::read_skeleton_json(a.skeleton);
  else skel = skeleton::extract(mesh, nullptr, {}, {});
  const double skeleton_ms = ms_since(t);
  double mapping_ms = 0.0;
  std::size_t charts = 0;
  diffusion::StmOptions so;
  so.atlas_size = a.atlas_size;
  vk::ContextConfig config;
  config.device = a.device;
  vk::Context ctx(config);
  diffusion::Diffuser diffuser(ctx);

  std::vector<Row> rows;
  for (const auto& [sigma, edges] : sigmas) {
    // The mapping first: every row's seam ratio is taken over its charts.
    t = Clock::now();
    so.overlap = diffusion::kBandSigmas * sigma;
    const diffusion::Stm stm = diffusion::build_stm(mesh, skel, so);
    mapping_ms += ms_since(t);
    charts = std::max(charts, stm.mapping.charts.size());

    Row heat_row{sigma, edges, "heat"};
    t = Clock::now();
    const std::vector<float> heat = diffusion::heat_diffusion(mesh, values, sigma, a.heat_steps);
    heat_row.ms = ms_since(t);
    fill_agreement(heat_row, heat, heat);
    heat_row.seam = diffusion::seam_ratio(mesh, stm.mapping, heat);
    rows.push_back(heat_row);

    Row k{sigma, edges, "k-ring"};
    SmoothOptions ko;
    ko.sigma = static_cast<float>(sigma);
    ko.rings = k.rings = diffusion::kring_for_sigma(static_cast<float>(sigma), static_cast<float>(edge));
    t = Clock::now();
    const std::vector<float> kring = smooth_field(mesh, SdfDomain::Vertex, values, ko);
    k.ms = ms_since(t);
    fill_agreement(k, kring, heat);
    k.seam = diffusion::seam_ratio(mesh, stm.mapping, kring);
    rows.push_back(k);

    Row tex{sigma, edges, "texture"};
    diffusion::DiffuseOptions d;
    d.sigma = static_cast<float>(sigma);
    const diffusion::DiffuseResult r = diffuser.run(mesh, stm.mapping, values, d);
    tex.ms = r.timings.total;
    fill_agreement(tex, r.values, heat);
    tex.seam = diffusion::seam_ratio(mesh, stm.mapping, r.values);
    rows.push_back(tex);
  }

  std::printf("%s: %zu vertices, mean edge %.6g; k-ring and texture-space diffusion against heat diffusion "
              "(cotangent Laplacian, lumped mass, %d implicit steps to t = sigma^2 / 2)\n",
              a.input.c_str(), mesh.vertex_count(), edge, a.heat_steps);
  std::printf("texture space: up to %zu charts on a %u^2 atlas, overlap band %g sigma (skeleton %.0f ms, mappings "
              "%.0f ms, not in the times below)\n",
              charts, a.atlas_size, diffusion::kBandSigmas, skeleton_ms, mapping_ms);
  std::printf("seam ratio: P95 value jump across the texture space's chart borders / inside its charts, of each "
              "method's result (heat's: what a seamless field gives over the same borders)\n");
  std::printf("| sigma | sigma / edge | method | pearson | median relative | rms | seam ratio | ms |\n");
  std::printf("|---:|---:|---|---:|---:|---:|---:|---:|\n");
  nlohmann::json j;
  j["input"] = a.input;
  j["vertices"] = mesh.vertex_count();
  j["mean_edge"] = edge;
  j["heat_steps"] = a.heat_steps;
  for (const Row& r : rows) {
    const std::string method = r.method == "k-ring" ? "k-ring (k=" + std::to_string(r.rings) + ")" : r.method;
    std::printf("| %.6g | %.3g | %s | %.6f | %.4f%% | %.6g | %.3f | %.1f |\n", r.sigma, r.sigma_edges, method.c_str(),
                r.pearson, 100.0 * r.median_relative, r.rms, r.seam, r.ms);
    nlohmann::json jr{{"sigma", r.sigma}, {"sigma_edges", r.sigma_edges}, {"method", r.method},
                      {"pearson", r.pearson}, {"median_relative", r.median_relative}, {"rms", r.rms},
                      {"seam_ratio", r.seam}, {"ms", r.ms}};
    if (r.method == "k-ring") jr["rings"] = r.rings;
    j["rows"].push_back(jr);
  }
  j["charts"] = charts;
  j["atlas_size"] = a.atlas_size;
  j["overlap_band_sigmas"] = diffusion::kBandSigmas;
  if (!a.json.empty()) write_text_atomically(a.json, j.dump(2) + "\n");
}
#else
void compare_diffusion(const DiffusionCompareArgs&) {
  throw UsageError("compare --diffusion needs the Vulkan engine (built with SDFKIT_WITH_VULKAN=OFF)");
}
#endif

}  // namespace sdfkit::cli
