// Texture-space diffusion: the host side of diffuse.hpp. Builds the triangle soup, the chart
// table, the blur's line jobs and the vertex queries in upload memory, then one render graph of
// the passes in passes/atlas_*.cpp, executed once; values (and the atlas) are read from mapped
// memory.

#include "sdfkit/diffusion/diffuse.hpp"

#include "atlas_passes.hpp"

#include "sdfkit/diffusion/heat.hpp"
#include "sdfkit/diffusion/seams.hpp"
#include "sdfkit/diffusion/stm.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"
#include "sdfkit/core/union_find.hpp"
#include "sdfkit/post/smooth.hpp"
#include "sdfkit/vulkan/context.hpp"
#include "sdfkit/vulkan/memory.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>

namespace sdfkit::diffusion {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

constexpr VkFormat kRasterFormat = VK_FORMAT_R32G32_SFLOAT;

// `with_stretch`: the second colour attachment, the stretch-compensated blur's half-widths
// (atlas_raster.frag); else value and coverage alone (atlas_raster_value.frag).
vk::Pipeline make_raster_pipeline(vk::Context& ctx, bool with_stretch) {
  vk::GraphicsPipelineDescription d;
  d.vertex_shader = "atlas_raster.vert";
  d.fragment_shader = with_stretch ? "atlas_raster.frag" : "atlas_raster_value.frag";
  // charts, vertex values, and the triangle soup itself (the provoking corner reads its triangle's
  // three mesh vertices there, atlas_raster.vert)
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  d.push_bytes = sizeof(passes::RasterPush);
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(passes::RasterVertex, uv)},
                  {1, 0, VK_FORMAT_R32_UINT, offsetof(passes::RasterVertex, vertex)},
                  {2, 0, VK_FORMAT_R32_UINT, offsetof(passes::RasterVertex, chart)},
                  {3, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(passes::RasterVertex, stretch)},
                  {4, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(passes::RasterVertex, variance)}};
  d.vertex_stride = sizeof(passes::RasterVertex);
  d.color_formats = {kRasterFormat};  // (value, coverage)
  if (with_stretch) d.color_formats.push_back(kRasterFormat);  // the half-widths
  d.depth_write = false;
  return vk::create_graphics_pipeline(ctx, d);
}

