// The depth-peeling SDF backend: geometry upload, cameras, and per batch of cameras a render
// graph of peel and diameter passes; a final gather pass. See depth_peel.hpp for the method.

#include "sdfkit/vulkan/depth_peel.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <future>
#include <map>
#include <span>
#include <string_view>

namespace sdfkit::vk {

namespace {

// Normalised depth (1 = bounding-sphere diameter) under which a fragment counts as the same
// layer as the previous one.
constexpr float kPeelEpsilon = 1e-6f;
// The framed radius is the bounding sphere's radius times this, so nothing touches the border.
constexpr float kFrameMargin = 1.02f;
constexpr VkFormat kLayerFormat = VK_FORMAT_R32G32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
static_assert(std::bit_cast<std::uint32_t>(SDFKIT_NO_SURFACE) == SDFKIT_NO_SURFACE_BITS);

struct GpuCamera {
  glm::vec4 right, up, dir;
};
struct PeelPush {
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::uint32_t first_layer;
  float epsilon;
  std::uint32_t back;
};
struct DiameterPush {
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
struct ListPush {
  glm::vec4 center_scale;
  std::uint32_t camera_base;
  std::int32_t resolution;
  std::uint32_t capacity;
};
struct ResolvePush {
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
// Fragment-list node: depth | facing, normal, next (sdf_definition_shared.h).
constexpr VkDeviceSize kNodeBytes = 4 * SDFKIT_NODE_WORDS;
// The fragment-list pass's colour attachment only gives the render area (nothing reads it).
constexpr VkFormat kListTargetFormat = VK_FORMAT_R8_UINT;
struct GatherPush {
  std::uint32_t point_count;
  std::uint32_t max_samples;
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Point i of n of the spherical Fibonacci set on the whole unit sphere (cameras, normal groups).
glm::dvec3 fibonacci_sphere_point(int i, int n) {
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = std::fmod(i * kGoldenAngle, 2.0 * M_PI);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Spherical Fibonacci directions on the whole sphere, each with an orthonormal image frame.
std::vector<GpuCamera> make_cameras(int n) {
  std::vector<GpuCamera> cams(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Frame f = tangent_frame(glm::normalize(glm::vec3(fibonacci_sphere_point(i, n))));
    cams[static_cast<std::size_t>(i)] = {glm::vec4(f.t, 0.0f), glm::vec4(f.b, 0.0f), glm::vec4(f.axis, 0.0f)};
  }
  return cams;
}

// A group of drawn triangles whose outward normals lie within a cone (FragmentLists, closed
// meshes). A camera looking along `view` culls a triangle whose normal faces it (dot < 0); it
// skips the whole group, before vertex processing, when every normal in the cone faces it by
// more than kBinMarginDegrees, so the skipped triangles are exactly ones the pipeline would cull.
struct NormalBin {
  glm::vec3 dir{0.0f};       // unit axis of the cone
  float skip_below = -2.0f;  // skip when dot(dir, view) < skip_below (-2: never)
  std::uint32_t first = 0;   // first triangle of the group in draw order
  std::uint32_t count = 0;
};
constexpr double kBinMarginDegrees = 2.0;

// Groups unit normals into `bins` cones around spherical Fibonacci axes (nearest axis). Returns
// the groups (empty ones dropped) and fills `order` with the triangles sorted by group.
std::vector<NormalBin> bin_normals(std::span<const glm::vec4> normals, int bins, std::vector<std::uint32_t>& order) {
  std::vector<glm::dvec3> axes(static_cast<std::size_t>(bins));
  for (int i = 0; i < bins; ++i) axes[static_cast<std::size_t>(i)] = fibonacci_sphere_point(i, bins);
  // Draw order: latitude bands, by azimuth within a band, so the groups a camera keeps (a cap
  // of directions) form a few runs, one draw each (about 8 per camera at 128 groups, against
  // 34 in Fibonacci order).
  const int bands = std::max(2, static_cast<int>(std::lround(std::sqrt(bins / 2.0))));
  const auto band_key = [&](const glm::dvec3& a) {
    const int band = std::min(bands - 1, static_cast<int>((1.0 - a.z) / 2.0 * bands));
    return std::pair(band, std::atan2(a.y, a.x));
  };
  std::sort(axes.begin(), axes.end(), [&](const glm::dvec3& a, const glm::dvec3& b) { return band_key(a) < band_key(b); });
  std::vector<std::uint32_t> bin_of(normals.size());
  std::vector<double> min_cos(axes.size(), 1.0);
  std::vector<std::uint32_t> counts(axes.size() + 1, 0);
  for (std::size_t t = 0; t < normals.size(); ++t) {
    const glm::dvec3 n(normals[t]);
    std::size_t best = 0;
    double best_dot = -2.0;
    for (std::size_t b = 0; b < axes.size(); ++b) {
      const double d = glm::dot(axes[b], n);
      if (d > best_dot) {
        best_dot = d;
        best = b;
      }
    }
    bin_of[t] = static_cast<std::uint32_t>(best);
    min_cos[best] = std::min(min_cos[best], best_dot);
    ++counts[best + 1];
  }
  for (std::size_t b = 0; b < axes.size(); ++b) counts[b + 1] += counts[b];
  order.resize(normals.size());
  std::vector<std::uint32_t> next(counts.begin(), counts.end() - 1);
  for (std::size_t t = 0; t < normals.size(); ++t) order[next[bin_of[t]]++] = static_cast<std::uint32_t>(t);
  std::vector<NormalBin> out;
  for (std::size_t b = 0; b < axes.size(); ++b) {
    if (counts[b + 1] == counts[b]) continue;
    NormalBin nb;
    nb.dir = glm::vec3(axes[b]);
    const double spread = std::acos(std::clamp(min_cos[b], -1.0, 1.0)) + kBinMarginDegrees * M_PI / 180.0;
    if (spread < 0.5 * M_PI) nb.skip_below = static_cast<float>(-std::sin(spread));
    nb.first = counts[b];
    nb.count = counts[b + 1] - counts[b];
    out.push_back(nb);
  }
  return out;
}

const VkDescriptorType kPeelBindings[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                          VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
const VkDescriptorType kDiameterBindings[] = {
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
const VkDescriptorType kListBindings[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                          VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                          VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
const VkDescriptorType kResolveBindings[] = {
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
const VkDescriptorType kGatherBindings[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                            VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};

// A pipeline that rasterizes the uploaded mesh: its positions (vec3) are vertex binding 0.
GraphicsPipelineDescription mesh_raster_pipeline(std::string_view vertex_shader, std::string_view fragment_shader,
                                                 std::span<const VkDescriptorType> bindings, std::uint32_t push_bytes) {
  GraphicsPipelineDescription gd;
  gd.vertex_shader = vertex_shader;
  gd.fragment_shader = fragment_shader;
  gd.bindings.assign(bindings.begin(), bindings.end());
  gd.push_bytes = push_bytes;
  gd.vertex_stride = sizeof(glm::vec3);
  gd.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
  return gd;
}

}  // namespace

std::vector<DeviceInfo> list_devices_for_depth_peel() {
  DeviceRequirements req;
  req.shader_output_layer = true;
  return list_devices(req);
}

struct DepthPeelBackend::Impl {
  DepthPeelConfig cfg;
  std::unique_ptr<Context> ctx;
  int batch = 8;            // cameras per batch
  int layers_per_submit = 3;
  std::vector<GpuCamera> cameras;

  Pipeline peel_front, peel_back, diameter, gather;  // peel_*: identical layouts
  UniqueSampler sampler;
  UniqueDescriptorPool pool;
  VkDescriptorSet peel_sets[3]{};      // by previous ring index
  VkDescriptorSet diameter_sets[3]{};  // by current ring index
  VkDescriptorSet gather_set = VK_NULL_HANDLE;

  Image ring[3];
  bool ring_ready[3] = {false, false, false};
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
  UniqueDescriptorPool list_pool;
  VkDescriptorSet list_set = VK_NULL_HANDLE, resolve_set = VK_NULL_HANDLE;
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
  void write_sets();
  void create_list_resources();
  void grow_nodes(std::size_t capacity);
  // FragmentLists: list and resolve passes for every camera; samples into counts/samples.
  void run_lists(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                 std::vector<PassTiming>& gpu);
  std::uint32_t auto_max_samples(float cone_degrees) const;
  // Gather pass; with upload_* (host-visible), copies them into counts/samples first.
  RawSdf run_gather(std::size_t n, std::uint32_t max_samples, std::vector<PassTiming>* gpu,
                    const Buffer* upload_counts = nullptr, const Buffer* upload_samples = nullptr);
};

DepthPeelBackend::Impl::Impl(const DepthPeelConfig& c)
    : cfg(c),
      ctx([&] {
        ContextConfig cc;
        cc.device = c.device;
        cc.validation = c.validation;
        cc.requirements.shader_output_layer = true;
        return std::make_unique<Context>(cc);
      }()),
      transients(*ctx) {
  if (cfg.views < 1 || cfg.views > 65536)
    throw InputError("--views must be between 1 and 65536, got " + std::to_string(cfg.views));
  if (cfg.resolution < 16 || cfg.resolution > static_cast<int>(ctx->capabilities().max_image_dimension_2d))
    throw InputError("--resolution must be between 16 and " +
                     std::to_string(ctx->capabilities().max_image_dimension_2d) + ", got " +
                     std::to_string(cfg.resolution));
  if (cfg.max_layers < 1) throw InputError("max_layers must be at least 1");
  // One camera per batch by default: on lavapipe, layered rendering of 8 cameras (16 layers) was
  // 5.7x slower per camera than one camera (2 layers) at 512^2 (elephant, 32 views: 6.1 s vs
  // 1.08 s of peel GPU time), the tiles of many layers no longer fitting in the CPU caches.
  batch = cfg.cameras_per_batch > 0 ? cfg.cameras_per_batch : 1;
  batch = std::min({batch, cfg.views, static_cast<int>(ctx->capabilities().max_framebuffer_layers / 2)});
  // Layers recorded per submission: fixed when configured; by default the first submission of a
  // camera covers one pass less than the previous camera needed, then one layer per submission,
  // so that few passes beyond the last layer run (measured on armadillo, 32 views: 3 layers per
  // submission cost 7.0 s of CPU, 1 per submission 5.7 s).
  layers_per_submit = cfg.layers_per_submit > 0 ? cfg.layers_per_submit : 0;
  cameras = make_cameras(cfg.views);

  VkDevice dev = ctx->device();
  GraphicsPipelineDescription gd = mesh_raster_pipeline("depth_peel.vert", "depth_peel.frag", kPeelBindings, sizeof(PeelPush));
  gd.color_formats = {kLayerFormat};
  gd.depth_format = kDepthFormat;
  gd.depth_compare = VK_COMPARE_OP_LESS;
  // With this projection a triangle facing the camera is counter-clockwise in framebuffer
  // coordinates (tested: front and back layers feed the analytic tests).
  gd.cull = VK_CULL_MODE_BACK_BIT;
  peel_front = create_graphics_pipeline(*ctx, gd);
  gd.cull = VK_CULL_MODE_FRONT_BIT;
  peel_back = create_graphics_pipeline(*ctx, gd);
  diameter = create_compute_pipeline(*ctx, "diameter.comp", kDiameterBindings, sizeof(DiameterPush));
  gather = create_compute_pipeline(*ctx, "gather.comp", kGatherBindings, sizeof(GatherPush));
  sampler = create_nearest_sampler(dev);

  std::vector<VkDescriptorType> all;
  for (int i = 0; i < 3; ++i) all.insert(all.end(), std::begin(kPeelBindings), std::end(kPeelBindings));
  for (int i = 0; i < 3; ++i) all.insert(all.end(), std::begin(kDiameterBindings), std::end(kDiameterBindings));
  all.insert(all.end(), std::begin(kGatherBindings), std::end(kGatherBindings));
  pool = create_descriptor_pool(dev, all, 7);
  for (int i = 0; i < 3; ++i) {
    peel_sets[i] = allocate_set(dev, pool.get(), peel_front.set_layout.get());
    diameter_sets[i] = allocate_set(dev, pool.get(), diameter.set_layout.get());
  }
  gather_set = allocate_set(dev, pool.get(), gather.set_layout.get());

  const auto res = static_cast<std::uint32_t>(cfg.resolution);
  for (auto& r : ring)
    r = create_image(*ctx, {kLayerFormat, res, res, static_cast<std::uint32_t>(2 * batch),
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  camera_buffer = create_buffer(*ctx, cameras.size() * sizeof(GpuCamera), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                MemoryUse::Upload);
  pending = create_buffer(*ctx, 4 * static_cast<VkDeviceSize>(std::max(layers_per_submit, cfg.max_layers)),
                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Readback);
  std::memcpy(camera_buffer.mapped(), cameras.data(), cameras.size() * sizeof(GpuCamera));

  VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, nullptr, 0, VK_QUERY_TYPE_OCCLUSION,
                           static_cast<std::uint32_t>(std::max(layers_per_submit, cfg.max_layers)), 0};
  VkQueryPool qp = VK_NULL_HANDLE;
  check(vkCreateQueryPool(dev, &qi, nullptr, &qp), "creating the occlusion query pool");
  occlusion = UniqueQueryPool(dev, qp);
  if (cfg.mode == PeelMode::FragmentLists) create_list_resources();
}

void DepthPeelBackend::Impl::create_list_resources() {
  lists = true;
  // Cameras per batch: one raster pass (instanced) and one resolve pass per batch.
  batch = cfg.cameras_per_batch > 0 ? std::min(cfg.cameras_per_batch, cfg.views) : std::min(8, cfg.views);
  VkDevice dev = ctx->device();
  GraphicsPipelineDescription gd =
      mesh_raster_pipeline("fragment_list.vert", "fragment_list.frag", kListBindings, sizeof(ListPush));
  gd.color_formats = {kListTargetFormat};
  gd.cull = VK_CULL_MODE_NONE;
  list_all = create_graphics_pipeline(*ctx, gd);
  gd.cull = VK_CULL_MODE_FRONT_BIT;
  list_back = create_graphics_pipeline(*ctx, gd);
  resolve = create_compute_pipeline(*ctx, "fragment_list.comp", kResolveBindings, sizeof(ResolvePush));
  std::vector<VkDescriptorType> all(std::begin(kListBindings), std::end(kListBindings));
  all.insert(all.end(), std::begin(kResolveBindings), std::end(kResolveBindings));
  list_pool = create_descriptor_pool(dev, all, 2);
  list_set = allocate_set(dev, list_pool.get(), list_all.set_layout.get());
  resolve_set = allocate_set(dev, list_pool.get(), resolve.set_layout.get());

  const auto pixels = static_cast<VkDeviceSize>(cfg.resolution) * static_cast<VkDeviceSize>(cfg.resolution);
  heads = create_buffer(*ctx, 4 * pixels * static_cast<VkDeviceSize>(batch),
                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::DeviceLocal);
  counter = create_buffer(*ctx, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                          MemoryUse::Readback);
  grow_nodes(cfg.fragment_capacity > 0 ? cfg.fragment_capacity : static_cast<std::size_t>(pixels) * batch);
}

void DepthPeelBackend::Impl::grow_nodes(std::size_t capacity) {
  const VkDeviceSize limit = ctx->capabilities().max_storage_buffer_range / kNodeBytes;
  if (capacity > limit)
    throw DeviceError("the fragment lists of one batch of " + std::to_string(batch) + " cameras need " +
                      std::to_string(capacity) + " nodes, more than the device's storage buffer range holds (" +
                      std::to_string(limit) + "); use fewer cameras per batch or a lower resolution");
  nodes = Buffer{};  // release the old buffer first
  nodes = create_buffer(*ctx, capacity * kNodeBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::DeviceLocal);
  node_capacity = capacity;
}

DepthPeelBackend::Impl::DrawGeometry DepthPeelBackend::Impl::prepare_geometry(
    std::span<const glm::vec3> positions) const {
  DrawGeometry g;
  // Degenerate triangles are never drawn (never ray targets); the rest keep their order.
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    const glm::vec3 a = positions[t[0]], b = positions[t[1]], c = positions[t[2]];
    if (triangle_is_degenerate(a, b, c)) continue;
    g.drawn.push_back(static_cast<std::uint32_t>(f));
    g.normals.emplace_back(glm::normalize(glm::cross(b - a, c - a)), 0.0f);
  }
  // Closed meshes in FragmentLists mode draw back faces only: draw order by normal group, so a
  // camera can skip the groups facing it. Otherwise the input order.
  if (lists && !front_layers && cfg.normal_bins > 1 && !g.drawn.empty()) {
    std::vector<std::uint32_t> order;
    g.bins = bin_normals(g.normals, cfg.normal_bins, order);
    std::vector<std::uint32_t> sorted_drawn(g.drawn.size());
    std::vector<glm::vec4> sorted_normals(g.normals.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      sorted_drawn[i] = g.drawn[order[i]];
      sorted_normals[i] = g.normals[order[i]];
    }
    g.drawn = std::move(sorted_drawn);
    g.normals = std::move(sorted_normals);
  }
  g.corners.reserve(3 * g.drawn.size());
  for (std::uint32_t f : g.drawn)
    for (std::uint32_t v : triangles[f]) g.corners.push_back(positions[v]);

  // Bounding sphere: box centre, farthest vertex (only vertices used by triangles count).
  g.center = bounding_box(positions).center();
  float r2 = 0.0f;
  for (const auto& t : triangles)
    for (std::uint32_t v : t) {
      const glm::vec3 d = positions[v] - g.center;
      r2 = std::max(r2, glm::dot(d, d));
    }
  g.radius = std::max(std::sqrt(r2), 1e-20f);
  return g;
}

void DepthPeelBackend::Impl::upload_geometry(const DrawGeometry& geometry) {
  drawn = geometry.drawn;
  bins = geometry.bins;
  center = geometry.center;
  radius = geometry.radius;
  auto upload = [&](Buffer& buf, const void* data, std::size_t bytes, VkBufferUsageFlags usage) {
    const std::size_t alloc = std::max<std::size_t>(bytes, 16);
    if (!buf.buffer || buf.size < alloc) buf = create_buffer(*ctx, alloc, usage, MemoryUse::Upload);
    if (bytes) std::memcpy(buf.mapped(), data, bytes);
  };
  upload(corner_buffer, geometry.corners.data(), geometry.corners.size() * sizeof(glm::vec3),
         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  upload(normal_buffer, geometry.normals.data(), geometry.normals.size() * sizeof(glm::vec4),
         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

std::uint32_t DepthPeelBackend::Impl::auto_max_samples(float cone_degrees) const {
  // Cameras inside a cone: at most views * (1 - cos(a/2)) / 2 on average; the Fibonacci set's
  // local count deviates by a few; 25% + 8 of headroom covers every cone.
  const double frac = (1.0 - std::cos(0.5 * cone_degrees * M_PI / 180.0)) / 2.0;
  return static_cast<std::uint32_t>(std::ceil(cfg.views * frac * 1.25)) + 8u;
}

void DepthPeelBackend::Impl::ensure_query_buffers(std::size_t n, std::uint32_t max_samples) {
  const std::size_t cap = std::max<std::size_t>(n, 1);
  bool changed = false;
  if (point_capacity < cap) {
    points = create_buffer(*ctx, 2 * cap * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
    counts = create_buffer(*ctx, cap * 4,
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                           MemoryUse::DeviceLocal);
    result = create_buffer(*ctx, cap * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
    point_capacity = cap;
    changed = true;
  }
  const std::size_t sc = cap * max_samples;
  if (sample_capacity < sc) {
    const VkDeviceSize bytes = sc * sizeof(glm::vec2);
    if (bytes > ctx->capabilities().max_storage_buffer_range)
      throw DeviceError("the per-point sample storage (" + std::to_string(bytes >> 20) +
                        " MiB) exceeds the device's storage buffer range; use fewer views or a smaller "
                        "max_samples_per_point");
    samples = create_buffer(*ctx, bytes,
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                            MemoryUse::DeviceLocal);
    sample_capacity = sc;
    changed = true;
  }
  if (changed) write_sets();
}

void DepthPeelBackend::Impl::write_sets() {
  VkDevice dev = ctx->device();
  const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  for (int i = 0; i < 3; ++i) {
    if (normal_buffer.buffer) {
      const DescriptorWrite pw[] = {
          {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, normal_buffer.get()},
          {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, camera_buffer.get()},
          {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_NULL_HANDLE, ring[i].view.get(), ro, sampler.get()}};
      write_set(dev, peel_sets[i], pw);
    }
    if (points.buffer) {
      const int prev = (i + 2) % 3;
      const DescriptorWrite dw[] = {
          {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, camera_buffer.get()},
          {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, points.get()},
          {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counts.get()},
          {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, samples.get()},
          {4, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_NULL_HANDLE, ring[prev].view.get(), ro, sampler.get()},
          {5, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_NULL_HANDLE, ring[i].view.get(), ro, sampler.get()},
          {6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pending.get()}};
      write_set(dev, diameter_sets[i], dw);
    }
  }
  if (points.buffer) {
    const DescriptorWrite gw[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counts.get()},
                                  {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, samples.get()},
                                  {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, result.get()}};
    write_set(dev, gather_set, gw);
  }
  if (lists && normal_buffer.buffer) {
    const DescriptorWrite lw[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, normal_buffer.get()},
                                  {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, camera_buffer.get()},
                                  {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, heads.get()},
                                  {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nodes.get()},
                                  {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counter.get()}};
    write_set(dev, list_set, lw);
  }
  if (lists && points.buffer) {
    const DescriptorWrite rw[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, camera_buffer.get()},
                                  {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, points.get()},
                                  {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counts.get()},
                                  {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, samples.get()},
                                  {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, heads.get()},
                                  {5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nodes.get()},
                                  {6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counter.get()}};
    write_set(dev, resolve_set, rw);
  }
}

void DepthPeelBackend::Impl::run_lists(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                                       std::vector<PassTiming>& gpu) {
  const glm::vec4 center_scale(center, 1.0f / (radius * kFrameMargin));
  const auto res = static_cast<std::uint32_t>(cfg.resolution);
  const ImageInfo target_info{kListTargetFormat, res, res, 1};
  const auto corner_count = static_cast<std::uint32_t>(3 * drawn.size());
  const auto groups = static_cast<std::uint32_t>((n + 63) / 64);
  const Pipeline& raster = front_layers ? list_all : list_back;
  dropped = 0;
  submitted = 0;
  const int first_camera = camera_begin, end_camera = camera_end > 0 ? camera_end : cfg.views;
  for (int base = first_camera; base < end_camera;) {
    const auto count = static_cast<std::uint32_t>(std::min(batch, end_camera - base));
    RenderGraph g;
    auto cnt = g.import_buffer("counts", counts.size, {counts.get()});
    auto smp = g.import_buffer("samples", samples.size, {samples.get()});
    auto pos = g.import_buffer("corners", corner_buffer.size, {corner_buffer.get()});
    auto hd = g.import_buffer("list_heads", heads.size, {heads.get()});
    auto nd = g.import_buffer("list_nodes", nodes.size, {nodes.get()});
    auto ctr = g.import_buffer("list_counter", counter.size, {counter.get()});
    if (base == first_camera) {
      auto clear = g.add_pass("clear_counts", PassKind::Transfer);
      cnt = clear.transfer_dst(cnt);
      clear.execute([&, cnt](PassContext& pc) { vkCmdFillBuffer(pc.cmd, pc.buffer(cnt), 0, VK_WHOLE_SIZE, 0); });
    }
    auto reset = g.add_pass("reset_lists", PassKind::Transfer);
    hd = reset.transfer_dst(hd);
    ctr = reset.transfer_dst(ctr);
    reset.execute([&, hd, ctr](PassContext& pc) {
      vkCmdFillBuffer(pc.cmd, pc.buffer(hd), 0, VK_WHOLE_SIZE, SDFKIT_END_OF_LIST);
      vkCmdFillBuffer(pc.cmd, pc.buffer(ctr), 0, VK_WHOLE_SIZE, 0);
    });
    auto list = g.add_pass("fragment_lists", PassKind::Graphics);
    list.color(g.create_image("list_target", target_info), LoadOp::DontCare);
    list.vertex(pos);
    hd = list.atomic(hd);
    ctr = list.atomic(ctr);
    nd = list.storage_write(nd);
    const ListPush lp{center_scale, static_cast<std::uint32_t>(base), cfg.resolution,
                      static_cast<std::uint32_t>(node_capacity)};
    list.execute([&, lp, count, base](PassContext& pc) {
      const VkDeviceSize zero = 0;
      const VkBuffer vb = pc.buffer(pos);
      vkCmdBindVertexBuffers(pc.cmd, 0, 1, &vb, &zero);
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, raster.get());
      vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, raster.layout.get(), 0, 1, &list_set, 0,
                              nullptr);
      vkCmdPushConstants(pc.cmd, raster.layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                         sizeof(lp), &lp);
      if (bins.empty()) {
        vkCmdDraw(pc.cmd, corner_count, count, 0, 0);
        submitted += static_cast<std::size_t>(corner_count / 3) * count;
        return;
      }
      // One draw per run of consecutive groups that the camera does not skip; the instance
      // index still names the camera within the batch.
      for (std::uint32_t c = 0; c < count; ++c) {
        const glm::vec3 view(cameras[static_cast<std::size_t>(base) + c].dir);
        for (std::size_t b = 0; b < bins.size();) {
          if (glm::dot(bins[b].dir, view) < bins[b].skip_below) {
            ++b;
            continue;
          }
          const std::uint32_t first = bins[b].first;
          std::uint32_t end = first + bins[b].count;
          for (++b; b < bins.size() && !(glm::dot(bins[b].dir, view) < bins[b].skip_below); ++b)
            end = bins[b].first + bins[b].count;
          vkCmdDraw(pc.cmd, 3 * (end - first), 1, 3 * first, c);
          submitted += end - first;
        }
      }
    });
    auto rs = g.add_pass("resolve_lists", PassKind::Compute);
    rs.storage_read(hd);
    rs.storage_read(nd);
    rs.storage_read(ctr);
    cnt = rs.atomic(cnt);
    smp = rs.storage_write(smp);
    const ResolvePush rp{center_scale, static_cast<std::uint32_t>(base), count, static_cast<std::uint32_t>(n),
                         max_samples, cos_half, static_cast<std::uint32_t>(rule), cfg.resolution,
                         1.0f / static_cast<float>(cfg.resolution), static_cast<std::uint32_t>(node_capacity)};
    rs.execute([&, rp](PassContext& pc) {
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, resolve.get());
      vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, resolve.layout.get(), 0, 1, &resolve_set, 0,
                              nullptr);
      vkCmdPushConstants(pc.cmd, resolve.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(rp), &rp);
      vkCmdDispatch(pc.cmd, groups, 1, 1);
    });
    const CompiledGraph plan = g.compile();
    if (base == first_camera && log_level() <= LogLevel::Debug)
      log_debug("fragment-list render graph (first batch):\n" + plan.describe());
    auto t = execute(*ctx, plan, transients, {.profile = cfg.profile});
    gpu.insert(gpu.end(), t.begin(), t.end());

    const std::uint32_t appended = *static_cast<const std::uint32_t*>(counter.mapped());
    if (appended > node_capacity) {
      // The resolve pass skipped this batch: grow and run it again.
      dropped += appended - node_capacity;
      grow_nodes(static_cast<std::size_t>(appended) + appended / 4);
      write_sets();
      continue;
    }
    base += static_cast<int>(count);
  }
}

void DepthPeelBackend::Impl::upload_points(const SdfQuery& query) {
  const std::size_t n = query.size();
  auto* p = static_cast<glm::vec4*>(points.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 nrm = query.normals[i];
    const bool valid = query.valid.empty() || query.valid[i];
    p[i] = glm::vec4(query.origins[i] - query.origin_offset * nrm, valid ? 1.0f : 0.0f);
    p[n + i] = glm::vec4(-nrm, 0.0f);
  }
}

void DepthPeelBackend::Impl::stage_samples(std::size_t n, std::uint32_t max_samples, std::vector<PassTiming>& gpu) {
  const VkDeviceSize count_bytes = 4 * static_cast<VkDeviceSize>(n);
  const VkDeviceSize sample_bytes = static_cast<VkDeviceSize>(n) * max_samples * sizeof(glm::vec2);
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  if (!staged_counts.buffer || staged_counts.size < count_bytes)
    staged_counts = create_buffer(*ctx, count_bytes, usage, MemoryUse::Readback);
  if (!staged_samples.buffer || staged_samples.size < sample_bytes)
    staged_samples = create_buffer(*ctx, sample_bytes, usage, MemoryUse::Readback);
  RenderGraph g;
  auto cnt = g.import_buffer("counts", counts.size, {counts.get()});
  auto smp = g.import_buffer("samples", samples.size, {samples.get()});
  auto sc = g.import_buffer("staged_counts", staged_counts.size, {staged_counts.get()});
  auto ss = g.import_buffer("staged_samples", staged_samples.size, {staged_samples.get()});
  auto copy = g.add_pass("stage_samples", PassKind::Transfer);
  copy.transfer_src(cnt);
  copy.transfer_src(smp);
  sc = copy.transfer_dst(sc);
  ss = copy.transfer_dst(ss);
  copy.side_effect();  // read by the host
  copy.execute([&, cnt, smp, sc, ss](PassContext& pc) {
    const VkBufferCopy c1{0, 0, count_bytes}, c2{0, 0, sample_bytes};
    vkCmdCopyBuffer(pc.cmd, pc.buffer(cnt), pc.buffer(sc), 1, &c1);
    vkCmdCopyBuffer(pc.cmd, pc.buffer(smp), pc.buffer(ss), 1, &c2);
  });
  auto t = execute(*ctx, g.compile(), transients, {.profile = cfg.profile});
  gpu.insert(gpu.end(), t.begin(), t.end());
}

RawSdf DepthPeelBackend::Impl::run_gather(std::size_t n, std::uint32_t max_samples, std::vector<PassTiming>* gpu,
                                          const Buffer* upload_counts, const Buffer* upload_samples) {
  RenderGraph g;
  auto cnt = g.import_buffer("counts", counts.size, {counts.get()});
  auto smp = g.import_buffer("samples", samples.size, {samples.get()});
  auto res = g.import_buffer("result", result.size, {result.get()});
  if (upload_counts && upload_samples) {
    // Test entry: the host's samples replace what the diameter passes would have stored.
    auto sc = g.import_buffer("staged_counts", upload_counts->size, {upload_counts->get()});
    auto ss = g.import_buffer("staged_samples", upload_samples->size, {upload_samples->get()});
    auto up = g.add_pass("upload_samples", PassKind::Transfer);
    up.transfer_src(sc);
    up.transfer_src(ss);
    cnt = up.transfer_dst(cnt);
    smp = up.transfer_dst(smp);
    up.execute([&, sc, ss, cnt, smp](PassContext& pc) {
      const VkBufferCopy c1{0, 0, upload_counts->size};
      const VkBufferCopy c2{0, 0, upload_samples->size};
      vkCmdCopyBuffer(pc.cmd, pc.buffer(sc), pc.buffer(cnt), 1, &c1);
      vkCmdCopyBuffer(pc.cmd, pc.buffer(ss), pc.buffer(smp), 1, &c2);
    });
  }
  auto p = g.add_pass("gather", PassKind::Compute);
  p.storage_read(cnt);
  smp = p.storage_read_write(smp);
  res = p.storage_write(res);
  const GatherPush push{static_cast<std::uint32_t>(n), max_samples};
  p.execute([&](PassContext& pc) {
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, gather.get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, gather.layout.get(), 0, 1, &gather_set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, gather.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    vkCmdDispatch(pc.cmd, static_cast<std::uint32_t>((n + 63) / 64), 1, 1);
  });
  auto t = execute(*ctx, g.compile(), transients, {.profile = cfg.profile});
  if (gpu) gpu->insert(gpu->end(), t.begin(), t.end());
  RawSdf out;
  out.values.resize(n);
  out.kept_rays.resize(n);
  const auto* r = static_cast<const std::uint32_t*>(result.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(&out.values[i], &r[4 * i], 4);
    out.kept_rays[i] = r[4 * i + 1];
  }
  return out;
}

void DepthPeelBackend::Impl::append_lane_samples(const Impl& second, std::size_t n, std::uint32_t max_samples) {
  auto* have_counts = static_cast<std::uint32_t*>(staged_counts.mapped());
  auto* have_samples = static_cast<glm::vec2*>(staged_samples.mapped());
  const auto* more_counts = static_cast<const std::uint32_t*>(second.staged_counts.mapped());
  const auto* more_samples = static_cast<const glm::vec2*>(second.staged_samples.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t have = std::min(have_counts[i], max_samples);
    const std::uint32_t add = std::min(more_counts[i], max_samples - have);
    const std::size_t base = i * max_samples;
    std::copy_n(more_samples + base, add, have_samples + base + have);
    have_counts[i] += more_counts[i];
  }
}

namespace {

int resolve_lanes(const DepthPeelConfig& config, const Context& ctx) {
  if (config.mode != PeelMode::FragmentLists) return 1;
  if (config.lanes > 0) return std::min(config.lanes, 2);
  return ctx.info().type == "cpu" && config.views >= 16 ? 2 : 1;
}

}  // namespace

DepthPeelBackend::DepthPeelBackend(const DepthPeelConfig& config) : impl_(std::make_unique<Impl>(config)) {
  if (resolve_lanes(config, *impl_->ctx) == 2) {
    lane_ = std::make_unique<Impl>(config);
    const int half = config.views / 2;
    impl_->camera_end = half;
    lane_->camera_begin = half;
    lane_->camera_end = config.views;
  }
}
DepthPeelBackend::~DepthPeelBackend() = default;

std::string DepthPeelBackend::device_name() const { return impl_->ctx->info().name; }
Context& DepthPeelBackend::context() { return *impl_->ctx; }
const DepthPeelConfig& DepthPeelBackend::config() const { return impl_->cfg; }
int DepthPeelBackend::last_layer_count() const { return impl_->last_layers; }
std::size_t DepthPeelBackend::fragment_capacity() const { return impl_->node_capacity; }
std::size_t DepthPeelBackend::last_dropped_fragments() const {
  return impl_->dropped + (lane_ ? lane_->dropped : 0);
}
std::size_t DepthPeelBackend::last_submitted_triangles() const {
  return impl_->submitted + (lane_ ? lane_->submitted : 0);
}
int DepthPeelBackend::lanes() const { return lane_ ? 2 : 1; }
bool DepthPeelBackend::peels_front_layers() const { return impl_->front_layers; }
std::vector<StageTiming> DepthPeelBackend::last_timings() const { return impl_->timings; }
std::size_t DepthPeelBackend::device_memory_bytes() const {
  return static_cast<std::size_t>(impl_->ctx->allocator().peak_bytes_in_use()) +
         (lane_ ? static_cast<std::size_t>(lane_->ctx->allocator().peak_bytes_in_use()) : 0);
}

void DepthPeelBackend::set_mesh(const Mesh& mesh) {
  const auto t0 = Clock::now();
  validate_mesh(mesh, "the mesh given to the Vulkan backend");
  const MeshReport report = analyze(mesh);
  const bool front_layers = impl_->cfg.front_layers == FrontLayers::Always || report.boundary_edges > 0 ||
                            report.non_manifold_edges > 0;
  for (Impl* lane : {impl_.get(), lane_.get()}) {
    if (!lane) continue;
    lane->triangles = mesh.triangles;
    lane->vertex_count = mesh.positions.size();
    lane->front_layers = front_layers;
  }
  const Impl::DrawGeometry geometry = impl_->prepare_geometry(mesh.positions);
  for (Impl* lane : {impl_.get(), lane_.get()}) {
    if (!lane) continue;
    lane->upload_geometry(geometry);
    lane->write_sets();
  }
  impl_->timings = {{"upload_mesh", ms_since(t0)}};
}

void DepthPeelBackend::update_positions(std::span<const glm::vec3> positions) {
  if (impl_->triangles.empty()) throw Error("update_positions() called before set_mesh()");
  if (positions.size() != impl_->vertex_count)
    throw Error("update_positions() got " + std::to_string(positions.size()) + " positions for a mesh of " +
                std::to_string(impl_->vertex_count) + " vertices");
  const auto t0 = Clock::now();
  const Impl::DrawGeometry geometry = impl_->prepare_geometry(positions);
  impl_->upload_geometry(geometry);
  if (lane_) lane_->upload_geometry(geometry);
  impl_->timings = {{"upload_mesh", ms_since(t0)}};
}

RawSdf DepthPeelBackend::compute_in_chunks(const SdfQuery& query, const SdfOptions& options, std::size_t per_chunk) {
  RawSdf out;
  out.values.reserve(query.size());
  out.kept_rays.reserve(query.size());
  std::vector<StageTiming> total;
  std::size_t chunks = 0;
  for (std::size_t begin = 0; begin < query.size(); begin += per_chunk, ++chunks) {
    const std::size_t end = std::min(query.size(), begin + per_chunk);
    SdfQuery part;
    part.domain = query.domain;
    part.origin_offset = query.origin_offset;
    part.origins.assign(query.origins.begin() + static_cast<std::ptrdiff_t>(begin), query.origins.begin() + static_cast<std::ptrdiff_t>(end));
    part.normals.assign(query.normals.begin() + static_cast<std::ptrdiff_t>(begin), query.normals.begin() + static_cast<std::ptrdiff_t>(end));
    if (!query.valid.empty())
      part.valid.assign(query.valid.begin() + static_cast<std::ptrdiff_t>(begin), query.valid.begin() + static_cast<std::ptrdiff_t>(end));
    RawSdf r = compute(part, options);
    out.values.insert(out.values.end(), r.values.begin(), r.values.end());
    out.kept_rays.insert(out.kept_rays.end(), r.kept_rays.begin(), r.kept_rays.end());
    for (const StageTiming& t : impl_->timings) {
      auto it = std::find_if(total.begin(), total.end(), [&](const StageTiming& x) { return x.stage == t.stage; });
      if (it == total.end())
        total.push_back(t);
      else if (t.stage != "upload_mesh")
        it->milliseconds += t.milliseconds;
    }
  }
  log_info("depth peeling: " + std::to_string(query.size()) + " points in " + std::to_string(chunks) +
           " chunks (the per-point sample storage exceeds one storage buffer)");
  impl_->timings = std::move(total);
  return out;
}

RawSdf DepthPeelBackend::compute(const SdfQuery& query, const SdfOptions& options) {
  Impl& m = *impl_;
  validate_options(options);
  if (m.triangles.empty()) throw Error("compute() called before set_mesh()");
  // Keep the geometry upload of the preceding set_mesh/update_positions, replace the rest.
  std::erase_if(m.timings, [](const StageTiming& t) { return t.stage != "upload_mesh"; });
  m.ctx->allocator().reset_peak();
  if (lane_) lane_->ctx->allocator().reset_peak();
  const std::size_t n = query.size();
  if (n == 0) return {};

  auto t0 = Clock::now();
  const std::uint32_t max_samples = m.cfg.max_samples_per_point > 0
                                        ? static_cast<std::uint32_t>(m.cfg.max_samples_per_point)
                                        : m.auto_max_samples(options.cone_degrees);
  // The per-point sample storage must fit one storage buffer: larger queries run in chunks of
  // points, each chunk rasterizing every camera again (a huge mesh costs more passes, not more
  // memory than the device can address).
  const std::size_t per_chunk = static_cast<std::size_t>(
      m.ctx->capabilities().max_storage_buffer_range / (static_cast<VkDeviceSize>(max_samples) * sizeof(glm::vec2)));
  const std::size_t limit = m.cfg.max_points_per_chunk > 0
                                ? std::min(per_chunk, static_cast<std::size_t>(m.cfg.max_points_per_chunk))
                                : per_chunk;
  if (limit == 0)
    throw DeviceError("one point's sample storage exceeds the device's storage buffer range; use fewer views or a "
                      "smaller max_samples_per_point");
  if (n > limit) return compute_in_chunks(query, options, limit);
  m.ensure_query_buffers(n, max_samples);
  m.upload_points(query);
  Impl* lane = m.lists ? lane_.get() : nullptr;
  if (lane) {
    lane->ensure_query_buffers(n, max_samples);
    lane->upload_points(query);
  }
  m.timings.push_back({"upload", ms_since(t0)});

  t0 = Clock::now();
  const glm::vec4 center_scale(m.center, 1.0f / (m.radius * kFrameMargin));
  const auto res = static_cast<std::uint32_t>(m.cfg.resolution);
  const ImageInfo ring_info{kLayerFormat, res, res, static_cast<std::uint32_t>(2 * m.batch)};
  const ImageInfo depth_info{kDepthFormat, res, res, static_cast<std::uint32_t>(2 * m.batch)};
  const float cos_half = cos_half_cone(options.cone_degrees);
  const auto corner_count = static_cast<std::uint32_t>(3 * m.drawn.size());
  const auto groups = static_cast<std::uint32_t>((n + 63) / 64);
  std::vector<PassTiming> gpu;
  bool cap_hit = false;
  m.last_layers = 0;
  int previous_camera_layers = 1;
  if (m.lists) {
    if (lane) {
      // Two lanes: each context renders its half of the cameras on its own thread (lavapipe
      // bins on one thread per queue, so the second context's binning overlaps the first one's
      // rasterization), then the second lane's samples are appended to the first lane's per point.
      std::vector<PassTiming> lane_gpu;
      auto other = std::async(std::launch::async, [&] {
        lane->run_lists(n, max_samples, cos_half, options.false_hit, lane_gpu);
        lane->stage_samples(n, max_samples, lane_gpu);
      });
      std::exception_ptr failure;
      try {
        m.run_lists(n, max_samples, cos_half, options.false_hit, gpu);
        m.stage_samples(n, max_samples, gpu);
      } catch (...) {
        failure = std::current_exception();
      }
      other.get();  // rethrows the lane's failure
      if (failure) std::rethrow_exception(failure);
      gpu.insert(gpu.end(), lane_gpu.begin(), lane_gpu.end());
      for (const std::string& message : lane->ctx->validation_messages())
        m.ctx->report_validation_message(VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
                                         ("(second lane) " + message).c_str());
      lane->ctx->clear_validation_messages();
      m.append_lane_samples(*lane, n, max_samples);
    } else {
      m.run_lists(n, max_samples, cos_half, options.false_hit, gpu);
    }
    m.last_layers = 1;
    const std::size_t dropped = m.dropped + (lane ? lane->dropped : 0);
    const std::size_t capacity = std::max(m.node_capacity, lane ? lane->node_capacity : 0);
    if (dropped > 0)
      log_warning("the fragment-list node buffer overflowed (" + std::to_string(dropped) +
                  " fragments dropped); it was grown to " + std::to_string(capacity) +
                  " nodes and the affected camera batches were run again");
  }

  for (int base = 0; base < (m.lists ? 0 : m.cfg.views); base += m.batch) {
    const auto count = static_cast<std::uint32_t>(std::min(m.batch, m.cfg.views - base));
    int layer = 1;
    bool more = true;
    while (more && layer <= m.cfg.max_layers) {
      const int wanted = m.layers_per_submit > 0 ? m.layers_per_submit
                         : layer == 1           ? std::max(1, previous_camera_layers - 1)
                                                : 1;
      const int steps = std::min(wanted, m.cfg.max_layers - layer + 1);
      RenderGraph g;
      ImageHandle rings[3];
      for (int r = 0; r < 3; ++r) {
        ExternalImage e{m.ring[r].get(), m.ring[r].view.get()};
        e.initial = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     m.ring_ready[r] ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED};
        e.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        rings[r] = g.import_image("layer" + std::to_string(r), ring_info, e);
      }
      auto depth = g.create_image("depth", depth_info);
      auto cnt = g.import_buffer("counts", m.counts.size, {m.counts.get()});
      auto pos = g.import_buffer("corners", m.corner_buffer.size, {m.corner_buffer.get()});
      auto smp = g.import_buffer("samples", m.samples.size, {m.samples.get()});

      if (base == 0 && layer == 1) {
        auto clear = g.add_pass("clear_counts", PassKind::Transfer);
        cnt = clear.transfer_dst(cnt);
        clear.execute([&, cnt](PassContext& pc) { vkCmdFillBuffer(pc.cmd, pc.buffer(cnt), 0, VK_WHOLE_SIZE, 0); });
      }
      auto pend = g.import_buffer("pending", m.pending.size, {m.pending.get()});
      auto reset = g.add_pass("reset_queries", PassKind::Transfer);
      reset.side_effect();
      pend = reset.transfer_dst(pend);
      reset.execute([&, steps, pend](PassContext& pc) {
        vkCmdResetQueryPool(pc.cmd, m.occlusion.get(), 0, static_cast<std::uint32_t>(steps));
        vkCmdFillBuffer(pc.cmd, pc.buffer(pend), 0, VK_WHOLE_SIZE, 0);
      });
      for (int s = 0; s < steps; ++s) {
        const int k = layer + s;
        const int cur = k % 3, prev = (k + 2) % 3;
        const auto first = static_cast<std::uint32_t>(k == 1);
        auto peel = g.add_pass("peel", PassKind::Graphics);
        peel.sampled(rings[prev]);
        peel.vertex(pos);
        depth = peel.depth(depth, LoadOp::Clear, 1.0f);
        rings[cur] = peel.color(rings[cur], LoadOp::Clear, VkClearColorValue{.uint32 = {SDFKIT_NO_SURFACE_BITS, 0, 0, 0}});
        peel.side_effect();  // the occlusion query
        const PeelPush pp{center_scale, static_cast<std::uint32_t>(base), first, kPeelEpsilon, 0};
        peel.execute([&, pp, prev, s, count](PassContext& pc) {
          const VkDeviceSize zero = 0;
          const VkBuffer vb = pc.buffer(pos);
          vkCmdBindVertexBuffers(pc.cmd, 0, 1, &vb, &zero);
          vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m.peel_front.layout.get(), 0, 1,
                                  &m.peel_sets[prev], 0, nullptr);
          vkCmdBeginQuery(pc.cmd, m.occlusion.get(), static_cast<std::uint32_t>(s), 0);
          PeelPush push = pp;
          for (const Pipeline* p : {&m.peel_front, &m.peel_back}) {
            push.back = p == &m.peel_back ? 1u : 0u;
            if (!push.back && !m.front_layers) continue;  // front layers stay empty (kNoSurface)
            vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p->get());
            vkCmdPushConstants(pc.cmd, p->layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                               0, sizeof(push), &push);
            vkCmdDraw(pc.cmd, corner_count, count, 0, 0);
          }
          vkCmdEndQuery(pc.cmd, m.occlusion.get(), static_cast<std::uint32_t>(s));
        });
        auto diam = g.add_pass("diameter", PassKind::Compute);
        diam.sampled(rings[prev]);
        diam.sampled(rings[cur]);
        cnt = diam.atomic(cnt);
        smp = diam.storage_write(smp);
        pend = diam.atomic(pend);
        const DiameterPush dp{center_scale, static_cast<std::uint32_t>(base), count, first,
                              static_cast<std::uint32_t>(n), max_samples, cos_half,
                              static_cast<std::uint32_t>(options.false_hit), m.cfg.resolution,
                              1.0f / static_cast<float>(m.cfg.resolution), static_cast<std::uint32_t>(s)};
        diam.execute([&, dp, cur](PassContext& pc) {
          vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m.diameter.get());
          vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m.diameter.layout.get(), 0, 1,
                                  &m.diameter_sets[cur], 0, nullptr);
          vkCmdPushConstants(pc.cmd, m.diameter.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(dp), &dp);
          vkCmdDispatch(pc.cmd, groups, 1, 1);
        });
      }
      const CompiledGraph plan = g.compile();
      if (base == 0 && layer == 1 && log_level() <= LogLevel::Debug)
        log_debug("depth peel render graph (first submission):\n" + plan.describe());
      auto t = execute(*m.ctx, plan, m.transients, {.profile = m.cfg.profile});
      gpu.insert(gpu.end(), t.begin(), t.end());
      // Only the images this graph used were moved to SHADER_READ_ONLY (their final layout).
      for (int k = layer; k < layer + steps; ++k) m.ring_ready[k % 3] = m.ring_ready[(k + 2) % 3] = true;

