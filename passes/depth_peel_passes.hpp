#pragma once
// The depth-peeling backend's render-graph passes, one file each (passes/*.cpp). A pass is a
// function that takes graph handles, declares its uses, records through what it declared
// (PassContext::descriptor_set, buffer, query_pool) and returns the handles it wrote. The
// push-constant structs mirror the GLSL blocks of the same name (tested against the SPIR-V).
// The session that owns devices, pipelines and chunking is in engine/vulkan/depth_peel/.

#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace sdfkit::vk::passes {

// ---- push constants (the `Push` blocks of the shaders named) ---------------------------------

struct PeelPush {  // depth_peel.vert, depth_peel.frag
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::uint32_t first_layer;
  float epsilon;
  std::uint32_t back;
};
struct DiameterPush {  // diameter.comp
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::uint32_t camera_count;
  std::uint32_t first_layer;
  std::uint32_t point_count;
  std::uint32_t max_samples;
  float cos_half_cone;
  std::uint32_t rule;
  std::int32_t resolution;
  float front_tolerance;
  std::uint32_t pending_slot;
};
struct ListPush {  // fragment_list.vert, fragment_list.frag
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::int32_t resolution;
  std::uint32_t capacity;
};
struct ResolvePush {  // fragment_list.comp
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::uint32_t camera_count;
  std::uint32_t point_count;
  std::uint32_t max_samples;
  float cos_half_cone;
  std::uint32_t rule;
  std::int32_t resolution;
  float front_tolerance;
  std::uint32_t capacity;
};
struct GatherPush {  // gather.comp
  std::uint32_t point_count;
  std::uint32_t max_samples;
};

// A camera record (depth_peel_common.glsl's Camera).
struct GpuCamera {
  glm::vec4 right, up, dir;
};

// The buffers every sample-producing pass reads: cameras, query points (origins then inward
// normals), per-point sample counts and (length, theta) slots.
struct QueryBuffers {
  BufferHandle cameras, points, counts, samples;
};

// ---- peel (Layers mode): one front and one back layer of a batch of cameras -------------------

// A groups of drawn triangles whose normals face away from a camera can be skipped (see
// engine/vulkan/depth_peel/geometry.hpp); the peel pass draws everything.
struct PeelPass {
  const Pipeline* front = nullptr;  // depth_peel.* culling back faces
  const Pipeline* back = nullptr;   // depth_peel.* culling front faces
  bool front_layers = true;         // draw the front faces too
  VkSampler sampler = VK_NULL_HANDLE;
  BufferHandle corners, normals, cameras;
  ImageHandle previous;             // the previous layer (sampled)
  ImageHandle target, depth;        // written (cleared)
  QueryPoolHandle occlusion;
  std::uint32_t query = 0;          // occlusion query index
  std::uint32_t corner_count = 0, camera_count = 0;
  PeelPush push{};
};
struct PeelOutput {
  ImageHandle target, depth;
};
PeelOutput add_peel_pass(RenderGraph& graph, const PeelPass& pass);
// Resets the first `queries` occlusion queries and zeroes the per-step pending counts before a
// submission's peel steps.
BufferHandle add_peel_reset_pass(RenderGraph& graph, QueryPoolHandle occlusion, std::uint32_t queries,
                                 BufferHandle pending);

// ---- diameter (Layers mode): samples where the point lies between two back layers ------------

struct DiameterPass {
  const Pipeline* pipeline = nullptr;  // diameter.comp
  VkSampler sampler = VK_NULL_HANDLE;
  QueryBuffers query;
  ImageHandle previous, current;  // layers k-1 and k (sampled)
  BufferHandle pending;           // per peel step: points that may still be reached
  std::uint32_t groups = 0;       // workgroups of 64 points
  DiameterPush push{};
};
struct DiameterOutput {
  BufferHandle counts, samples, pending;
};
DiameterOutput add_diameter_pass(RenderGraph& graph, const DiameterPass& pass);

// ---- fragment lists (FragmentLists mode): every fragment of a batch into per-pixel lists -----

// A cone of drawn triangles' normals (FragmentLists on closed meshes): a camera looking along
// `view` skips the group when dot(dir, view) < skip_below (see engine/vulkan/depth_peel/geometry).
struct NormalBin {
  glm::vec3 dir{0.0f};
  float skip_below = -2.0f;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

struct FragmentListPass {
  const Pipeline* pipeline = nullptr;  // fragment_list.* (cull none, or front faces on closed meshes)
  BufferHandle corners, normals, cameras;
  BufferHandle heads, nodes, counter;
  ImageInfo target_info;               // the attachment that gives the render area
  std::span<const NormalBin> bins;     // empty: one draw of all triangles per camera
  std::span<const GpuCamera> batch_cameras;  // the batch's cameras (for the bins' test)
  std::uint32_t corner_count = 0, camera_count = 0;
  std::size_t* submitted = nullptr;    // adds the triangles sent to the pipeline
  ListPush push{};
};
struct FragmentListOutput {
  BufferHandle heads, nodes, counter;
};
// Also adds the pass that resets the heads (to SDFKIT_END_OF_LIST) and the counter.
FragmentListOutput add_fragment_list_passes(RenderGraph& graph, const FragmentListPass& pass);

// ---- resolve (FragmentLists mode): per point and camera, the exit and the closest hit --------

struct ResolvePass {
  const Pipeline* pipeline = nullptr;  // fragment_list.comp
  QueryBuffers query;
  BufferHandle heads, nodes, counter;
  std::uint32_t groups = 0;
  ResolvePush push{};
};
struct ResolveOutput {
  BufferHandle counts, samples;
};
ResolveOutput add_resolve_pass(RenderGraph& graph, const ResolvePass& pass);

// ---- gather: the shared statistics per point ---------------------------------------------------

struct GatherPass {
  const Pipeline* pipeline = nullptr;  // gather.comp
  BufferHandle counts, samples, result;
  std::uint32_t groups = 0;
  GatherPush push{};
};
BufferHandle add_gather_pass(RenderGraph& graph, const GatherPass& pass);

// ---- small transfer passes ---------------------------------------------------------------------

// Zeroes the per-point sample counts.
BufferHandle add_clear_counts_pass(RenderGraph& graph, BufferHandle counts);
// Copies whole buffers src[i] -> dst[i] (bytes[i] each); returns the written destinations.
std::vector<BufferHandle> add_copy_pass(RenderGraph& graph, const char* name, std::span<const BufferHandle> src,
                                        std::span<const BufferHandle> dst, std::span<const VkDeviceSize> bytes,
                                        bool host_reads);

}  // namespace sdfkit::vk::passes