vk::Pipeline make_compute(vk::Context& ctx, std::string_view shader, std::size_t buffers, std::uint32_t push) {
  const std::vector<VkDescriptorType> b(buffers, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  return vk::create_compute_pipeline(ctx, shader, b, push);
}

vk::ExternalBuffer host_written(const vk::Buffer& b) {
  vk::ExternalBuffer e;
  e.buffer = b.get();
  e.initial = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
  return e;
}

// A buffer of at least 16 bytes (Vulkan refuses empty ones).
vk::Buffer make_buffer(vk::Context& ctx, std::size_t bytes, VkBufferUsageFlags usage, vk::MemoryUse use) {
  return vk::create_buffer(ctx, std::max<std::size_t>(bytes, 16), usage, use);
}

// The blur's sigma in a chart's texels. With sigma in model units, the variance the rest of the
// road adds is taken off, so that the whole has the Gaussian's variance sigma² per axis: the
// linear interpolation over the triangles (chart_interpolation_variance: the chart's own, derived in diffuse.hpp) and
// the bilinear read-back at the vertex (weights 1 - f and f at distances f and 1 - f texels from
// it: variance f (1 - f), 1/6 texel² over f uniform in [0, 1)). The rasterization point-samples the
// interpolant at texel centres (no spread of its own) and the box cascade's variance is the
// blur's. Tested on a flat grid with a quadratic field, whose Gaussian blur adds exactly twice
// the variance per axis (diffuse_test: the pipeline's total variance is the requested one).
float sigma_px_of(const Chart& chart, const DiffuseOptions& o, double interp_variance) {
  if (o.radius_px > 0.0f) return o.radius_px;
  const double tpu = chart.texels_per_unit;
  const double s = static_cast<double>(o.sigma) * tpu;
  return static_cast<float>(std::sqrt(std::max(s * s - interp_variance * tpu * tpu - 1.0 / 6.0, 0.0)));
}

void check_options(const DiffuseOptions& o) {
  const bool r = o.radius_px > 0.0f, s = o.sigma > 0.0f;
  if (o.steps > kMaxSteps)
    throw InputError("the diffusion's steps must be a whole number from 1 to " + std::to_string(kMaxSteps) + " (0: automatic)");
  if (!std::isfinite(o.radius_px) || !std::isfinite(o.sigma) || o.radius_px < 0.0f || o.sigma < 0.0f)
    throw InputError("the diffusion's radius and sigma must be finite and positive");
  if (r == s) throw InputError("texture-space diffusion needs exactly one of a radius in texels or a sigma in model units");
  if (r && !o.stretch)
    throw InputError("turning the stretch compensation off needs a sigma in model units (a radius in texels never stretches)");
}

// One of `steps` successive Gaussians whose variances add up to the whole's: the width over √steps.
DiffuseOptions step_options(const DiffuseOptions& o, std::uint32_t steps) {
  DiffuseOptions s = o;
  const float root = std::sqrt(static_cast<float>(steps));
  s.sigma = o.sigma / root;
  s.radius_px = o.radius_px / root;
  return s;
}

// DiffuseOptions::steps = 0: the fewest steps whose kernel (kBandSigmas step widths) fits inside
// the coverage around the typical vertex (the median over the vertices of what each needs,
// AtlasMapping::vertex_reach), but no step whose variance is below the mesh's interpolation
// variance (area-weighted mean of E(x), see triangle_blur_variance): that much of each step's
// variance the road itself adds, and the blur takes it off, so a narrower step would leave the
// typical triangle nothing to blur with and only repeat the interpolation. 1 without a reach.
// (Until 2026-11-29 the floor was the RMS edge, a variance of 8 E: on coarse meshes whose bands
// are short (pipe, joint, oblong, pinion: long triangles, charts as large as the kernel) it held
// the steps at 1-2 where the kernel needed tens to carry across the charts; bench/RESULTS.md.)
std::uint32_t auto_steps(const Mesh& mesh, const AtlasMapping& mapping, const DiffuseOptions& o, double interp_variance) {
  const std::size_t V = mesh.vertex_count();
  if (mapping.vertex_reach.size() != V || V == 0) return 1;
  std::vector<double> need(V), width(V);
  for (std::size_t v = 0; v < V; ++v) {
    const double tpu = mapping.charts[mapping.vertex_chart[v]].texels_per_unit;
    width[v] = o.sigma > 0.0f ? static_cast<double>(o.sigma) : (tpu > 0.0 ? o.radius_px / tpu : 0.0);
    const double reach = mapping.vertex_reach[v];
    need[v] = reach > 0.0 ? std::pow(kBandSigmas * width[v] / reach, 2.0) : static_cast<double>(kMaxSteps);
  }
  const double typical = quantile(std::move(need), 0.5);
  const double finest =
      interp_variance > 0.0 ? std::floor(std::pow(quantile(std::move(width), 0.5), 2.0) / interp_variance) : 1.0;
  const double n = std::min({std::ceil(typical - 1e-9), finest, static_cast<double>(kMaxSteps)});
  return static_cast<std::uint32_t>(std::max(n, 1.0));
}

// The map's Jacobian over an atlas triangle, dX/d(uv) = [x1 - x0, x2 - x0] · [uv1 - uv0, uv2 - uv0]^-1:
// its columns are the surface's steps (model units) per texel along the atlas's x and y. Both
// zero for a triangle degenerate in the atlas (the blur then takes its chart's mean scale).
struct TriangleMap {
  glm::dvec3 du{0.0}, dv{0.0};
};
TriangleMap triangle_map(const glm::vec3 (&x)[3], const glm::vec2 (&uv)[3]) {
  const glm::dvec3 e1 = glm::dvec3(x[1]) - glm::dvec3(x[0]), e2 = glm::dvec3(x[2]) - glm::dvec3(x[0]);
  const glm::dvec2 d1 = glm::dvec2(uv[1]) - glm::dvec2(uv[0]), d2 = glm::dvec2(uv[2]) - glm::dvec2(uv[0]);
  const double det = d1.x * d2.y - d1.y * d2.x;
  if (!(std::abs(det) > 1e-9)) return {};
  TriangleMap m{(e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det};
  const bool finite = std::isfinite(glm::length(m.du)) && std::isfinite(glm::length(m.dv));
  return finite ? m : TriangleMap{};
}

// Model units per texel along the atlas's x and y: the lengths of the map's columns.
glm::vec2 triangle_stretch(const TriangleMap& m) {
  return {static_cast<float>(glm::length(m.du)), static_cast<float>(glm::length(m.dv))};
}

// The stretch-compensated blur's variance left over a triangle along each atlas axis: sigma²
// less what the triangle's interpolation adds along that axis's surface direction (the map's
// column; the triangle's mean over both where the map is degenerate).
glm::vec2 triangle_blur_variance(const glm::vec3 (&x)[3], const TriangleMap& m, double sigma) {
  const double s2 = sigma * sigma;
  const double iso = triangle_interpolation_variance(x[0], x[1], x[2]);
  const auto left = [&](const glm::dvec3& column) {
    const double len = glm::length(column);
    const double e = len > 0.0 ? triangle_interpolation_variance_along(x[0], x[1], x[2], column / len) : iso;
    return static_cast<float>(std::max(s2 - e, 0.0));
  };
  return {left(m.du), left(m.dv)};
}

}  // namespace

std::array<std::uint32_t, 3> box_radii(float sigma_px) {
  if (!(sigma_px > 0.0f)) return {0, 0, 0};
  // Kovesi: n boxes of two odd widths wl and wl + 2, m of them the smaller, variance sigma².
  constexpr double n = 3.0;
  const double s2 = static_cast<double>(sigma_px) * sigma_px;
  const double ideal = std::sqrt(12.0 * s2 / n + 1.0);
  auto wl = static_cast<long>(std::floor(ideal));
  if (wl % 2 == 0) --wl;
  wl = std::max(wl, 1L);
  const double m_ideal = (12.0 * s2 - n * wl * wl - 4.0 * n * wl - 3.0 * n) / (-4.0 * wl - 4.0);
  const long m = std::clamp(std::lround(m_ideal), 0L, 3L);
  std::array<std::uint32_t, 3> r{};
  for (long i = 0; i < 3; ++i) r[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(((i < m ? wl : wl + 2) - 1) / 2);
  return r;
}

double triangle_interpolation_variance(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  const glm::dvec3 a(p0), b(p1), c(p2);
  return (glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c)) / 24.0;
}

double triangle_interpolation_variance_along(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::dvec3& d) {
  const glm::dvec3 a(p0), b(p1), c(p2);
  const double x = glm::dot(b - a, d), y = glm::dot(c - b, d), z = glm::dot(a - c, d);
  return (x * x + y * y + z * z) / 12.0;
}

double interpolation_variance(const Mesh& mesh) {
  double area = 0.0, sum = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t[0]]), b(mesh.positions[t[1]]), c(mesh.positions[t[2]]);
    const double ar = 0.5 * glm::length(glm::cross(b - a, c - a));
    area += ar;
    sum += ar * triangle_interpolation_variance(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]);
  }
  return area > 0.0 ? sum / area : 0.0;
}