      std::vector<std::uint64_t> frags(static_cast<std::size_t>(steps));
      check(vkGetQueryPoolResults(m.ctx->device(), m.occlusion.get(), 0, static_cast<std::uint32_t>(steps),
                                  frags.size() * 8, frags.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "reading occlusion queries");
      // Stop after the first step whose layer was empty, or after which no query point can
      // still be accepted (every candidate lies in front of that back layer).
      const auto* pending_points = static_cast<const std::uint32_t*>(m.pending.mapped());
      for (int s = 0; s < steps; ++s)
        if (frags[static_cast<std::size_t>(s)] == 0 || pending_points[s] == 0) {
          more = false;
          const int used = frags[static_cast<std::size_t>(s)] == 0 ? layer + s - 1 : layer + s;
          m.last_layers = std::max(m.last_layers, used);
          previous_camera_layers = layer + s;  // passes this camera needed
          break;
        }
      layer += steps;
      if (more && layer > m.cfg.max_layers) {
        cap_hit = true;
        m.last_layers = m.cfg.max_layers;
      }
    }
  }
  if (cap_hit)
    log_warning("depth peeling stopped at max_layers = " + std::to_string(m.cfg.max_layers) +
                " with fragments still coming; deeper layers were ignored");
  m.timings.push_back({m.lists ? "lists_and_resolve" : "peel_and_diameter", ms_since(t0)});

