#pragma once
// The Shape Diameter Function by depth peeling (Shapira et al. 2008, section 3.1, Algorithms 1
// and 2): rasterization only, no acceleration structure.
//
// Cameras on a sphere (spherical Fibonacci) look at the mesh with orthographic projections
// framing its bounding sphere. Per batch of cameras, peel passes render the k-th front layer and
// the k-th back layer of every camera at once (layered rendering: gl_Layer = 2 * camera + back)
// into a ring of three layer images (depth and normal per pixel). After each layer a diameter
// pass tests every query point against the previous and the current back layer; the accepted
// ray lengths and their angles are stored per point, and a final gather pass applies the shared
// statistics (sdfkit::gather) on the device.
//
// Definitions and tolerances:
//  * A peel pass keeps a fragment only when its depth is strictly greater than the previous
//    layer's depth at that pixel plus kPeelEpsilon (in normalised depth, where 1 = the bounding
//    sphere's diameter): coincident duplicates collapse into one layer, and surfaces closer than
//    ~1e-6 of the diameter count as one.
//  * A query point (its ray origin p - offset * n) is accepted for camera c and layer k when the
//    view direction is within half the cone angle of its inward normal, and its depth lies
//    strictly between back layer k-1 and back layer k at its pixel, with both back depths moved
//    to the point's exact position along the plane given by the stored normal (sub-pixel
//    correction, limited to two pixels). The back layer is then the first exit behind the
//    point. If front layer k lies behind the point (by more than one pixel's depth) and in front
//    of back layer k, the closest hit is that front face (open or self-intersecting meshes).
//  * The closest hit passes the false-intersection rule (Paper: hit normal . start normal <= 0;
//    Cgal: view direction . hit normal > 0) or the ray is dropped.
//  * Peeling a camera stops when an occlusion query reports no fragment in the last layer (front
//    and back layers are counted together when front layers are peeled), when no query point
//    within the cone lies behind the last back layer any more (the diameter pass counts them:
//    deeper layers could not give any point a sample), or at max_layers (a warning is logged
//    when fragments and points were still pending).
//  * Each point stores at most max_samples_per_point (length, theta) pairs. The default bound
//    exceeds the number of cameras that can fall inside one cone, so it is never reached; with a
//    smaller bound, samples past it are dropped (the first ones stored, in camera order, are
//    kept) and a warning gives the number of points affected.

#include "sdfkit/core/sdf.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace sdfkit::vk {

// Front layers matter only where a front face can be the closest hit behind a point: meshes
// with boundary or non-manifold edges (or self-intersections). Auto peels them for meshes with
// boundary or non-manifold edges and peels back layers alone otherwise (same result on closed
// manifold meshes, about half the rasterization); Always alternates front and back layers for
// every mesh as the paper does (use it for self-intersecting closed meshes).
enum class FrontLayers { Auto, Always };

// How the surfaces behind each pixel are found.
//  * Layers: the paper's depth peeling (Algorithms 1 and 2), one front and one back layer per
//    peel pass and a diameter pass after each; the reference mode.
//  * FragmentLists: per batch of cameras ONE raster pass without depth test appends every
//    fragment (depth, outward normal, facing) to per-pixel linked lists (a head per pixel and
//    camera, a node buffer, an atomic counter), then ONE resolve pass finds, per query point and
//    camera, the nearest back face strictly behind the point (the exit) and the nearest front
//    face behind it by more than one pixel's depth; the closest of the two is the hit. Same
//    tolerances, sub-pixel depth correction, cone test, false-hit rule and gather as Layers, so
//    the two modes agree up to rounding (tested). Fronts are only rasterized when Layers would
//    peel front layers (FrontLayers). The node buffer starts at fragment_capacity nodes
//    (automatic: one per pixel of the batch) and persists across calls; when a batch appends
//    more fragments than it holds, the extra fragments are counted and dropped, the resolve pass
//    ignores that batch, and the host grows the buffer (1.25x the count) and runs the batch again,
//    logging one warning per compute(). A batch needing more than the device's storage-buffer
//    range is an error (use fewer cameras per batch or a lower resolution).
enum class PeelMode { Layers, FragmentLists };