std::vector<double> chart_interpolation_variance(const Mesh& mesh, const AtlasMapping& mapping) {
  std::vector<double> area(mapping.charts.size(), 0.0), sum(mapping.charts.size(), 0.0);
  for (const AtlasTriangle& t : mapping.triangles) {
    if (t.chart >= mapping.charts.size() || t.face >= mesh.face_count()) continue;  // validate_mapping's to report
    const Triangle& f = mesh.triangles[t.face];
    const glm::dvec3 a(mesh.positions[f[0]]), b(mesh.positions[f[1]]), c(mesh.positions[f[2]]);
    const double ar = 0.5 * glm::length(glm::cross(b - a, c - a));
    area[t.chart] += ar;
    sum[t.chart] += ar * triangle_interpolation_variance(mesh.positions[f[0]], mesh.positions[f[1]], mesh.positions[f[2]]);
  }
  const double whole = interpolation_variance(mesh);
  for (std::size_t c = 0; c < sum.size(); ++c) sum[c] = area[c] > 0.0 ? sum[c] / area[c] : whole;
  return sum;
}

BlurPlan plan_blur(const AtlasMapping& mapping, const DiffuseOptions& options, double interp_variance) {
  return plan_blur(mapping, options, std::vector<double>(mapping.charts.size(), interp_variance));
}

BlurPlan plan_blur(const AtlasMapping& mapping, const DiffuseOptions& options, std::span<const double> chart_interp_variance) {
  check_options(options);
  if (chart_interp_variance.size() != mapping.charts.size())
    throw InputError("the blur's plan needs one interpolation variance per chart");
  BlurPlan plan;
  bool axis_fused[2] = {false, false}, axis_cascade[2] = {false, false};
  plan.stretch = options.sigma > 0.0f && options.stretch;
  for (std::size_t ci = 0; ci < mapping.charts.size(); ++ci) {
    const Chart& c = mapping.charts[ci];
    auto r = box_radii(sigma_px_of(c, options, chart_interp_variance[ci]));
    // A periodic box no wider than the period (the shader wraps an index once at most).
    if (c.wraps_x)
      for (std::uint32_t& x : r) x = std::min(x, c.width > 1 ? (c.width - 1) / 2 : 0u);
    plan.radii.push_back(r);
    plan.line_jobs += std::uint64_t{c.width} + c.height;
    std::array<bool, 2> fused{};
    for (int axis = 0; axis < 2; ++axis) {
      const std::uint64_t n = axis == 0 ? c.width : c.height, lines = axis == 0 ? c.height : c.width;
      const bool wrap = axis == 0 && c.wraps_x;
      const std::uint64_t e[3] = {r[0], r[1], r[2]};
      const std::uint64_t overrun = wrap ? 2 * (e[0] + e[1] + e[2]) : e[1] + e[2];
      // A short line runs whole in private memory (any radius); a longer one streams whenever
      // its radii fit the rings, however long its overrun against the line: the same dispatches
      // at every radius up to kFusedMaxRadius (a wrapping row's overrun read once still costs
      // less than the cascade's three boxes, which read the whole line twice each).
      const bool whole = n <= passes::kShortLine;
      fused[static_cast<std::size_t>(axis)] =
          options.fused_blur && !plan.stretch && (whole || std::max({e[0], e[1], e[2]}) <= passes::kFusedMaxRadius);
      if (fused[static_cast<std::size_t>(axis)]) {
        // Every texel read once (a streamed line: what leaves box 0's window comes from a ring); a
        // streamed wrapping row also reads its overrun (a plain line reads nothing outside itself).
        plan.texel_reads += lines * (n + (wrap && !whole ? overrun : 0));
        plan.fused_lines += lines;
        axis_fused[axis] = true;
      } else if (plan.stretch) {
        // Per box and texel: the prefix walk's read, then the half-width, two prefix sums and the
        // two fractional end texels, whatever the widths.
        plan.texel_reads += lines * 3 * 6 * n;
        plan.cascade_lines += lines;
        axis_cascade[axis] = true;
      } else {
        for (int b = 0; b < 3; ++b) plan.texel_reads += lines * (2 * n + 2ull * r[static_cast<std::size_t>(b)] + 1);
        plan.cascade_lines += lines;
        axis_cascade[axis] = true;
      }
    }
    plan.fused.push_back(fused);
  }
  for (int axis = 0; axis < 2; ++axis) plan.dispatches += (axis_fused[axis] ? 1u : 0u) + (axis_cascade[axis] ? 3u : 0u);
  return plan;
}

