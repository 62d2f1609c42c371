// sdfkit bench --diffusion (diffusion_bench.hpp).
#include "diffusion_bench.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/diffuse.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/post/smooth.hpp"
#include "sdfkit/skeleton/skeleton.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <ctime>
#include <sstream>

namespace sdfkit::bench {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The q-quantile of v (nearest rank): the spread of a cell is its quartiles.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

// "p25–p75" of the runs, the spread beside a median.
std::string spread(const std::vector<double>& v) {
  char s[64];
  std::snprintf(s, sizeof s, "%.0f–%.0f", quantile(v, 0.25), quantile(v, 0.75));
  return s;
}

// A per-vertex field to diffuse: distance to the centroid (timings do not depend on the values).
std::vector<float> bench_field(const Mesh& m) {
  glm::vec3 c(0.0f);
  for (const glm::vec3& p : m.positions) c += p;
  c /= static_cast<float>(std::max<std::size_t>(m.positions.size(), 1));
  std::vector<float> u(m.positions.size());
  for (std::size_t v = 0; v < u.size(); ++v) u[v] = glm::length(m.positions[v] - c);
  return u;
}

}  // namespace

DiffusionMesh cylinder_mesh(int segments, int stacks, std::uint32_t size) {
  DiffusionMesh d;
  d.name = "cylinder-" + std::to_string(segments) + "x" + std::to_string(stacks + 1);
  const float r = 1.0f, h = 2.0f * std::numbers::pi_v<float>;
  d.mesh = shapes::open_cylinder(r, h, segments, stacks);
  const Mesh& m = d.mesh;
  diffusion::AtlasMapping a;
  a.size = size;
  const std::uint32_t side = size - 2 * a.gutter;
  diffusion::Chart c;
  c.x0 = c.y0 = a.gutter;
  c.width = c.height = side;
  c.wraps_x = true;
  c.texels_per_unit = static_cast<float>(side) / h;
  a.charts.push_back(c);
  const auto uv = [&](std::uint32_t v) {
    const int i = static_cast<int>(v) % segments, j = static_cast<int>(v) / segments;
    return glm::vec2(static_cast<float>(c.x0) + static_cast<float>(side) * static_cast<float>(i) / static_cast<float>(segments),
                     static_cast<float>(c.y0) + 0.5f + (static_cast<float>(side) - 1.0f) * static_cast<float>(j) / static_cast<float>(stacks));
  };
  for (std::uint32_t f = 0; f < m.face_count(); ++f) {
    diffusion::AtlasTriangle t;
    t.face = f;
    for (int k = 0; k < 3; ++k) t.uv[k] = uv(m.triangles[f][static_cast<std::size_t>(k)]);
    a.triangles.push_back(t);
  }
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    a.vertex_chart.push_back(0);
    a.vertex_uv.push_back(uv(v));
  }
  d.mapping = std::move(a);
  return d;
}