struct DepthPeelConfig {
  std::string device;           // see ContextConfig::device
  int views = 256;              // cameras on the sphere
  // Pixels per side of each camera's image. 256 by measurement: against Embree, 256^2 and 512^2
  // gave the same median differences (elephant 3.96 / 4.02 %, cow 3.33 / 3.33 % at 64 views;
  // the difference is view-sampling noise), while 512^2 cost ~35% more CPU on armadillo.
  int resolution = 256;
  int max_layers = 64;          // peel iterations per camera at most
  bool validation = false;
  bool profile = false;         // per-pass GPU timestamps in last_timings()
  int max_samples_per_point = 0;  // 0 = automatic bound (see above)
  // Points per compute chunk: queries whose sample storage exceeds the device's storage-buffer
  // range run in chunks of points, each rasterizing every camera again. 0 = as many as fit.
  int max_points_per_chunk = 0;
  int cameras_per_batch = 0;      // 0 = automatic (Layers: 1, measured fastest on lavapipe; lists: 8)
  int layers_per_submit = 0;      // 0 = adaptive (from the previous camera's layer count)
  FrontLayers front_layers = FrontLayers::Auto;
  // FragmentLists by default: on lavapipe (2 cores, Mesa 22.3) a raster pass costs ~0.3 us of
  // single-threaded vertex/setup/binning per triangle and camera, so the pass count decides the
  // time; Layers needs ~1000 passes on armadillo (128 views x up to 9 layers), the lists 128
  // camera draws in 16 passes. Measured (process CPU per warm call, 128 views, 512^2): armadillo
  // 14.1 s (Layers) vs 2.9 s (lists), refined_elephant 10.5 s vs 3.0 s, identical values on
  // closed meshes (same median difference to Embree: 2.38 % / 2.57 %). Layers stays the paper's
  // reference mode, tested against the lists.
  PeelMode mode = PeelMode::FragmentLists;
  // FragmentLists only: initial nodes of the node buffer (0 = automatic, see PeelMode).
  std::size_t fragment_capacity = 0;
  // FragmentLists on closed meshes (back faces only): the triangles are grouped into this many
  // cones of normal directions and a camera does not draw the groups that face it, which the
  // pipeline would cull triangle by triangle after vertex processing. 0 or 1 = one draw of all
  // triangles per camera. Same values either way.
  int normal_bins = 64;
  // FragmentLists: contexts that render the cameras, each its half on its own thread (1 or 2;
  // 0 = automatic: 2 on CPU devices with at least 16 views, else 1). On lavapipe one queue
  // thread bins every triangle of a render pass before the rasterizer threads start on it, so
  // a second context (device) binning the other half overlaps the first one's rasterization;
  // the second lane's samples are appended to the first lane's per point before the gather.
  // A GPU runs one context.
  int lanes = 0;
  // CPU devices (lavapipe): compute() warns (one line) when its estimated time exceeds this many
  // seconds; see estimated_cpu_seconds(). 0 = never.
  double warn_after_seconds = 60.0;
};

// The time a CPU rasterizer (lavapipe) takes at least for `triangles` x `views` camera draws in
// `chunks` chunks of points on `lanes` lanes, in seconds: ~0.3 us of single-threaded vertex
// processing, setup and binning per triangle and camera draw and lane (measured on the 2-core
// EPYC CI machine, Mesa 22.3, see `mode` above), each chunk drawing every camera again. Peel
// layers (PeelMode::Layers) and rasterization come on top: a lower bound.
double estimated_cpu_seconds(std::size_t triangles, int views, std::size_t chunks, int lanes);

// Devices as `sdfkit devices` shows them, with suitability for this backend.
std::vector<DeviceInfo> list_devices_for_depth_peel();

class DepthPeelBackend final : public SdfBackend {
public:
  explicit DepthPeelBackend(const DepthPeelConfig& config = {});
  ~DepthPeelBackend() override;

  std::string name() const override { return "vulkan"; }
  std::string device_name() const override;
  void set_mesh(const Mesh& mesh) override;
  void update_positions(std::span<const glm::vec3> positions) override;
  RawSdf compute(const SdfQuery& query, const SdfOptions& options) override;
  std::vector<StageTiming> last_timings() const override;
  std::size_t device_memory_bytes() const override;

  // Test entry point: runs only the device gather on given per-point samples (length in model
  // units, theta in radians), as the diameter passes would have stored them.
  RawSdf gather_on_device(const std::vector<std::vector<std::pair<float, float>>>& samples);

  Context& context();
  const DepthPeelConfig& config() const;
  // Layers peeled in the last compute() (deepest batch).
  int last_layer_count() const;
  // FragmentLists: the node buffer's capacity now (nodes) and the fragments dropped (then
  // re-run after growing) in the last compute().
  std::size_t fragment_capacity() const;
  std::size_t last_dropped_fragments() const;
  // FragmentLists: triangles sent to the pipeline, summed over the cameras, in the last
  // compute() (its last chunk of points when it ran in chunks). Without normal groups (or on an
  // open mesh) this is views x non-degenerate triangles.
  std::size_t last_submitted_triangles() const;
  // Contexts rendering the cameras (see DepthPeelConfig::lanes).
  int lanes() const;
  // Whether front layers are peeled for the current mesh (see FrontLayers).
  bool peels_front_layers() const;

private:
  // Splits a query whose per-point sample storage exceeds one storage buffer into chunks of
  // `per_chunk` points (each chunk rasterizes every camera again); timings add up.
  RawSdf compute_in_chunks(const SdfQuery& query, const SdfOptions& options, std::size_t per_chunk);
  // On a CPU device: one warning line when estimated_cpu_seconds for `points` in chunks of
  // `per_chunk` exceeds DepthPeelConfig::warn_after_seconds.
  void warn_if_slow(std::size_t points, std::size_t per_chunk) const;
  bool in_chunks_ = false;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::unique_ptr<Impl> lane_;  // the second lane's context, or null
};

}  // namespace sdfkit::vk
