#pragma once
// The depth-peeling backend's session (one per context, "lane"): device context, pipelines,
// the peel ring and query pool, uploaded geometry, per-query buffers. Its pieces live in this
// folder: session.cpp (resources), geometry.cpp (what is drawn, in which order), cameras.cpp,
// layers.cpp and lists.cpp (the two peel modes' per-batch render graphs), lanes.cpp (two
// contexts rendering halves of the cameras), chunking.cpp (queries larger than one storage
// buffer), backend.cpp (DepthPeelBackend). The passes are in passes/.

#include "depth_peel_passes.hpp"

#include "sdfkit/core/sdf.hpp"
#include "sdfkit/vulkan/context.hpp"
#include "sdfkit/vulkan/depth_peel.hpp"
#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace sdfkit::vk {

using passes::GpuCamera;
using passes::NormalBin;

// Normalised depth (1 = bounding-sphere diameter) under which a fragment counts as the same
// layer as the previous one.
inline constexpr float kPeelEpsilon = 1e-6f;
// The framed radius is the bounding sphere's radius times this, so nothing touches the border.
inline constexpr float kFrameMargin = 1.02f;
inline constexpr VkFormat kLayerFormat = VK_FORMAT_R32G32_UINT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
// Fragment-list node: depth | facing, normal, next (sdf_definition_shared.h).
inline constexpr VkDeviceSize kNodeBytes = 4 * SDFKIT_NODE_WORDS;
// The fragment-list pass's colour attachment only gives the render area (nothing reads it).
inline constexpr VkFormat kListTargetFormat = VK_FORMAT_R8_UINT;

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// cameras.cpp: point i of n of the spherical Fibonacci set on the whole unit sphere, and n
// camera records looking along those directions with orthonormal image frames.
glm::dvec3 fibonacci_sphere_point(int i, int n);
std::vector<GpuCamera> make_cameras(int n);

// geometry.cpp: groups unit normals into `bins` cones around spherical Fibonacci axes; returns
// the groups (empty ones dropped) and fills `order` with the triangles sorted by group.
std::vector<NormalBin> bin_normals(std::span<const glm::vec4> normals, int bins, std::vector<std::uint32_t>& order);

// lanes.cpp: how many contexts render the cameras (DepthPeelConfig::lanes).
int resolve_lanes(const DepthPeelConfig& config, const Context& ctx);

struct DepthPeelBackend::Impl {
  DepthPeelConfig cfg;
  std::unique_ptr<Context> ctx;
  int batch = 8;            // cameras per batch
  int layers_per_submit = 3;
  std::vector<GpuCamera> cameras;

  Pipeline peel_front, peel_back, diameter, gather;  // peel_*: identical layouts
  UniqueSampler sampler;

  // The ring of three layer images, living across submissions: the graph keeps their layouts.
  Image ring[3];
  HistoryImage ring_history[3];
  UniqueQueryPool occlusion;
  TransientPool transients;
  Buffer camera_buffer;
  Buffer pending;  // per peel step of a submission: points not yet reached (host-read)

  // Geometry.
  std::vector<Triangle> triangles;
  std::size_t vertex_count = 0;
  bool front_layers = true;  // peel front layers for the current mesh
  std::vector<std::uint32_t> drawn;  // non-degenerate triangles, in index-buffer order
  std::vector<NormalBin> bins;       // FragmentLists on closed meshes: drawn triangles by normal
  // The drawn triangles' corners, three vec3 per triangle in draw order. Non-indexed draws: the
  // vertex stage passes gl_VertexIndex / 3 to the fragment stage as the triangle's index. With
  // gl_PrimitiveID instead, llvmpipe runs its primitive assembler, which reallocates an array
  // per primitive (~20 % of the queue thread's time at 128 views).
  Buffer corner_buffer;
  Buffer normal_buffer;              // drawn x vec4 (outward unit normal)
  glm::vec3 center{0.0f};
  float radius = 1.0f;

  // Per-query buffers (grown as needed).
  std::size_t point_capacity = 0, sample_capacity = 0;
  Buffer points, counts, samples, result;

  // FragmentLists mode (see PeelMode).
  bool lists = false;
  Pipeline list_all, list_back, resolve;  // list_*: identical layouts; list_back culls front faces
  Buffer heads;    // batch x res^2 list heads
  Buffer nodes;    // node_capacity x kNodeBytes
  Buffer counter;  // fragments appended by the last batch (host-read)
  std::size_t node_capacity = 0;
  std::size_t dropped = 0;
  std::size_t submitted = 0;  // triangles drawn by the last run_lists, over all cameras
  // FragmentLists: the cameras [camera_begin, camera_end) this context renders (camera_end 0 =
  // all); with two lanes each context renders half (see DepthPeelConfig::lanes).
  int camera_begin = 0, camera_end = 0;
  Buffer staged_counts, staged_samples;  // host copies of counts/samples (lanes merge there)

  std::vector<StageTiming> timings;
  int last_layers = 0;

  explicit Impl(const DepthPeelConfig& c);
  // The host side of a mesh state (which triangles are drawn, in which order, their corners and
  // normals, the framed sphere); computed once and uploaded into every lane.
  struct DrawGeometry {
    std::vector<std::uint32_t> drawn;
    std::vector<NormalBin> bins;
    std::vector<glm::vec3> corners;
    std::vector<glm::vec4> normals;
    glm::vec3 center{0.0f};
    float radius = 1.0f;
  };
  DrawGeometry prepare_geometry(std::span<const glm::vec3> positions) const;
  void upload_geometry(const DrawGeometry& geometry);
  void ensure_query_buffers(std::size_t n, std::uint32_t max_samples);
  // Writes the query's points (origin moved inward, inward normal) into `points`.
  void upload_points(const SdfQuery& query);
  // Copies counts and samples of the first n points into staged_counts / staged_samples.
  void stage_samples(std::size_t n, std::uint32_t max_samples, std::vector<PassTiming>& gpu);
  // Appends the second lane's staged samples of each point after this lane's (in the staged
  // copies); a point's count becomes the sum (it may exceed max_samples: the gather keeps the
  // first max_samples and the overflow is reported as with one lane).
  void append_lane_samples(const Impl& second, std::size_t n, std::uint32_t max_samples);
  void create_list_resources();
  void grow_nodes(std::size_t capacity);
  // The buffers the sample-producing passes share, imported into `graph`.
  passes::QueryBuffers import_query(RenderGraph& graph) const;
  glm::vec4 center_scale() const { return glm::vec4(center, 1.0f / (radius * kFrameMargin)); }
  // FragmentLists (lists.cpp): list and resolve passes for every camera; samples into
  // counts/samples.
  void run_lists(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                 std::vector<PassTiming>& gpu);
  // Layers (layers.cpp): peel and diameter passes, camera batch by camera batch, layer by layer
  // until nothing is left to peel; returns whether max_layers stopped a camera early.
  bool run_layers(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                  std::vector<PassTiming>& gpu);
  std::uint32_t auto_max_samples(float cone_degrees) const;
  // Gather pass; with upload_* (host-visible), copies them into counts/samples first.
  RawSdf run_gather(std::size_t n, std::uint32_t max_samples, std::vector<PassTiming>* gpu,
                    const Buffer* upload_counts = nullptr, const Buffer* upload_samples = nullptr);
};

}  // namespace sdfkit::vk