void validate_mapping(const Mesh& mesh, const AtlasMapping& m) {
  const std::size_t V = mesh.vertex_count();
  if (m.size == 0) throw InputError("the atlas is empty (size 0)");
  if (m.vertex_chart.size() != V || m.vertex_uv.size() != V)
    throw InputError("the atlas mapping has " + std::to_string(m.vertex_chart.size()) + " vertex charts and " +
                     std::to_string(m.vertex_uv.size()) + " vertex uvs for a mesh of " + std::to_string(V) +
                     " vertices");
  for (std::size_t c = 0; c < m.charts.size(); ++c) {
    const Chart& ch = m.charts[c];
    if (ch.width == 0 || ch.height == 0 || std::uint64_t{ch.x0} + ch.width > m.size ||
        std::uint64_t{ch.y0} + ch.height > m.size)
      throw InputError("chart " + std::to_string(c) + "'s rectangle is empty or leaves the " +
                       std::to_string(m.size) + "² atlas");
    if (!std::isfinite(ch.texels_per_unit) || ch.texels_per_unit < 0.0f)
      throw InputError("chart " + std::to_string(c) + " has no valid scale (texels_per_unit)");
  }
  const auto inside = [&](const Chart& ch, glm::vec2 uv, float slack) {
    return uv.x >= static_cast<float>(ch.x0) - slack && uv.y >= static_cast<float>(ch.y0) - slack &&
           uv.x <= static_cast<float>(ch.x0 + ch.width) + slack && uv.y <= static_cast<float>(ch.y0 + ch.height) + slack;
  };
  for (std::size_t v = 0; v < V; ++v) {
    const std::uint32_t c = m.vertex_chart[v];
    if (c >= m.charts.size())
      throw InputError("vertex " + std::to_string(v) + " reads back from chart " + std::to_string(c) + " of " +
                       std::to_string(m.charts.size()));
    if (!inside(m.charts[c], m.vertex_uv[v], 0.01f))
      throw InputError("vertex " + std::to_string(v) + "'s uv lies outside its chart " + std::to_string(c));
  }
  std::uint32_t next = 0;  // the samples: sorted by vertex, every vertex at least one
  for (std::size_t i = 0; i < m.samples.size(); ++i) {
    const VertexSample& s = m.samples[i];
    const auto which = [&] { return "sample " + std::to_string(i) + " (vertex " + std::to_string(s.vertex) + ")"; };
    if (s.vertex >= V || s.vertex + 1 < next || s.vertex > next)
      throw InputError(which() + ": the samples must name every vertex, in order");
    next = s.vertex + 1;
    if (s.chart >= m.charts.size()) throw InputError(which() + " reads from a chart that does not exist");
    if (!inside(m.charts[s.chart], s.uv, 0.01f)) throw InputError(which() + "'s uv lies outside its chart");
    if (!(s.weight > 0.0f) || !std::isfinite(s.weight)) throw InputError(which() + "'s weight is not finite and positive");
  }
  if (!m.samples.empty() && next != V) throw InputError("the samples must name every vertex, in order");
  if (!m.vertex_reach.empty() && m.vertex_reach.size() != V)
    throw InputError("the atlas mapping has " + std::to_string(m.vertex_reach.size()) + " vertex reaches for a mesh of " +
                     std::to_string(V) + " vertices");
  for (std::size_t v = 0; v < m.vertex_reach.size(); ++v)
    if (!(m.vertex_reach[v] >= 0.0f) || !std::isfinite(m.vertex_reach[v]))
      throw InputError("vertex " + std::to_string(v) + "'s reach is not finite and non-negative");
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const AtlasTriangle& tri = m.triangles[t];
    if (tri.chart >= m.charts.size() || tri.face >= mesh.face_count())
      throw InputError("atlas triangle " + std::to_string(t) + " names chart " + std::to_string(tri.chart) +
                       " / face " + std::to_string(tri.face) + " that do not exist");
    const Chart& ch = m.charts[tri.chart];
    // A wrapping chart's triangle may reach a width beyond its rectangle (across the seam).
    const float slack = ch.wraps_x ? static_cast<float>(ch.width) : 0.01f;
    for (const glm::vec2& uv : tri.uv)
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y) || !inside(ch, uv, slack))
        throw InputError("atlas triangle " + std::to_string(t) + " has a corner outside its chart " +
                         std::to_string(tri.chart));
  }
}

int kring_for_sigma(float sigma, float mean_edge) {
  if (!(sigma > 0.0f) || !(mean_edge > 0.0f)) return 1;
  return std::max(1, static_cast<int>(std::ceil(2.0f * sigma / mean_edge - 1e-4f)));
}

struct Diffuser::Impl {
  explicit Impl(vk::Context& c)
      : ctx(c),
        raster(make_raster_pipeline(c, false)),
        raster_stretch(make_raster_pipeline(c, true)),
        blur(make_compute(c, "atlas_blur.comp", 4, sizeof(passes::BlurPush))),
        blur_box(make_compute(c, "atlas_blur_box.comp", 4, sizeof(passes::BlurPush))),
        blur_stretch(make_compute(c, "atlas_blur_stretch.comp", 6, sizeof(passes::StretchBlurPush))),
        sample(make_compute(c, "atlas_sample.comp", 5, sizeof(passes::SamplePush))),
        dilate(make_compute(c, "atlas_dilate.comp", 3, sizeof(passes::DilatePush))),
        transients(c) {}
  vk::Context& ctx;
  vk::Pipeline raster, raster_stretch, blur, blur_box, blur_stretch, sample, dilate;
  vk::TransientPool transients;
};

Diffuser::Diffuser(vk::Context& ctx) : impl_(std::make_unique<Impl>(ctx)) {}
Diffuser::~Diffuser() = default;

