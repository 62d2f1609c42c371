// sdfkit-seam-bench: seams and accuracy of texture-space diffusion through build_stm's atlas
// (issue 13's validation) over many meshes. Per mesh (skeleton extracted from the geometry, no
// SDF backend, as the tests do) and per sigma (in mean edge lengths): the mapping with the overlap
// band of kBandSigmas · sigma (or none with --no-band), the diffusion on the Vulkan device, and
//  - the seam ratio: P95 of |u_a - u_b| / |x_a - x_b| over edges whose ends are read back from
//    different charts, over the same P95 for the edges inside charts (the issue's ≤ 1.5), and
//    in brackets the same ratio of the heat-diffused field (what the field gives without seams);
//  - against intrinsic heat diffusion (t = sigma² / 2, cotangent Laplacian, lumped mass; N implicit
//    steps (M + (t / N) L) u_{k+1} = M u_k, the library's diffusion::kHeatSteps = 64 as the tests,
//    through tests/diffusion/diffuse_test_util.hpp; --heat-steps 1 is the single solve
//    (M + t L) u = M u0): Pearson, median
//    relative difference and RMS difference of the texture-space result, and the RMS of k-ring
//    smoothing at the same sigma (kring_for_sigma); "tex/k" is the ratio of the two RMS (≤ 1: the
//    texture space is no further from heat than k-ring).
// The field: a smooth wave over the bounding box plus seeded noise (the camel test's field).
// After the table, a summary per sigma over the meshes: the medians of the seam ratio and of
// tex/k, and how many meshes meet seam ratio ≤ 1.5, tex/k ≤ 1, Pearson ≥ 0.95 and median relative
// difference ≤ 5 %.
//
// --heat-steps takes a list (default "64,1": the reference, then the single solve beside it;
// e.g. 1,8,64): the rows and the seam ratio's bracket use the first;
// the last column gives Pearson / median rel. / tex/k against each further one, and the summary
// has one line per sigma and step count (the same texture-space and k-ring results, measured
// against each reference).
//
// With the band, each vertex is read back from every chart covering it, blended (StmOptions::blend),
// unless --no-blend. Joint and sheet charts are conformal maps (StmOptions::conformal) unless
// --no-conformal (their projections). The blur's width follows the charts' local stretch (DiffuseOptions::stretch)
// unless --no-stretch (one width per chart). The tex/k column "per chart" gives the same ratio
// with one width per chart, from the same mapping in the same run (the stretch compensation's
// own effect), and the summary counts it too. The result keeps the input's integral per piece
// (DiffuseOptions::conserve) unless --no-conserve (the blur's own read-back).
//
// --steps N: the blur's steps (DiffuseOptions::steps; default 0, automatic from the mapping's reach:
// the "blur steps" column says how many ran); 1 is the paper's single blur. --no-per-chart skips
// the one-width-per-chart comparison run (its columns then read nan / 0), which halves the time.
//
// --by-kind: after each row, where the error sits: per chart kind (bone, joint, sheet) of the
// vertices' own charts, their share of the vertices, the RMS of texture space and of k-ring
// against heat over them, and the kind's share of texture space's squared error.
//
//   sdfkit-seam-bench [--sigmas 1,2,3,5] [--heat-steps 64,1] [--steps N] [--no-band] [--no-blend] [--no-conformal] [--no-stretch] [--no-per-chart]
//                     [--no-conserve] [--by-kind] [--atlas-size N] [--models] [MESH...]
#include "../../tests/diffusion/diffuse_test_util.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/diffusion/diffuse.hpp"
#include "sdfkit/diffusion/seams.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/post/compare.hpp"
#include "sdfkit/post/smooth.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/skeleton/models.hpp"
#include "sdfkit/skeleton/skeleton.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <utility>
#include <random>

using namespace sdfkit;


