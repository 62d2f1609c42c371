// The session's resources: context, pipelines, the peel ring, the occlusion query pool, the
// per-query buffers; staging and the gather.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace sdfkit::vk {

namespace {

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


}  // namespace

std::vector<DeviceInfo> list_devices_for_depth_peel() {
  DeviceRequirements req;
  req.shader_output_layer = true;
  return list_devices(req);
}

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
  GraphicsPipelineDescription gd = mesh_raster_pipeline("depth_peel.vert", "depth_peel.frag", kPeelBindings, sizeof(passes::PeelPush));
  gd.color_formats = {kLayerFormat};
  gd.depth_format = kDepthFormat;
  gd.depth_compare = VK_COMPARE_OP_LESS;
  // With this projection a triangle facing the camera is counter-clockwise in framebuffer
  // coordinates (tested: front and back layers feed the analytic tests).
  gd.cull = VK_CULL_MODE_BACK_BIT;
  peel_front = create_graphics_pipeline(*ctx, gd);
  gd.cull = VK_CULL_MODE_FRONT_BIT;
  peel_back = create_graphics_pipeline(*ctx, gd);
  diameter = create_compute_pipeline(*ctx, "diameter.comp", kDiameterBindings, sizeof(passes::DiameterPush));
  gather = create_compute_pipeline(*ctx, "gather.comp", kGatherBindings, sizeof(passes::GatherPush));
  sampler = create_nearest_sampler(dev);


  const auto res = static_cast<std::uint32_t>(cfg.resolution);
  for (int r = 0; r < 3; ++r) {
    ring[r] = create_image(*ctx, {kLayerFormat, res, res, static_cast<std::uint32_t>(2 * batch),
                                  VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
    ring_history[r] = {ring[r].get(), ring[r].view.get(), VK_IMAGE_LAYOUT_UNDEFINED};
  }
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
  GraphicsPipelineDescription gd =
      mesh_raster_pipeline("fragment_list.vert", "fragment_list.frag", kListBindings, sizeof(passes::ListPush));
  gd.color_formats = {kListTargetFormat};
  gd.cull = VK_CULL_MODE_NONE;
  list_all = create_graphics_pipeline(*ctx, gd);
  gd.cull = VK_CULL_MODE_FRONT_BIT;
  list_back = create_graphics_pipeline(*ctx, gd);
  resolve = create_compute_pipeline(*ctx, "fragment_list.comp", kResolveBindings, sizeof(passes::ResolvePush));

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

std::uint32_t DepthPeelBackend::Impl::auto_max_samples(float cone_degrees) const {
  // Cameras inside a cone: at most views * (1 - cos(a/2)) / 2 on average; the Fibonacci set's
  // local count deviates by a few; 25% + 8 of headroom covers every cone.
  const double frac = (1.0 - std::cos(0.5 * cone_degrees * M_PI / 180.0)) / 2.0;
  return static_cast<std::uint32_t>(std::ceil(cfg.views * frac * 1.25)) + 8u;
}

void DepthPeelBackend::Impl::ensure_query_buffers(std::size_t n, std::uint32_t max_samples) {
  const std::size_t cap = std::max<std::size_t>(n, 1);
  if (point_capacity < cap) {
    points = create_buffer(*ctx, 2 * cap * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
    counts = create_buffer(*ctx, cap * 4,
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                           MemoryUse::DeviceLocal);
    result = create_buffer(*ctx, cap * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
    point_capacity = cap;
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
  const BufferHandle src[] = {g.import_buffer("counts", counts.size, {counts.get()}),
                              g.import_buffer("samples", samples.size, {samples.get()})};
  const BufferHandle dst[] = {g.import_buffer("staged_counts", staged_counts.size, {staged_counts.get()}),
                              g.import_buffer("staged_samples", staged_samples.size, {staged_samples.get()})};
  const VkDeviceSize bytes[] = {count_bytes, sample_bytes};
  passes::add_copy_pass(g, "stage_samples", src, dst, bytes, /*host_reads=*/true);
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
    // Test entry and lanes: the host's samples replace what the passes stored.
    const BufferHandle src[] = {g.import_buffer("staged_counts", upload_counts->size, {upload_counts->get()}),
                                g.import_buffer("staged_samples", upload_samples->size, {upload_samples->get()})};
    const BufferHandle dst[] = {cnt, smp};
    const VkDeviceSize bytes[] = {upload_counts->size, upload_samples->size};
    const std::vector<BufferHandle> written = passes::add_copy_pass(g, "upload_samples", src, dst, bytes, false);
    cnt = written[0];
    smp = written[1];
  }
  passes::GatherPass gp;
  gp.pipeline = &gather;
  gp.counts = cnt;
  gp.samples = smp;
  gp.result = res;
  gp.groups = static_cast<std::uint32_t>((n + 63) / 64);
  gp.push = {static_cast<std::uint32_t>(n), max_samples};
  passes::add_gather_pass(g, gp);
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

passes::QueryBuffers DepthPeelBackend::Impl::import_query(RenderGraph& g) const {
  passes::QueryBuffers q;
  q.cameras = g.import_buffer("cameras", camera_buffer.size, {camera_buffer.get()});
  q.points = g.import_buffer("points", points.size, {points.get()});
  q.counts = g.import_buffer("counts", counts.size, {counts.get()});
  q.samples = g.import_buffer("samples", samples.size, {samples.get()});
  return q;
}

}  // namespace sdfkit::vk