DiffuseResult Diffuser::run(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> values,
                            const DiffuseOptions& options) {
  const auto start = Clock::now();
  vk::Context& ctx = impl_->ctx;
  check_options(options);
  validate_mapping(mesh, mapping);
  const std::size_t V = mesh.vertex_count();
  if (values.size() != V)
    throw InputError("diffusion of " + std::to_string(values.size()) + " values on a mesh of " + std::to_string(V) +
                     " vertices");
  for (std::size_t v = 0; v < V; ++v)
    if (!std::isfinite(values[v])) throw InputError("vertex " + std::to_string(v) + "'s value is not finite");
  const std::uint32_t size = mapping.size;
  const std::uint32_t max_side = ctx.capabilities().max_image_dimension_2d;
  const VkDeviceSize texel_bytes = passes::tiled_texel_bytes(size);
  if ((max_side && size > max_side) ||
      (ctx.capabilities().max_storage_buffer_range && texel_bytes > ctx.capabilities().max_storage_buffer_range))
    throw DeviceError("a " + std::to_string(size) + "² atlas is larger than the device allows");

  DiffuseResult result;
  const double mesh_interp = options.sigma > 0.0f || options.steps == 0 ? interpolation_variance(mesh) : 0.0;
  const double interp_variance = options.sigma > 0.0f ? mesh_interp : 0.0;
  // The interpolation's variance is local (the kernel's mean of E(x) around the vertex read
  // back): per chart for one width per chart, per triangle for the stretch-compensated blur.
  // A mesh-wide mean would take a coarse part's large triangles' variance off a fine part's blur
  // (a CAD part's long flat-face triangles: sqrt(mean) 1.1-1.6 mean edges on anchor, helmet,
  // couplingdown, turbine, oblong, spool, so no blur at all there at sigma = 1 edge).
  const std::vector<double> chart_interp =
      options.sigma > 0.0f ? chart_interpolation_variance(mesh, mapping) : std::vector<double>(mapping.charts.size(), 0.0);
  // The Gaussian as `steps` Gaussians of 1/steps its variance, one after another.
  result.steps = options.steps > 0 ? options.steps : auto_steps(mesh, mapping, options, mesh_interp);
  const DiffuseOptions step = step_options(options, result.steps);
  result.plan = plan_blur(mapping, step, std::span<const double>(chart_interp));
  // The stretch blur's prefix sums take two texel buffers' bytes (vec4 per texel).
  if (result.plan.stretch && ctx.capabilities().max_storage_buffer_range &&
      2 * texel_bytes > ctx.capabilities().max_storage_buffer_range)
    throw DeviceError("a " + std::to_string(size) + "² atlas is larger than the device allows for the stretch-compensated blur's prefix sums");

  // Chart table.
  std::vector<passes::GpuChart> charts;
  charts.reserve(mapping.charts.size());
  for (std::size_t c = 0; c < mapping.charts.size(); ++c) {
    const Chart& ch = mapping.charts[c];
    const auto& r = result.plan.radii[c];
    const float metric = ch.texels_per_unit > 0.0f ? 1.0f / ch.texels_per_unit : 1.0f;
    charts.push_back({glm::uvec4(ch.x0, ch.y0, ch.width, ch.height), glm::uvec4(r[0], r[1], r[2], ch.wraps_x ? 1u : 0u),
                      glm::vec4(metric, 0.0f, 0.0f, 0.0f)});
  }
  vk::Buffer chart_buf = make_buffer(ctx, charts.size() * sizeof(passes::GpuChart), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     vk::MemoryUse::Upload);
  if (!charts.empty()) std::memcpy(chart_buf.mapped(), charts.data(), charts.size() * sizeof(passes::GpuChart));

  // Triangle soup: a triangle of a wrapping chart is unwrapped around its first corner and drawn
  // at every shift by the chart's width that reaches the rectangle (the shader clips). Written
  // straight into its upload buffer, triangles in parallel, each at its offset in mapping order:
  // a host vector first cost more than all the rest of this preparation on large meshes (its
  // growth past the reserve for the shifted copies, the first touch of its pages, the copy).
  const auto unwrapped = [&](const AtlasTriangle& t, glm::vec2 (&uv)[3]) {
    uv[0] = t.uv[0], uv[1] = t.uv[1], uv[2] = t.uv[2];
    const Chart& ch = mapping.charts[t.chart];
    if (!ch.wraps_x) return std::pair{0, 0};  // drawn once, unshifted
    const float w = static_cast<float>(ch.width);
    for (int k = 1; k < 3; ++k) {
      while (uv[k].x - uv[0].x > 0.5f * w) uv[k].x -= w;
      while (uv[0].x - uv[k].x > 0.5f * w) uv[k].x += w;
    }
    const float lo = std::min({uv[0].x, uv[1].x, uv[2].x}), hi = std::max({uv[0].x, uv[1].x, uv[2].x});
    int first = 3, last = -3;  // the shifts s * width, s in [-2, 2], that reach the rectangle
    for (int sh = -2; sh <= 2; ++sh) {
      const float shift = static_cast<float>(sh) * w;
      if (hi + shift <= static_cast<float>(ch.x0) || lo + shift >= static_cast<float>(ch.x0) + w) continue;
      first = std::min(first, sh), last = std::max(last, sh);
    }
    return std::pair{first, last};
  };
  const std::size_t T = mapping.triangles.size();
  std::vector<std::size_t> soup_offset(T + 1, 0);
  for (std::size_t i = 0; i < T; ++i) {
    glm::vec2 uv[3];
    const auto [first, last] = unwrapped(mapping.triangles[i], uv);  // (0, 0): one copy
    soup_offset[i + 1] = soup_offset[i] + 3 * static_cast<std::size_t>(std::max(0, last - first + 1));
  }
  const std::size_t soup_vertices = soup_offset[T];
  vk::Buffer soup_buf = make_buffer(ctx, soup_vertices * sizeof(passes::RasterVertex),
                                    VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    vk::MemoryUse::Upload);
  auto* soup = static_cast<passes::RasterVertex*>(soup_buf.mapped());
  parallel_for(T, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const AtlasTriangle& t = mapping.triangles[i];
      const auto& face = mesh.triangles[t.face];
      glm::vec2 uv[3];
      const auto [first, last] = unwrapped(t, uv);
      const glm::vec3 x[3] = {mesh.positions[face[0]], mesh.positions[face[1]], mesh.positions[face[2]]};
      // The map's stretch, and the stretch blur's variance over this triangle per atlas axis:
      // sigma² less what its own interpolation adds along that axis.
      const TriangleMap map = triangle_map(x, uv);
      const glm::vec2 st = triangle_stretch(map);
      const glm::vec2 var = step.sigma > 0.0f ? triangle_blur_variance(x, map, static_cast<double>(step.sigma)) : glm::vec2(0.0f);
      passes::RasterVertex* out = soup + soup_offset[i];
      if (!mapping.charts[t.chart].wraps_x) {
        for (int k = 0; k < 3; ++k) *out++ = {uv[k], face[k], t.chart, st, var};
        continue;
      }
      const float w = static_cast<float>(mapping.charts[t.chart].width);
      for (int sh = first; sh <= last; ++sh)
        for (int k = 0; k < 3; ++k) *out++ = {uv[k] + glm::vec2(static_cast<float>(sh) * w, 0.0f), face[k], t.chart, st, var};
    }
  }, 4096);

  // Line jobs of the blur: the rows of the charts whose rows are fused, the other rows, then the
  // columns likewise (passes/atlas_passes.hpp AtlasBlurPass).
  std::vector<glm::uvec2> jobs;
  jobs.reserve(result.plan.line_jobs);
  std::uint32_t counts[4] = {};
  for (int axis = 0; axis < 2; ++axis)
    for (int want_fused = 1; want_fused >= 0; --want_fused) {
      const std::size_t before = jobs.size();
      for (std::uint32_t c = 0; c < charts.size(); ++c) {
        if (result.plan.fused[c][static_cast<std::size_t>(axis)] != (want_fused == 1)) continue;
        const std::uint32_t lines = axis == 0 ? mapping.charts[c].height : mapping.charts[c].width;
        for (std::uint32_t l = 0; l < lines; ++l) jobs.emplace_back(c, l);
      }
      counts[2 * axis + (1 - want_fused)] = static_cast<std::uint32_t>(jobs.size() - before);
    }
  vk::Buffer job_buf = make_buffer(ctx, jobs.size() * sizeof(glm::uvec2), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                   vk::MemoryUse::Upload);
  if (!jobs.empty()) std::memcpy(job_buf.mapped(), jobs.data(), jobs.size() * sizeof(glm::uvec2));

  // Vertex queries and the read-back buffers.
  // Vertex queries (the mapping's samples, or each vertex's own chart alone), their ranges per
  // vertex, and the read-back buffers.
  const bool blended = !mapping.samples.empty();
  const std::size_t Q = blended ? mapping.samples.size() : V;
  vk::Buffer query_buf = make_buffer(ctx, Q * sizeof(passes::SampleQuery), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     vk::MemoryUse::Upload);
  vk::Buffer range_buf = make_buffer(ctx, V * sizeof(passes::SampleRange), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     vk::MemoryUse::Upload);
  auto* q = static_cast<passes::SampleQuery*>(query_buf.mapped());
  auto* ranges = static_cast<passes::SampleRange*>(range_buf.mapped());
  if (blended) {
    for (std::size_t i = 0; i < Q; ++i) {
      const VertexSample& s = mapping.samples[i];
      q[i] = {s.uv, s.chart, s.weight};
    }
    std::size_t i = 0;
    for (std::size_t v = 0; v < V; ++v) {
      const std::size_t first = i;
      while (i < Q && mapping.samples[i].vertex == v) ++i;
      ranges[v] = {static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(i - first)};
    }
  } else {
    for (std::size_t v = 0; v < V; ++v) {
      q[v] = {mapping.vertex_uv[v], mapping.vertex_chart[v], 1.0f};
      ranges[v] = {static_cast<std::uint32_t>(v), 1u};
    }
  }
  // The field in, each step's read-back over it, the result out (host-coherent both ways).
  vk::Buffer value_buf = make_buffer(ctx, V * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback);
  if (V) std::memcpy(value_buf.mapped(), values.data(), V * sizeof(float));
  vk::Buffer atlas_buf;
  if (options.keep_atlas)
    atlas_buf = make_buffer(ctx, VkDeviceSize{size} * size * sizeof(float),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  result.timings.prepare = ms_since(start);

  // The graph.
  vk::RenderGraph graph;
  const auto chart_h = graph.import_buffer("atlas.charts", chart_buf.size, host_written(chart_buf));
  const auto soup_h = graph.import_buffer("atlas.triangles", soup_buf.size, host_written(soup_buf));
  const auto job_h = graph.import_buffer("atlas.blur_jobs", job_buf.size, host_written(job_buf));
  const auto query_h = graph.import_buffer("atlas.queries", query_buf.size, host_written(query_buf));
  const auto range_h = graph.import_buffer("atlas.ranges", range_buf.size, host_written(range_buf));
  const auto value_h = graph.import_buffer("atlas.values", value_buf.size, host_written(value_buf));
  const auto target = graph.create_image("atlas.raster", {kRasterFormat, size, size, 1});
  // The half-widths exist only for a stretch-compensated blur (a radius in texels, or no blur,
  // never reads them).
  const bool with_stretch = result.plan.stretch && options.blur;
  const auto stretch_target =
      with_stretch ? graph.create_image("atlas.raster.stretch", {kRasterFormat, size, size, 1}) : vk::ImageHandle{};
  const auto stretch = with_stretch ? graph.create_buffer("atlas.stretch", VkDeviceSize{size} * size * sizeof(glm::vec2))
                                    : vk::BufferHandle{};
  const auto texels = graph.create_buffer("atlas.texels", texel_bytes);
  const auto scratch = graph.create_buffer("atlas.scratch", texel_bytes);

  passes::AtlasRasterPass rp;
  rp.pipeline = with_stretch ? &impl_->raster_stretch : &impl_->raster;
  rp.target = target;
  rp.stretch_target = stretch_target;
  rp.vertices = soup_h;
  rp.charts = chart_h;
  rp.texels = texels;
  rp.stretch = stretch;
  rp.vertex_count = static_cast<std::uint32_t>(soup_vertices);
  rp.size = size;

  passes::AtlasBlurPass bp;
  bp.pipeline = &impl_->blur;
  bp.box_pipeline = &impl_->blur_box;
  if (with_stretch) {
    bp.stretch_pipeline = &impl_->blur_stretch;
    bp.prefix = graph.create_buffer("atlas.prefix", 2 * texel_bytes);  // vec4 per texel: (hi, lo)
    bp.variance = static_cast<float>(std::max(static_cast<double>(step.sigma) * step.sigma - interp_variance, 0.0));
  }
  bp.scratch = scratch;
  bp.charts = chart_h;
  bp.jobs = job_h;
  bp.rows_fused = counts[0];
  bp.rows_cascade = counts[1];
  bp.columns_fused = counts[2];
  bp.columns_cascade = counts[3];
  bp.size = size;

  passes::AtlasSamplePass sp;
  sp.pipeline = &impl_->sample;
  sp.charts = chart_h;
  sp.queries = query_h;
  sp.ranges = range_h;
  sp.values = value_h;
  sp.vertex_count = static_cast<std::uint32_t>(V);
  sp.size = size;

  // Each step rasterizes the values the last one read back, so the overlap bands carry the
  // neighbouring charts' blurred values into the next blur (DiffuseOptions::steps).
  // The half-widths depend on the map alone: the first step draws them, the others only values.
  vk::BufferHandle blurred;
  for (std::uint32_t k = 0; k < result.steps; ++k) {
    rp.values = sp.values;
    const passes::AtlasRasterOutput rastered = passes::add_atlas_raster_pass(graph, rp);
    rp.pipeline = &impl_->raster;
    rp.target = rastered.target;
    rp.stretch_target = {};
    if (k == 0) bp.stretch = rastered.stretch;
    blurred = rastered.texels;
    if (options.blur) {
      bp.texels = rastered.texels;
      const passes::AtlasBlurOutput out = passes::add_atlas_blur_passes(graph, bp);
      blurred = out.texels;
      bp.scratch = out.scratch;
      bp.prefix = out.prefix;
    }
    rp.texels = blurred;
    sp.texels = blurred;
    sp.values = passes::add_atlas_sample_pass(graph, sp);
  }

  if (options.keep_atlas) {
    passes::AtlasDilatePass dp;
    dp.pipeline = &impl_->dilate;
    dp.texels = blurred;
    dp.charts = chart_h;
    dp.atlas = graph.import_buffer("atlas.dilated", atlas_buf.size, {atlas_buf.get()});
    dp.chart_count = static_cast<std::uint32_t>(charts.size());
    dp.size = size;
    dp.margin = mapping.gutter / 2;
    dp.charts_host = &charts;
    passes::add_atlas_dilate_pass(graph, dp);
  }

  const auto exec_start = Clock::now();
  vk::ExecuteOptions eo;
  eo.profile = options.profile;
  const vk::CompiledGraph compiled = graph.compile();
  for (std::size_t r = 0; r < compiled.resource_names.size(); ++r)
    if (compiled.physical_of[r] != UINT32_MAX) result.graph_resources.push_back(compiled.resource_names[r]);
  const std::vector<vk::PassTiming> timings = vk::execute(ctx, compiled, impl_->transients, eo);
  result.timings.execute = ms_since(exec_start);
  for (const vk::PassTiming& t : timings) {
    const std::string_view name = t.pass;
    if (name.starts_with("atlas.raster")) result.timings.raster += t.gpu_milliseconds;
    else if (name.starts_with("atlas.blur")) result.timings.blur += t.gpu_milliseconds;
    else result.timings.sample += t.gpu_milliseconds;
  }

  const auto read_start = Clock::now();
  result.values.resize(V);
  if (V) std::memcpy(result.values.data(), value_buf.mapped(), V * sizeof(float));
  if (options.keep_atlas) {
    result.atlas.resize(std::size_t{size} * size);
    std::memcpy(result.atlas.data(), atlas_buf.mapped(), result.atlas.size() * sizeof(float));
  }
  result.timings.readback = ms_since(read_start);
  if (options.conserve) conserve_integral(mesh, values, result.values);  // also without the blur: the benchmark's baseline pays it too
  result.timings.total = ms_since(start);
  return result;
}

