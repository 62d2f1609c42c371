#pragma once
// Texture-space diffusion (the paper's section 4.1): a per-vertex field is rasterized into the
// atlas of a mapping (atlas.hpp), blurred there by a Gaussian and read back per vertex, all on the
// device through one render graph (passes/atlas_*.cpp):
//
//   atlas_raster  the AtlasTriangles, each corner with its mesh vertex's value, into an RG32F
//                 atlas (value, coverage 1), each fragment clipped to its chart's rectangle (a
//                 triangle across the seam of a wrapping chart is drawn once per side); copied
//                 into a texel buffer. For the
//                 stretch-compensated blur only, beside it each triangle's stretch (model units
//                 per texel along x and y, the columns of its map's Jacobian) into a second
//                 RG32F target, copied into a stretch buffer (a radius in texels: one target)
//   atlas_blur    a separable Gaussian as a cascade of three box filters per axis (one compute
//                 pass per axis), each box a running sum along a row or column of one chart: the work per
//                 texel is the same at every radius. Rows of a wrapping chart wrap; outside its
//                 rectangle a chart sees zeros, and both channels are blurred, so the value read
//                 back is blur(value·coverage) / blur(coverage) (normalized convolution): nothing
//                 from another chart, from the gutter or from uncovered texels ever comes in.
//                 With a sigma, each box's width is per texel (the stretch buffer), each box from
//                 the line's prefix sums (three compute passes per axis)
//   atlas_sample  per vertex, bilinear at vertex_uv inside the vertex's chart, normalized; with
//                 AtlasMapping::samples, the weighted blend of such reads in every chart covering
//                 the vertex (build_stm's partition of unity across chart borders)
//   steps         (DiffuseOptions::steps) the three above, raster -> blur -> sample, once per step:
//                 each step rasterizes the per-vertex values the last one read back (the raster's
//                 vertex stage reads them by vertex index), so a chart's overlap band carries its
//                 neighbours' blurred values into the next blur, and a Gaussian wider than where
//                 the bands reach runs as several narrower ones whose variances add up to it
//   atlas_dilate  (only when the atlas itself is asked for) the normalized atlas, uncovered texels
//                 and half the gutter around each chart filled from the nearest covered texel of the
//                 same chart, for a texture consumer (TEXCOORD_1) and the PNG
//
// Scale: with `sigma` (model units) every texel blurs with sigma over its own model units per
// texel along each axis (the stretch buffer; DiffuseOptions::stretch, glsl/atlas_blur_stretch.comp),
// so the blur is sigma in model units along both atlas axes wherever the map stretches (a bone
// chart's angle direction scales with the radius around the bone; the map's shear is not
// compensated), not only where it is isometric at the chart's mean scale (stretch off: sigma · texels_per_unit per
// chart); with `radius_px` every chart blurs with that many texels (the paper's Table 2). A Gaussian of sigma on the
// surface is heat flow for time t = sigma² / 2 (tests/diffusion hold it to that).

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/diffusion/atlas.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::vk {
class Context;
}

