#pragma once
// The texture-space diffusion's render-graph passes (sdfkit::diffusion::Diffuser), one file each:
// atlas_raster.cpp, atlas_blur.cpp, atlas_sample.cpp, atlas_dilate.cpp. Like the other passes
// they take handles, declare their uses, bind through what they declared and return the handles
// they wrote. The push-constant structs mirror the GLSL blocks (tests/vulkan/push_constants_test).

#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace sdfkit::diffusion::passes {

// One chart as the shaders see it (std430): rect = x0, y0, width, height (texels);
// params = the three box radii of the blur, wraps_x; metric.x = the chart's mean model units per
// texel (1 / texels_per_unit), what the stretch-compensated blur assumes where no triangle drew a
// stretch.
struct GpuChart {
  glm::uvec4 rect;
  glm::uvec4 params;
  glm::vec4 metric;
};
static_assert(sizeof(GpuChart) == 48);

// One corner of a rasterized atlas triangle (atlas_raster.vert's vertex input).
struct RasterVertex {
  glm::vec2 uv;        // atlas texels
  std::uint32_t vertex;  // the mesh vertex whose value the corner carries (AtlasRasterPass::values)
  std::uint32_t chart; // fragments outside this chart's rectangle are discarded
  glm::vec2 stretch;   // the triangle's |dX/du|, |dX/dv|: model units per texel along the atlas's x and y
  // The Gaussian's variance left for the stretch-compensated blur over this triangle along the
  // atlas's x and y, model units²: sigma² less the variance the triangle's own linear
  // interpolation adds along each axis's surface direction
  // (diffusion::triangle_interpolation_variance_along), so a mesh's fine and coarse parts, and a
  // long thin triangle's two directions, each get what they lack of sigma². 0 for a blur of one
  // width in texels (unused there).
  glm::vec2 variance;
};
static_assert(sizeof(RasterVertex) == 32);

// One read of a vertex's value (atlas_sample.comp): AtlasMapping's VertexSample.
struct SampleQuery {
  glm::vec2 uv;        // atlas texels
  std::uint32_t chart;
  float weight;
};
static_assert(sizeof(SampleQuery) == 16);
// A vertex's reads: queries [first, first + count), blended by weight.
struct SampleRange {
  std::uint32_t first, count;
};
static_assert(sizeof(SampleRange) == 8);

struct RasterPush {  // atlas_raster.vert, atlas_raster.frag
  glm::vec4 scale;   // x: 2 / atlas size (the blur's variance per triangle is RasterVertex::variance)
};
struct BlurPush {    // atlas_blur.comp, atlas_blur_box.comp
  std::uint32_t job_offset, job_count, size, axis, box, src_tiled;
};
struct StretchBlurPush {  // atlas_blur_stretch.comp
  std::uint32_t job_offset, job_count, size, axis, box, src_tiled;
  float variance;    // the Gaussian's variance per axis left for the blur, model units²
};

// Bytes of a tiled texel buffer (glsl/atlas_common.glsl: 64² tiles of vec2) of a size² atlas.
inline std::uint64_t tiled_texel_bytes(std::uint32_t size) {
  const std::uint64_t tiles = (size + 63u) / 64u;
  return tiles * tiles * 64u * 64u * 8u;
}
struct SamplePush {  // atlas_sample.comp
  std::uint32_t vertex_count, size;
};
struct DilatePush {  // atlas_dilate.comp
  std::uint32_t chart, size, reach, margin;
};

// Rasterizes `vertex_count` RasterVertex corners, each carrying the value of its mesh vertex in
// `values` (one float per mesh vertex), into `target` (RG32F, cleared to 0: value, coverage) and,
// when `stretch_target` is valid, into it (RG32F, cleared to -1: the stretch-compensated blur's
// box half-widths along x and y for each triangle's RasterVertex::variance, from its stretch;
// glsl/atlas_common.glsl stretch_half_width), and copies them into `texels` and `stretch` (size²
// vec2, row-major). `pipeline` has two colour attachments then
// (atlas_raster.frag), else one (atlas_raster_value.frag) and `stretch` is neither written nor
// returned (a blur with one width in texels never reads it). Returns the written buffers.
struct AtlasRasterPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle target, stretch_target;
  vk::BufferHandle vertices, values, charts, texels, stretch;
  std::uint32_t vertex_count = 0, size = 0;
};
// The versions the pass wrote: the buffers, and the render targets (which a later step's raster
// pass clears and draws again).
struct AtlasRasterOutput {
  vk::BufferHandle texels, stretch;
  vk::ImageHandle target, stretch_target;
};
AtlasRasterOutput add_atlas_raster_pass(vk::RenderGraph& graph, const AtlasRasterPass& pass);