int main(int argc, char** argv) {
  CLI::App app("Seams and heat-diffusion accuracy of texture-space diffusion (issue 13)");
  std::vector<std::string> meshes;
  std::vector<float> sigmas;
  bool no_band = false, no_blend = false, no_conformal = false, no_stretch = false, by_kind = false, no_per_chart = false,
       no_conserve = false;
  std::uint32_t atlas_size = 2048;
  bool models = false;
  std::uint32_t blur_steps = 0;
  app.add_option("meshes", meshes, "Mesh files (closed)")->check(CLI::ExistingFile);
  app.add_flag("--models", models, "Also generated shapes: capsule, torus, the skeleton models (star, genus 2, C and S plates)");
  std::string sigma_list = "1,2,3,5";
  app.add_option("--sigmas", sigma_list, "Sigmas in mean edge lengths, comma separated");
  std::string steps_list = diffusion::kHeatSteps == 1 ? "1" : std::to_string(diffusion::kHeatSteps) + ",1";
  app.add_option("--heat-steps", steps_list,
                 "Implicit steps of the heat reference, comma separated; the first is the rows', the others are summarized beside it "
                 "(default: the reference's steps, then the issue's single solve)")
      ->capture_default_str();
  app.add_flag("--no-band", no_band, "Charts without the overlap band (one ring of duplicated triangles)");
  app.add_flag("--no-conserve", no_conserve,
               "The blur's own read-back, without restoring the input's integral per piece (DiffuseOptions::conserve)");
  app.add_flag("--no-blend", no_blend, "Every vertex read back from its own chart only (no blend over the charts covering it)");
  app.add_flag("--no-conformal", no_conformal, "Joint and sheet charts keep their projections (no least squares conformal maps)");
  app.add_flag("--no-stretch", no_stretch, "One blur width in texels per chart (its mean scale) instead of one per texel from the map's local stretch");
  app.add_flag("--no-per-chart", no_per_chart, "Skip the comparison run with one blur width per chart (the 'tex/k per chart' columns: n/a); halves the time");
  app.add_flag("--by-kind", by_kind, "After each row, the error against heat per chart kind (bone, joint, sheet)");
  app.add_option("--steps", blur_steps, "The blur's steps (DiffuseOptions::steps): 0 = automatic from the mapping's reach, 1 = one blur (the paper's)")
      ->check(CLI::Range(0u, diffusion::kMaxSteps))
      ->capture_default_str();
  app.add_option("--atlas-size", atlas_size, "Atlas size in texels")->check(CLI::Range(16, 16384));
  CLI11_PARSE(app, argc, argv);
  if (meshes.empty() && !models) {
    std::fprintf(stderr, "error: give mesh files or --models\n");
    return 2;
  }
  if (no_band && no_conformal) {  // the conformal maps are made over the band: nothing to turn off
    std::fprintf(stderr, "error: --no-conformal has no effect with --no-band (charts without a band keep their projections)\n");
    return 2;
  }
  for (std::size_t at = 0; at <= sigma_list.size();) {
    const std::size_t end = std::min(sigma_list.find(',', at), sigma_list.size());
    const std::string item = sigma_list.substr(at, end - at);
    char* stop = nullptr;
    const float x = std::strtof(item.c_str(), &stop);
    if (item.empty() || *stop != '\0' || !(x > 0.0f) || !std::isfinite(x)) {
      std::fprintf(stderr, "error: --sigmas: '%s' is not a positive number\n", item.c_str());
      return 2;
    }
    sigmas.push_back(x);
    at = end + 1;
  }
  std::vector<int> heat_steps;
  for (std::size_t at = 0; at <= steps_list.size();) {
    const std::size_t end = std::min(steps_list.find(',', at), steps_list.size());
    const std::string item = steps_list.substr(at, end - at);
    char* stop = nullptr;
    const long n = std::strtol(item.c_str(), &stop, 10);
    if (item.empty() || *stop != '\0' || n < 1 || n > 4096) {
      std::fprintf(stderr, "error: --heat-steps: '%s' is not a whole number from 1 to 4096\n", item.c_str());
      return 2;
    }
    heat_steps.push_back(static_cast<int>(n));
    at = end + 1;
  }
  try {
    vk::Context ctx{vk::ContextConfig{}};
    diffusion::Diffuser diffuser(ctx);
    std::printf("atlas %u², band %s, %s, %s, %s, %s, %s. Seam ratio: P95 jump across chart borders / inside charts (≤ 1.5). "
                "Against heat diffusion: texture Pearson / median rel. / RMS; k-ring RMS; tex/k = RMS ratio.\n\n",
                atlas_size, no_band ? "none" : "3 sigma", no_band || no_blend ? "own chart read-back" : "blended read-back",
                no_conformal ? "projected joint charts" : "conformal joint charts",
                no_stretch ? "one blur width per chart" : "stretch-compensated blur",
                no_conserve ? "the read-back as it is" : "integral kept per piece",
                blur_steps == 0 ? "automatic steps" : (blur_steps == 1 ? "one blur (1 step)" : (std::to_string(blur_steps) + " steps").c_str()));
    std::printf("Heat reference: %d implicit step%s of t / %d", heat_steps[0], heat_steps[0] == 1 ? "" : "s", heat_steps[0]);
    if (heat_steps.size() > 1) std::printf(" (the last column: against %zu more)", heat_steps.size() - 1);
    std::printf(".\n\n");
    std::printf("| mesh | vertices | sigma (edges) | charts | atlas triangles / faces | seam ratio (heat) | pearson | median rel | "
                "rms | k-ring (k) rms | tex/k | tex/k per chart | overlap | build_stm s | blur steps | other steps: pearson / median rel / tex/k |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    // Per sigma and heat reference, over the meshes: seam ratio, tex/k, Pearson, median relative
    // difference (the summary at the end).
    struct Summary {
      std::vector<double> seam, texk, pearson, median_rel, texk_per_chart;
    };
    std::vector<std::vector<Summary>> summary(sigmas.size(), std::vector<Summary>(heat_steps.size()));
    std::vector<std::pair<std::string, std::function<Mesh()>>> inputs;
    for (const std::string& path : meshes)
      inputs.emplace_back(std::filesystem::path(path).stem().string(), [path] { return io::load_asset(path).mesh; });
    if (models) {
      namespace sm = skeleton::models;
      inputs.emplace_back("capsule", [] { return shapes::capsule(0.5f, 3.0f, 48, 40); });
      inputs.emplace_back("torus", [] { return shapes::torus(1.0f, 0.3f, 96, 32); });
      inputs.emplace_back("star", [] { return sm::five_armed_star().mesh; });
      inputs.emplace_back("genus2", [] { return sm::genus2().mesh; });
      inputs.emplace_back("c_plate", [] { return sm::c_shape().mesh; });
      inputs.emplace_back("s_plate", [] { return sm::s_shape().mesh; });
    }
    for (const auto& [name, make] : inputs) {
      try {
        const Mesh m = make();
        const skeleton::Skeleton skel = skeleton::extract(m, nullptr, {}, {});
        const std::vector<float> u = test::wave_field(m);
        const float edge = mean_edge_length(m);
        for (std::size_t si = 0; si < sigmas.size(); ++si) {
          const float edges = sigmas[si];
          const float sigma = edges * edge;
          diffusion::StmOptions so;
          so.atlas_size = atlas_size;
          so.overlap = no_band ? 0.0 : diffusion::kBandSigmas * sigma;
          so.blend = !no_blend;
          so.conformal = !no_conformal;
          const diffusion::Stm stm = diffusion::build_stm(m, skel, so);
          diffusion::DiffuseOptions o;
          o.sigma = sigma;
          o.stretch = !no_stretch;
          o.steps = blur_steps;
          o.conserve = !no_conserve;
          const diffusion::DiffuseResult run = diffuser.run(m, stm.mapping, u, o);
          const std::vector<float>& tex = run.values;
          const double ratio = diffusion::seam_ratio(m, stm.mapping, tex);
          std::vector<std::vector<float>> heats;
          for (const int steps : heat_steps) heats.push_back(test::heat_diffusion(m, u, sigma, steps));
          const std::vector<float>& heat = heats[0];
          // The same statistic of the heat field over the same partition of the edges: what the
          // field and where the borders lie give without any seam.
          const double heat_ratio = diffusion::seam_ratio(m, stm.mapping, heat);
          SmoothOptions ko;
          ko.sigma = sigma;
          ko.rings = diffusion::kring_for_sigma(sigma, edge);
          const std::vector<float> kr = smooth_field(m, SdfDomain::Vertex, u, ko);
          const FieldComparison c = compare_fields(tex, heat);
          const double rms = test::rms_difference(tex, heat), krms = test::rms_difference(kr, heat);
          // The same mapping with one blur width per chart (what the stretch compensation changes).
          diffusion::DiffuseOptions per_chart = o;
          per_chart.stretch = false;
          const std::vector<float> tex1 = no_per_chart ? std::vector<float>{} : diffuser.run(m, stm.mapping, u, per_chart).values;
          const double rms1 = tex1.empty() ? std::nan("") : test::rms_difference(tex1, heat);
          std::printf("| %s | %zu | %g | %zu | %.2f | %.2f (%.2f) | %.4f | %.2f %% | %.4f | %.4f (%d) | %.2f | %.2f | %.2f %% | %.2f | %u | ", name.c_str(),
                      m.vertex_count(), static_cast<double>(edges), stm.mapping.charts.size(),
                      static_cast<double>(stm.mapping.triangles.size()) / static_cast<double>(m.triangles.size()), ratio, heat_ratio,
                      c.pearson, 100.0 * c.median_relative, rms, krms, ko.rings, krms > 0 ? rms / krms : 0.0,
                      krms > 0 ? rms1 / krms : 0.0, 100.0 * stm.quality.overlap, stm.quality.seconds, run.steps);
          // Every reference (the first again, for the summary): the same results measured against it.
          for (std::size_t hi = 0; hi < heat_steps.size(); ++hi) {
            const FieldComparison ch = compare_fields(tex, heats[hi]);
            const double rh = test::rms_difference(tex, heats[hi]), kh = test::rms_difference(kr, heats[hi]);
            const double r1 = tex1.empty() ? 0.0 : test::rms_difference(tex1, heats[hi]);
            if (hi > 0)
              std::printf("%d: %.4f / %.2f %% / %.2f; ", heat_steps[hi], ch.pearson, 100.0 * ch.median_relative, kh > 0 ? rh / kh : 0.0);
            Summary& su = summary[si][hi];
            su.seam.push_back(ratio);
            su.texk.push_back(kh > 0 ? rh / kh : 0.0);
            su.pearson.push_back(ch.pearson);
            su.median_rel.push_back(ch.median_relative);
            if (!tex1.empty()) su.texk_per_chart.push_back(kh > 0 ? r1 / kh : 0.0);
          }
          std::printf("|\n");
          if (by_kind) {
            // Squared errors of texture space and k-ring against heat, summed per kind of the
            // vertex's own chart.
            double tex2[3] = {}, k2[3] = {}, all = 0.0;
            std::size_t count[3] = {};
            for (std::size_t v = 0; v < tex.size(); ++v) {
              const auto kind = static_cast<std::size_t>(stm.mapping.charts[stm.mapping.vertex_chart[v]].kind);
              const double dt = static_cast<double>(tex[v]) - heat[v], dk = static_cast<double>(kr[v]) - heat[v];
              tex2[kind] += dt * dt;
              k2[kind] += dk * dk;
              all += dt * dt;
              ++count[kind];
            }
            std::printf("|   by kind | ");
            const char* names[3] = {"bone", "joint", "sheet"};
            for (std::size_t k = 0; k < 3; ++k) {
              if (count[k] == 0) continue;
              const double n = static_cast<double>(count[k]);
              std::printf("%s: %.0f %% of vertices, tex rms %.4f, k-ring rms %.4f, %.0f %% of tex error; ", names[k],
                          100.0 * n / static_cast<double>(tex.size()), std::sqrt(tex2[k] / n), std::sqrt(k2[k] / n),
                          all > 0 ? 100.0 * tex2[k] / all : 0.0);
            }
            std::printf("|\n");
          }
          std::fflush(stdout);
        }
      } catch (const Error& e) {
        std::printf("| %s | error: %s |\n", name.c_str(), e.what());
      }
    }
    // The summary: medians and counts against the targets (seam ratio ≤ 1.5, tex/k ≤ 1,
    // Pearson ≥ 0.95, median relative difference ≤ 5 %), per sigma and heat reference.
    const auto median = [](std::vector<double> v) { return diffusion::quantile(std::move(v), 0.5); };
    const auto count = [](const std::vector<double>& v, auto pred) {
      std::size_t n = 0;
      for (double x : v) n += pred(x) ? 1 : 0;
      return n;
    };
    std::printf("\n| sigma (edges) | heat steps | meshes | seam ratio median | seam ratio <= 1.5 | tex/k median | tex/k <= 1 | pearson >= 0.95 | "
                "median rel <= 5 %% | tex/k per chart median | tex/k per chart <= 1 |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (std::size_t si = 0; si < sigmas.size(); ++si)
      for (std::size_t hi = 0; hi < heat_steps.size(); ++hi) {
        const Summary& u = summary[si][hi];
        std::printf("| %g | %d | %zu | %.2f | %zu | %.2f | %zu | %zu | %zu | %.2f | %zu |\n", static_cast<double>(sigmas[si]), heat_steps[hi],
                    u.seam.size(), median(u.seam), count(u.seam, [](double x) { return x <= 1.5; }), median(u.texk),
                    count(u.texk, [](double x) { return x <= 1.0; }), count(u.pearson, [](double x) { return x >= 0.95; }),
                    count(u.median_rel, [](double x) { return x <= 0.05; }), median(u.texk_per_chart),
                    count(u.texk_per_chart, [](double x) { return x <= 1.0; }));
      }
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