namespace sdfkit::diffusion {

struct DiffuseOptions {
  float radius_px = 0.0f;  // the Gaussian's standard deviation in atlas texels, every chart; or
  float sigma = 0.0f;      // in model units (per texel from the map's stretch, see `stretch`). Exactly one > 0.
  bool keep_atlas = false; // also return the dilated, normalized atlas (DiffuseResult::atlas)
  bool profile = false;    // per-pass device times (DiffuseResult::timings)
  // false: the graph without the blur passes (raster, sample): the benchmark's baseline, so the
  // blur's cost is the difference of two wall times (lavapipe's per-pass timestamps are not
  // reliable: it bins draws and rasterizes them later). The values are then meaningless.
  bool blur = true;
  // false: every line through the one-dispatch-per-box cascade (what the fused shader replaced
  // where it pays, BlurPlan::fused): the same values to float rounding, for comparison (the
  // benchmark's cascade columns, tests/diffusion).
  bool fused_blur = true;
  // With sigma (model units): the blur's width is set per texel from the local stretch of the
  // chart's map (each triangle's model units per texel along the atlas's x and y, rasterized
  // beside the values), so that it is sigma in model units wherever a chart stretches the
  // surface (glsl/atlas_blur_stretch.comp, every line in the cascade). false: one width in texels
  // per chart, sigma · texels_per_unit (the chart's mean scale), through the fused shader where
  // it pays (BlurPlan::fused), for comparison (sdfkit-seam-bench --no-stretch). With radius_px
  // the width is one radius in texels everywhere by definition, so a radius blur never stretches
  // (BlurPlan::stretch false) and this flag must stay at its default: a radius with stretch off is
  // an InputError.
  bool stretch = true;
  // The Gaussian as this many successive Gaussians of width sigma / √steps (radius_px / √steps),
  // whose variances add up to the whole's (1 … kMaxSteps). Each step rasterizes the values the
  // previous one read back, so what a chart's overlap band holds is refreshed from its
  // neighbours' blurred values between steps: the kernel carries on across chart borders and
  // round a small part, where one blur stops at the band's end (a band stops where its chart's
  // map would fold). Each step costs what one blur costs. 0: as many as the mapping's reach asks
  // for (AtlasMapping::vertex_reach; diffuse.cpp auto_steps), 1 where it has none; 1 is the
  // paper's single blur (Table 2).
  std::uint32_t steps = 0;
  // The result keeps the input's integral over each connected piece of the surface (lumped
  // vertex areas, the heat reference's mass matrix) and stays within the input's range there, as
  // heat flow does. The atlas's normalized blur and read-back average within each chart's
  // coverage, so they drift from that integral, more with every step (CGAL's pipe at 5 mean
  // edges, 52 steps: its mean 1.7 % off, nearly all of its difference to heat diffusion). The
  // result is projected back: the nearest field in the area-weighted norm with the input's
  // integral and range, i.e. one constant added per piece, clamped to the range (conserve_integral).
  // Every pass maps u + c to its result + c, so without the clamp that is also what correcting
  // every step would give. false: the blur's own read-back (sdfkit-seam-bench --no-conserve).
  bool conserve = true;
};
inline constexpr std::uint32_t kMaxSteps = 256;

// DiffuseOptions::conserve: per connected piece of `mesh` (over its triangles), replaces `result`
// by the field nearest to it in the norm weighted by the lumped vertex areas (a third of each
// incident triangle's area) whose integral is that of `input` and whose values lie within the
// range of `input` on the piece: clamp(result + c, min, max) with one constant c per piece.
// Vertices of no triangle are left as they are.
void conserve_integral(const Mesh& mesh, std::span<const float> input, std::span<float> result);

// Where the time went (milliseconds). Device times only with DiffuseOptions::profile.
struct DiffuseTimings {
  double prepare = 0.0;   // host: triangle soup, chart table and line jobs written to upload memory
  double raster = 0.0;    // device: atlas_raster (+ its copy into the texel buffer)
  double blur = 0.0;      // device: the blur's dispatches
  double sample = 0.0;    // device: atlas_sample (+ atlas_dilate when asked)
  double execute = 0.0;   // host wall time of the graph's submission, all passes
  double readback = 0.0;  // host: values (and atlas) out of mapped memory
  double total = 0.0;     // host wall time of diffuse()
};

// The blur's plan, on the host: three box radii per chart (texels) whose cascade has the
// Gaussian's variance, and the work its passes do. Independent of any device. With sigma in
// model units, what the road around the blur adds to the variance is taken off the blur's, so that
// the whole has sigma²: `interpolation_variance` (model units², per axis: interpolation_variance()
// of the mesh) and the bilinear sample-back's 1/6 texel² per axis.
struct BlurPlan {
  std::vector<std::array<std::uint32_t, 3>> radii;  // per chart
  // Per chart, rows then columns: blurred by the fused shader (the three boxes of an axis in one
  // dispatch) rather than the cascade (one dispatch per box). Fused: lines up to
  // passes::kShortLine texels (whole in private memory, any radius), and longer lines whose radii
  // fit the rings (kFusedMaxRadius), whatever their walk's overrun past the line (r1 + r2, a
  // wrapping row 2 (r0 + r1 + r2)), so that the passes do not change with the radius below
  // that. Never with DiffuseOptions::fused_blur off.
  std::vector<std::array<bool, 2>> fused;
  // Stretch-compensated (DiffuseOptions::stretch with sigma): every line in the cascade, each
  // box's width per texel from the map's local stretch; radii are then the chart-scale widths,
  // for reference only.
  bool stretch = false;
  std::uint64_t fused_lines = 0, cascade_lines = 0;
  std::uint32_t dispatches = 0;    // compute dispatches of the blur: per axis 1 fused + 3 cascade, when used
  std::uint64_t line_jobs = 0;     // rows + columns
  std::uint64_t texel_reads = 0;   // texels read from storage: fused once per walk, cascade twice per box + warm-up,
                                   // stretch-compensated six per box (prefix walk, half-width, two sums, two ends)
};
BlurPlan plan_blur(const AtlasMapping& mapping, const DiffuseOptions& options, double interpolation_variance = 0.0);
// The same with one interpolation variance per chart (chart_interpolation_variance; what diffuse
// uses): InputError unless there is one per chart.
BlurPlan plan_blur(const AtlasMapping& mapping, const DiffuseOptions& options, std::span<const double> chart_interpolation_variance);

// The variance per axis (model units²) that rasterizing a per-vertex field linearly over the
// triangles adds to whatever kernel then reads it at the vertices. The field read back at vertex
// v is sum_j u_j w_j, w_j = ∫ K(x - v) φ_j(x) dx with φ_j the hat of vertex j; the kernel's second
// moment about v is ∫ K(x - v) sum_j φ_j(x) |x_j - v|² dx, and sum_j φ_j(x) |x_j - v|² =
// |x - v|² + sum_j φ_j(x) |x_j - x|² (the interpolant of a quadratic; the cross term vanishes as
// sum_j φ_j(x) (x_j - x) = 0). So interpolation adds the mean of E(x) = sum_j φ_j(x) |x_j - x|²,
// which over a triangle is sum of its squared edges / 12 (both axes; 1D: a hat of half-width h
// adds h² / 6, the textbook value). Per axis of the surface, area-weighted over the triangles:
// mean (|e0|² + |e1|² + |e2|²) / 24. Tested with a quadratic field on a flat grid (diffuse_test).
double interpolation_variance(const Mesh& mesh);
// One triangle's share of it: E(x)'s mean over the triangle, the sum of its squared edges / 24 per
// axis. The variance interpolation adds is local (the kernel's mean of E around the vertex read
// back), so the diffusion takes it off where it arises, not as the mesh's mean: per atlas
// triangle for the stretch-compensated blur (each triangle's texels blur with sigma² less its own
// E), per chart (the area-weighted mean over the chart's atlas triangles) for one width per chart.
// On a mesh of one triangle size the three are the same; on one with large and small triangles
// (a CAD part: long flat-face triangles beside fine fillets) the mesh's mean can reach sigma² at
// sigma = 1 mean edge and leave the fine parts unblurred.
double triangle_interpolation_variance(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);
// The same along one direction d of the triangle's plane (unit length): the tensor form of the
// derivation above, sum_j φ_j(x) (x_j - x)(x_j - x)ᵀ, has the mean (1/12) sum_e e eᵀ over the
// triangle, so interpolation adds (1/12) sum_e (e · d)² along d; its mean over two orthogonal
// directions of the plane is triangle_interpolation_variance. A long thin triangle adds far more
// along its length than across it (legs 4 and 1: 8/3 against 1/6); the stretch-compensated blur
// takes each atlas axis's own off (its surface direction: the map's Jacobian column), so a mesh
// of anisotropic triangles (tubes, extrusions) gets sigma² on both axes, not sigma² plus and
// minus their difference, an error that grew with DiffuseOptions::steps (each step took it off again).
double triangle_interpolation_variance_along(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::dvec3& d);
// Per chart of `mapping`: the area-weighted mean of triangle_interpolation_variance over its atlas
// triangles (own and band); the mesh's for a chart without area.
std::vector<double> chart_interpolation_variance(const Mesh& mesh, const AtlasMapping& mapping);

// Three box radii (texels) whose cascade has variance sigma_px² (within the rounding of integer
// boxes: Kovesi's mix of two odd widths). sigma_px <= 0 gives {0, 0, 0}.
std::array<std::uint32_t, 3> box_radii(float sigma_px);

struct DiffuseResult {
  std::vector<float> values;  // per vertex
  std::vector<float> atlas;   // size × size, row y at [y * size], NaN where no chart reaches (keep_atlas)
  DiffuseTimings timings;
  BlurPlan plan;              // of one step
  std::uint32_t steps = 1;    // the steps run (DiffuseOptions::steps)
  // The names of the render graph's resources that its live passes use (imported and
  // transient, as compiled), e.g. "atlas.raster.stretch" only for a stretch-compensated blur.
  std::vector<std::string> graph_resources;
};

// Checks that `mapping` fits `mesh` (sizes, chart indices, rectangles inside the atlas and apart,
// uv inside their charts). Throws InputError with the first problem.
void validate_mapping(const Mesh& mesh, const AtlasMapping& mapping);

// Keeps the device pipelines and the graph's transient images between calls.
class Diffuser {
public:
  explicit Diffuser(vk::Context& ctx);
  ~Diffuser();
  Diffuser(const Diffuser&) = delete;
  Diffuser& operator=(const Diffuser&) = delete;

  // `vertex_values`: one finite value per mesh vertex. Throws InputError on a bad mapping or
  // options, DeviceError when the atlas is larger than the device allows.
  DiffuseResult run(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> vertex_values,
                    const DiffuseOptions& options);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-shot: a Diffuser for this call only.
std::vector<float> diffuse(vk::Context& ctx, const Mesh& mesh, const AtlasMapping& mapping,
                           std::span<const float> vertex_values, const DiffuseOptions& options);

// The k-ring smoothing comparable to a Gaussian of sigma (model units): engine/post/smooth puts
// its K-th ring near two sigma (sigma = K · mean edge / 2), so K = ceil(2 sigma / mean edge),
// at least 1. What `compare` and the tests set k-ring against.
int kring_for_sigma(float sigma, float mean_edge);

}  // namespace sdfkit::diffusion