  t0 = Clock::now();
  RawSdf out = m.lists && lane ? m.run_gather(n, max_samples, &gpu, &m.staged_counts, &m.staged_samples)
                               : m.run_gather(n, max_samples, &gpu);
  m.timings.push_back({"gather", ms_since(t0)});

  const auto* accepted = static_cast<const std::uint32_t*>(m.result.mapped());
  std::size_t overflow = 0;
  for (std::size_t i = 0; i < n; ++i) overflow += accepted[4 * i + 2] > max_samples;
  if (overflow > 0)
    log_warning(std::to_string(overflow) + " points had more than " + std::to_string(max_samples) +
                " accepted views; the extra samples were dropped");

  if (m.cfg.profile) {
    std::map<std::string, double> sums;
    for (const auto& p : gpu) sums[p.pass] += p.gpu_milliseconds;
    for (const auto& [name, msec] : sums) m.timings.push_back({"gpu_" + name, msec, true});
  }
  return out;
}

RawSdf DepthPeelBackend::gather_on_device(const std::vector<std::vector<std::pair<float, float>>>& samples) {
  Impl& m = *impl_;
  const std::size_t n = samples.size();
  std::uint32_t max_samples = 1;
  for (const auto& s : samples) max_samples = std::max<std::uint32_t>(max_samples, static_cast<std::uint32_t>(s.size()));
  m.ensure_query_buffers(n, max_samples);
  Buffer staged_counts = create_buffer(*m.ctx, m.counts.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Upload);
  Buffer staged_samples = create_buffer(*m.ctx, m.samples.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Upload);
  std::memset(staged_counts.mapped(), 0, m.counts.size);
  auto* cnt = static_cast<std::uint32_t*>(staged_counts.mapped());
  auto* smp = static_cast<glm::vec2*>(staged_samples.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    cnt[i] = static_cast<std::uint32_t>(samples[i].size());
    for (std::size_t j = 0; j < samples[i].size(); ++j)
      smp[i * max_samples + j] = glm::vec2(samples[i][j].first, samples[i][j].second);
  }
  return m.run_gather(n, max_samples, nullptr, &staged_counts, &staged_samples);
}

}  // namespace sdfkit::vk