nlohmann::json run_diffusion_bench(const std::vector<DiffusionMesh>& meshes, const DiffusionBenchOptions& o,
                                   std::string& markdown) {
  vk::ContextConfig config;
  config.device = o.device;
  vk::Context ctx(config);
  diffusion::Diffuser diffuser(ctx);
  nlohmann::json out;
  out["device"] = ctx.info().name;
  out["atlas_size"] = o.atlas_size;
  std::ostringstream md;
  md << "Texture-space diffusion (Table 2) on " << ctx.info().name << " (" << ctx.info().driver << "), atlas "
     << o.atlas_size << "², median of " << o.repeats << " warm runs "
     << "(p25–p75: their quartiles; blur: the graphs with and without it alternate which runs first). prepare: host (triangle soup, jobs, queries "
     << "into upload memory); raster+sample: the graph without the blur passes (raster, copy, sample), wall time; "
     << "blur: the full graph's wall time minus that; read-back: values out of mapped memory; total: diffuse() "
     << "end to end (prepare + graph + read-back); blur, 6-dispatch cascade: the same blur as one dispatch per box "
     << "(DiffuseOptions::fused_blur = false, the form before the fused shader), timed the same way in the same runs; "
     << "blur, stretch-compensated: the blur of sigma = radius / texels_per_unit (first chart) in model units, whose "
     << "width follows the map's local stretch per texel (DiffuseOptions::stretch, the default with a sigma: three "
     << "dispatches per axis), timed the same way, with the raster pass's stretch target and its copy (which only "
     << "this blur needs, so the graph without the blur has neither); "
     << "CPU ms: the process's CPU time (all threads, lavapipe's included) of the run less that of the run without "
     << "the blur, which a loaded machine inflates far less than wall time. "
     << "Every blur here is one blur, the paper's (DiffuseOptions::steps = 1); automatic steps: how many steps "
     << "the default (steps = 0, from the mapping's reach) would take for that radius, each costing one blur. "
     << "lavapipe's timestamps around the blur's dispatches read ~0.1 ms (it records, then runs the whole "
     << "submission), so times here are wall-time differences.\n\n";
  md << "| mesh | vertices | skeleton s | mapping ms | radius px | prepare ms | raster+sample ms | blur ms | blur p25–p75 | read-back ms | total ms | blur, 6-dispatch cascade ms | blur CPU ms | blur CPU p25–p75 | cascade CPU ms | blur, stretch-compensated ms | stretch CPU ms | blur dispatches | automatic steps |\n";
  md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  std::ostringstream kmd;
  kmd << "\nk-ring smoothing on the same meshes (engine/post/smooth, all cores):\n\n| mesh | vertices |";
  for (int k : o.rings) kmd << " k=" << k << " ms |";
  kmd << "\n|---|---:|";
  for (std::size_t i = 0; i < o.rings.size(); ++i) kmd << "---:|";
  kmd << "\n";

  for (const DiffusionMesh& bm : meshes) {
    std::fprintf(stderr, "sdfkit-bench --diffusion: %s (%zu vertices)\n", bm.name.c_str(), bm.mesh.vertex_count());
    nlohmann::json jm;
    jm["mesh"] = bm.name;
    jm["vertices"] = bm.mesh.vertex_count();
    jm["faces"] = bm.mesh.face_count();
    // The skeleton (no SDF backend: geometry only) of the mesh, or of its base mesh when it is a
    // midpoint subdivision (the base vertices keep their indices; build_stm gives the new ones a
    // neighbour's node).
    auto t = Clock::now();
    double skeleton_s = 0.0, mapping_ms = 0.0;
    diffusion::AtlasMapping mapping;
    if (bm.mapping) {
      mapping = *bm.mapping;
    } else {
      const Mesh& skel_mesh = bm.base ? *bm.base : bm.mesh;
      const skeleton::Skeleton skel = skeleton::extract(skel_mesh, nullptr, {}, {});
      skeleton_s = ms_since(t) / 1000.0;
      diffusion::StmOptions so;
      so.atlas_size = o.atlas_size;
      t = Clock::now();
      diffusion::Stm stm = diffusion::build_stm(bm.mesh, skel, so);
      mapping_ms = ms_since(t);
      jm["atlas_used"] = stm.quality.atlas_used;
      mapping = std::move(stm.mapping);
    }
    jm["skeleton_seconds"] = skeleton_s;
    jm["mapping_ms"] = mapping_ms;
    jm["charts"] = mapping.charts.size();

    const std::vector<float> u = bench_field(bm.mesh);
    for (float radius : o.radii) {
      // One blur, the paper's (DiffuseOptions::steps = 1); the steps the automatic choice would take
      // for this radius are reported beside it (not timed: each step costs one blur).
      diffusion::DiffuseOptions d;
      d.radius_px = radius;
      d.steps = 1;
      diffusion::DiffuseOptions automatic = d;
      automatic.steps = 0;
      const std::uint32_t auto_steps = diffuser.run(bm.mesh, mapping, u, automatic).steps;
      diffuser.run(bm.mesh, mapping, u, d);  // warm-up
      std::vector<double> raster, blur, sample, readback, total, unblurred, cascade, cpu_blur, cpu_cascade, stretch, cpu_stretch;
      const auto cpu_ms = [](std::clock_t a, std::clock_t b) { return 1000.0 * static_cast<double>(b - a) / CLOCKS_PER_SEC; };
      diffusion::DiffuseOptions nb = d;
      nb.blur = false;
      diffusion::DiffuseOptions box = d;  // the six-dispatch cascade the fused blur replaced
      box.fused_blur = false;
      diffuser.run(bm.mesh, mapping, u, box);  // warm-up
      // The stretch-compensated blur of the sigma whose chart-scale width is this radius.
      diffusion::DiffuseOptions st;
      st.steps = 1;
      st.sigma = mapping.charts.empty() || !(mapping.charts[0].texels_per_unit > 0.0f)
                     ? 0.0f
                     : radius / mapping.charts[0].texels_per_unit;
      diffusion::DiffuseOptions st_nb = st;
      st_nb.blur = false;
      const bool with_stretch = st.sigma > 0.0f;
      if (with_stretch) diffuser.run(bm.mesh, mapping, u, st);  // warm-up
      for (int r = 0; r < o.repeats; ++r) {
        // CPU time of the whole process (lavapipe's worker threads included) beside the wall
        // time: on a shared machine it is what the blur itself cost, whatever else runs. The
        // graphs with and without the blur alternate which runs first (a drift of the machine
        // over the pair then cancels in the median of the differences).
        double cpu_unblurred = 0.0, cpu_blurred = 0.0;
        double unblurred_ms = 0.0;
        diffusion::DiffuseResult res;
        for (int k = 0; k < 2; ++k) {
          const std::clock_t c0 = std::clock();
          if ((k == 0) == (r % 2 == 0)) {
            unblurred_ms = diffuser.run(bm.mesh, mapping, u, nb).timings.execute;
            cpu_unblurred = cpu_ms(c0, std::clock());
          } else {
            res = diffuser.run(bm.mesh, mapping, u, d);
            cpu_blurred = cpu_ms(c0, std::clock());
          }
        }
        unblurred.push_back(unblurred_ms);
        cpu_blur.push_back(cpu_blurred - cpu_unblurred);
        raster.push_back(unblurred.back());
        blur.push_back(res.timings.execute - unblurred.back());
        sample.push_back(res.timings.prepare);
        readback.push_back(res.timings.readback);
        total.push_back(res.timings.total);
        std::clock_t c0 = std::clock();
        cascade.push_back(diffuser.run(bm.mesh, mapping, u, box).timings.execute - unblurred.back());
        cpu_cascade.push_back(cpu_ms(c0, std::clock()) - cpu_unblurred);
        if (with_stretch) {
          // Its own baseline: the sigma graph without the blur (which declares no stretch
          // target, as the radius graph: this difference includes writing and copying it).
          c0 = std::clock();
          const double st_unblurred = diffuser.run(bm.mesh, mapping, u, st_nb).timings.execute;
          const std::clock_t c3 = std::clock();
          stretch.push_back(diffuser.run(bm.mesh, mapping, u, st).timings.execute - st_unblurred);
          cpu_stretch.push_back(cpu_ms(c3, std::clock()) - cpu_ms(c0, c3));
        }
      }
      nlohmann::json jr;
      jr["radius_px"] = radius;
      jr["prepare_ms"] = median(sample);
      jr["raster_sample_ms"] = median(raster);
      jr["blur_ms"] = median(blur);
      jr["blur_runs_ms"] = blur;
      jr["blur_cpu_runs_ms"] = cpu_blur;
      const diffusion::BlurPlan plan = diffusion::plan_blur(mapping, d);
      jr["blur_fused_lines"] = plan.fused_lines;
      jr["blur_cascade_lines"] = plan.cascade_lines;
      jr["blur_texel_reads"] = plan.texel_reads;
      jr["blur_cascade_ms"] = median(cascade);
      jr["blur_cpu_ms"] = median(cpu_blur);
      jr["blur_cascade_cpu_ms"] = median(cpu_cascade);
      if (with_stretch) {
        jr["stretch_sigma"] = st.sigma;
        jr["blur_stretch_ms"] = median(stretch);
        jr["blur_stretch_cpu_ms"] = median(cpu_stretch);
      }
      jr["blur_dispatches"] = plan.dispatches;
      jr["automatic_steps"] = auto_steps;
      jr["readback_ms"] = median(readback);
      jr["total_ms"] = median(total);
      jm["radii"].push_back(jr);
      char line[700];
      std::snprintf(line, sizeof line, "| %s | %zu | %.1f | %.0f | %.0f | %.1f | %.1f | %.1f | %s | %.1f | %.1f | %.1f | %.0f | %s | %.0f | %.1f | %.0f | %u | %u |\n",
                    bm.name.c_str(), bm.mesh.vertex_count(), skeleton_s, mapping_ms, static_cast<double>(radius),
                    median(sample), median(raster), median(blur), spread(blur).c_str(), median(readback), median(total),
                    median(cascade), median(cpu_blur), spread(cpu_blur).c_str(), median(cpu_cascade), median(stretch),
                    median(cpu_stretch), plan.dispatches, auto_steps);
      md << line;
    }
    kmd << "| " << bm.name << " | " << bm.mesh.vertex_count() << " |";
    for (int k : o.rings) {
      SmoothOptions s;
      s.rings = k;
      t = Clock::now();
      const std::vector<float> smoothed = smooth_field(bm.mesh, SdfDomain::Vertex, u, s);
      const double ms = ms_since(t);
      jm["kring_ms"].push_back({{"k", k}, {"ms", ms}});
      char cell[64];
      std::snprintf(cell, sizeof cell, " %.0f |", ms);
      kmd << cell;
    }
    kmd << "\n";
    out["meshes"].push_back(jm);
  }
  markdown = md.str() + kmd.str();
  return out;
}

}  // namespace sdfkit::bench