// The separable Gaussian: three boxes along x (rows), then three along y (columns), between
// `texels` (read row-major by the first passes) and `scratch`, both tiled_texel_bytes. Each line
// goes one of two ways, chosen per chart and axis by plan_blur: fused (atlas_blur.comp,
// `pipeline`: the three boxes in one dispatch, a short line whole in private memory, a long one
// streamed with its windows through ring buffers) or the cascade
// (atlas_blur_box.comp, `box_pipeline`: one dispatch per box, ping-ponging). The jobs (uvec2
// chart, line) lie in this order: fused rows, cascade rows, fused columns, cascade columns. Both
// ways end each axis in the same buffer, so an axis is a fused dispatch and three cascade
// dispatches over disjoint charts, each left out when it has no line. Returns the blurred, tiled
// texel buffer (a version of `texels`) and the versions of `scratch` and `prefix` it left (what a
// later step's blur writes again).
//
// Stretch-compensated (`stretch_pipeline` set, glsl/atlas_blur_stretch.comp, every line in the
// cascade, no fused lines): each box's width is chosen per output texel from the raster pass's
// `stretch` (the half-widths from the map's model units per texel along the axis there), so that
// the three boxes have the variance `variance` (model units²) in model units wherever the chart's
// map stretches.
struct AtlasBlurPass {
  const vk::Pipeline* pipeline = nullptr;
  const vk::Pipeline* box_pipeline = nullptr;
  const vk::Pipeline* stretch_pipeline = nullptr;
  vk::BufferHandle texels, scratch, charts, jobs, stretch;
  vk::BufferHandle prefix;  // stretch-compensated: the lines' prefix sums, vec4 (hi, lo) per texel (2 · tiled_texel_bytes)
  std::uint32_t rows_fused = 0, rows_cascade = 0, columns_fused = 0, columns_cascade = 0, size = 0;
  float variance = 0.0f;
};
struct AtlasBlurOutput {
  vk::BufferHandle texels, scratch, prefix;
};
AtlasBlurOutput add_atlas_blur_passes(vk::RenderGraph& graph, const AtlasBlurPass& pass);
// The largest box radius the fused shader's rings hold (glsl/atlas_blur.comp kRing = 256 >=
// 2 · 127 + 1).
inline constexpr std::uint32_t kFusedMaxRadius = 127;
// Lines up to this many texels the fused shader runs whole in private memory, at any radius.
inline constexpr std::uint32_t kShortLine = 256;

// Per vertex: the weighted mean of the normalized bilinear reads of the blurred texels at its
// queries (`ranges`: one SampleRange per vertex), written over its value in `values` (which it
// keeps where no covered texel reaches any of its queries). Returns the new version of `values`,
// which the next step's raster pass can read (DiffuseOptions::steps).
struct AtlasSamplePass {
  const vk::Pipeline* pipeline = nullptr;
  vk::BufferHandle texels, charts, queries, ranges, values;
  std::uint32_t vertex_count = 0, size = 0;
};
vk::BufferHandle add_atlas_sample_pass(vk::RenderGraph& graph, const AtlasSamplePass& pass);

// The normalized atlas (size² floats, NaN outside every chart's reach): each chart's rectangle
// and `margin` texels around it, uncovered texels from the nearest covered one within `reach`.
struct AtlasDilatePass {
  const vk::Pipeline* pipeline = nullptr;
  vk::BufferHandle texels, charts, atlas;
  std::uint32_t chart_count = 0, size = 0, reach = 4, margin = 1;
  const std::vector<GpuChart>* charts_host = nullptr;  // rectangles, for the dispatch sizes
};
vk::BufferHandle add_atlas_dilate_pass(vk::RenderGraph& graph, const AtlasDilatePass& pass);

}  // namespace sdfkit::diffusion::passes