void conserve_integral(const Mesh& mesh, std::span<const float> input, std::span<float> result) {
  const std::size_t V = mesh.vertex_count();
  if (input.size() != V || result.size() != V)
    throw InputError("conserve_integral: " + std::to_string(input.size()) + " and " + std::to_string(result.size()) +
                     " values on a mesh of " + std::to_string(V) + " vertices");
  const std::vector<double> area = lumped_mass(mesh);
  UnionFind pieces(V);
  for (const Triangle& t : mesh.triangles) pieces.unite(t[0], t[1]), pieces.unite(t[1], t[2]);
  // Per piece: area, the input's integral and range, the integral of input - result.
  struct Piece {
    double area = 0.0, integral = 0.0, difference = 0.0, lo = std::numeric_limits<double>::infinity(),
           hi = -std::numeric_limits<double>::infinity();
    bool clamped = false;
  };
  std::vector<std::uint32_t> id(V, UINT32_MAX);  // per vertex of positive area: its piece
  std::vector<Piece> piece;
  {
    std::vector<std::uint32_t> of_root(V, UINT32_MAX);
    for (std::uint32_t v = 0; v < V; ++v) {
      if (!(area[v] > 0.0)) continue;
      std::uint32_t& k = of_root[pieces.find(v)];
      if (k == UINT32_MAX) k = static_cast<std::uint32_t>(piece.size()), piece.emplace_back();
      id[v] = k;
      Piece& p = piece[k];
      p.area += area[v];
      p.integral += area[v] * input[v];
      p.difference += area[v] * (static_cast<double>(input[v]) - result[v]);
      p.lo = std::min(p.lo, static_cast<double>(input[v]));
      p.hi = std::max(p.hi, static_cast<double>(input[v]));
    }
  }
  // The nearest field (area-weighted) with the input's integral that stays in the input's range
  // (heat flow keeps both) is clamp(result + c, lo, hi) for the c that gives the integral (the
  // Lagrange condition of that projection). Without a clamp, c is the mean difference; a value
  // out of range by float rounding only is clamped without searching c again.
  std::vector<double> shift(piece.size());
  for (std::size_t k = 0; k < piece.size(); ++k) shift[k] = piece[k].difference / piece[k].area;
  for (std::uint32_t v = 0; v < V; ++v) {
    if (id[v] == UINT32_MAX) continue;
    Piece& p = piece[id[v]];
    const double x = result[v] + shift[id[v]], slack = 1e-6 * std::max({p.hi - p.lo, std::abs(p.lo), std::abs(p.hi)});
    p.clamped |= x < p.lo - slack || x > p.hi + slack;
  }
  // The vertices of the pieces that need a clamp, grouped by piece (one pass, whatever their number).
  std::vector<std::uint32_t> first(piece.size() + 1, 0), grouped;
  for (std::uint32_t v = 0; v < V; ++v)
    if (id[v] != UINT32_MAX && piece[id[v]].clamped) ++first[id[v] + 1];
  for (std::size_t k = 0; k < piece.size(); ++k) first[k + 1] += first[k];
  grouped.resize(first.back());
  {
    std::vector<std::uint32_t> at(first.begin(), first.end() - 1);
    for (std::uint32_t v = 0; v < V; ++v)
      if (id[v] != UINT32_MAX && piece[id[v]].clamped) grouped[at[id[v]]++] = v;
  }
  for (std::uint32_t k = 0; k < piece.size(); ++k) {
    const Piece& p = piece[k];
    if (!p.clamped) continue;
    const std::span<const std::uint32_t> vertices(grouped.data() + first[k], first[k + 1] - first[k]);
    // The integral at c is non-decreasing in c, from area * lo to area * hi, and the input's lies
    // between: bisection.
    double below = std::numeric_limits<double>::infinity(), above = -below;
    for (std::uint32_t v : vertices) below = std::min(below, p.lo - result[v]), above = std::max(above, p.hi - result[v]);
    for (int i = 0; i < 100 && above - below > 1e-12 * std::max(1.0, std::abs(above) + std::abs(below)); ++i) {
      const double mid = 0.5 * (below + above);
      double at = 0.0;
      for (std::uint32_t v : vertices) at += area[v] * std::clamp(result[v] + mid, p.lo, p.hi);
      (at < p.integral ? below : above) = mid;
    }
    shift[k] = 0.5 * (below + above);
  }
  for (std::uint32_t v = 0; v < V; ++v)
    if (id[v] != UINT32_MAX)
      result[v] = static_cast<float>(std::clamp(result[v] + shift[id[v]], piece[id[v]].lo, piece[id[v]].hi));
}

std::vector<float> diffuse(vk::Context& ctx, const Mesh& mesh, const AtlasMapping& mapping,
                           std::span<const float> vertex_values, const DiffuseOptions& options) {
  Diffuser d(ctx);
  return d.run(mesh, mapping, vertex_values, options).values;
}

}  // namespace sdfkit::diffusion
