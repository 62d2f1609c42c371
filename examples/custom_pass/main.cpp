// custom_pass: an outside project adding its own compute pass to sdfkit's render graph.
//
//   1. Makes a torus (sdfkit::shapes) and computes its per-vertex SDF with sdfkit's Vulkan
//      depth-peeling backend.
//   2. On that backend's Vulkan context, builds one render graph:
//        example.clear      transfer  zeroes a counter
//        example.normalise  compute   this project's shader (normalise.comp): the values mapped
//                                     to [0, 1], and the number above a threshold (an atomic)
//        figure.mesh        graphics  sdfkit's own pass (MeshRenderer::add_passes): the torus
//                                     coloured by its SDF
//        example.readback   transfer  results and picture copied to host memory
//      The passes only declare what they read and write; the graph orders them and places
//      every barrier.
//   3. Checks the device's results against the same computation on the CPU.
//
// Usage: custom_pass [picture.png]. Exit code 0 when the device and the CPU agree, 1 otherwise.

#include <sdfkit/core/sdf.hpp>
#include <sdfkit/core/shapes.hpp>
#include <sdfkit/render/figure.hpp>
#include <sdfkit/vulkan/context.hpp>
#include <sdfkit/vulkan/depth_peel.hpp>
#include <sdfkit/vulkan/memory.hpp>
#include <sdfkit/vulkan/pipeline.hpp>
#include <sdfkit/vulkan/render_graph.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <iostream>
#include <span>
#include <string>
#include <vector>

#include "normalise.comp.h"  // normalise_comp_spv: SPIR-V words compiled by CMakeLists.txt

namespace vk = sdfkit::vk;

namespace {

// normalise.comp's push constants (four 4-byte members, same order).
struct NormalisePush {
  float lo = 0.0f, hi = 1.0f;  // range of the values, model units
  float threshold = 0.0f;      // model units
  std::uint32_t count = 0;     // number of values
};

// What normalise.comp computes, on the CPU.
struct Expected {
  std::vector<float> normalised;  // one per value, in [0, 1]
  std::uint32_t above = 0;        // values > threshold
};

Expected on_cpu(std::span<const float> values, const NormalisePush& push) {
  Expected e;
  for (float v : values) {
    e.normalised.push_back((v - push.lo) / (push.hi - push.lo));
    if (v > push.threshold) ++e.above;
  }
  return e;
}

// A buffer the host wrote before the graph runs, imported into the graph in that state.
vk::ExternalBuffer host_written(const vk::Buffer& buffer) {
  vk::ExternalBuffer e;
  e.buffer = buffer.get();
  e.initial = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
  return e;
}

constexpr std::uint32_t kWidth = 256, kHeight = 128;  // the picture, pixels (RGBA8)

}  // namespace

int main(int argc, char** argv) try {
  // 1. The SDF of a torus (tube diameter 0.6), one value per vertex, on the Vulkan backend.
  //    Few views and a small resolution: this runs on a CPU driver (lavapipe) in CI.
  const sdfkit::Mesh mesh = sdfkit::shapes::torus(1.0f, 0.3f, 48, 24);
  vk::DepthPeelConfig config;
  config.views = 64;
  config.resolution = 128;
  vk::DepthPeelBackend backend(config);
  backend.set_mesh(mesh);  // uploads the geometry; the backend is a session that keeps it
  const sdfkit::SdfField field = sdfkit::compute_sdf(backend, mesh, sdfkit::SdfOptions{});
  const std::vector<float>& values = field.values;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  NormalisePush push;
  push.lo = *lo;
  push.hi = *hi > *lo ? *hi : *lo + 1.0f;
  std::vector<float> sorted = values;  // threshold: the median value, so that about half count
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  push.threshold = sorted[sorted.size() / 2];
  push.count = static_cast<std::uint32_t>(values.size());
  std::cout << "SDF of a torus on " << backend.device_name() << ": " << values.size() << " vertices, "
            << push.lo << " .. " << push.hi << "\n";

  // 2. Our pass and sdfkit's render passes in one graph, on the backend's own context.
  vk::Context& ctx = backend.context();
  const VkDeviceSize value_bytes = VkDeviceSize{push.count} * sizeof(float);
  vk::Buffer input = vk::create_buffer(ctx, value_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Upload);
  std::memcpy(input.mapped(), values.data(), value_bytes);
  // Host memory the last pass copies into: normalised values, the counter, then the picture.
  const VkDeviceSize counter_offset = value_bytes, picture_offset = value_bytes + sizeof(std::uint32_t);
  const VkDeviceSize picture_bytes = VkDeviceSize{kWidth} * kHeight * 4;
  vk::Buffer host = vk::create_buffer(ctx, picture_offset + picture_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      vk::MemoryUse::Readback);

  const VkDescriptorType bindings[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                       VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  const vk::Pipeline normalise = vk::create_compute_pipeline(ctx, std::span<const std::uint32_t>(normalise_comp_spv),
                                                             bindings, sizeof(NormalisePush), "normalise.comp");
  const vk::UniqueDescriptorPool pool = vk::create_descriptor_pool(ctx.device(), bindings, 1);
  const VkDescriptorSet set = vk::allocate_set(ctx.device(), pool.get(), normalise.set_layout.get());

  vk::RenderGraph graph;
  const vk::BufferHandle in = graph.import_buffer("example.values", value_bytes, host_written(input));
  vk::BufferHandle out = graph.create_buffer("example.normalised", value_bytes);  // transient
  vk::BufferHandle counter = graph.create_buffer("example.counter", sizeof(std::uint32_t));
  vk::BufferHandle readback = graph.import_buffer("example.readback", host.size, {host.get()});

  auto clear = graph.add_pass("example.clear", vk::PassKind::Transfer);
  counter = clear.transfer_dst(counter);  // each write returns the resource's next version
  clear.execute([counter](vk::PassContext& pc) {
    vkCmdFillBuffer(pc.cmd, pc.buffer(counter), 0, sizeof(std::uint32_t), 0);
  });

  auto compute = graph.add_pass("example.normalise", vk::PassKind::Compute);
  compute.storage_read(in);
  out = compute.storage_write(out);
  counter = compute.atomic(counter);
  compute.execute([&ctx, &normalise, set, push, in, out, counter](vk::PassContext& pc) {
    // Transient buffers exist only while the graph runs: point the descriptor set at them now.
    const vk::DescriptorWrite writes[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(in)},
                                          {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(out)},
                                          {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(counter)}};
    vk::write_set(ctx.device(), set, writes);
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, normalise.get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, normalise.layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, normalise.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    vkCmdDispatch(pc.cmd, (push.count + 63) / 64, 1, 1);
  });

  // sdfkit's own passes: the torus coloured by its SDF, seen from two sides, on white.
  sdfkit::render::MeshRenderer renderer(ctx);
  renderer.set_mesh(mesh, values, field.domain, sdfkit::render::sdf_scale(push.lo, push.hi));
  const auto views = sdfkit::render::orbit_views(mesh, 2, kWidth, kHeight);
  const vk::ImageHandle picture = renderer.add_passes(graph, kWidth, kHeight, views);

  auto copy = graph.add_pass("example.readback", vk::PassKind::Transfer);
  copy.transfer_src(out);
  copy.transfer_src(counter);
  copy.transfer_src(picture);
  readback = copy.transfer_dst(readback);
  copy.side_effect();  // nothing in the graph reads `readback`: the host does
  copy.execute([=](vk::PassContext& pc) {
    const VkBufferCopy values_region{0, 0, value_bytes};
    vkCmdCopyBuffer(pc.cmd, pc.buffer(out), pc.buffer(readback), 1, &values_region);
    const VkBufferCopy counter_region{0, counter_offset, sizeof(std::uint32_t)};
    vkCmdCopyBuffer(pc.cmd, pc.buffer(counter), pc.buffer(readback), 1, &counter_region);
    VkBufferImageCopy picture_region{};
    picture_region.bufferOffset = picture_offset;
    picture_region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    picture_region.imageExtent = {kWidth, kHeight, 1};
    vkCmdCopyImageToBuffer(pc.cmd, pc.image(picture), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.buffer(readback), 1,
                           &picture_region);
  });

  const vk::CompiledGraph plan = graph.compile();
  std::cout << plan.describe();
  vk::TransientPool transients(ctx);
  vk::execute(ctx, plan, transients);

  // 3. The device's results against the CPU's.
  const auto* bytes = static_cast<const std::uint8_t*>(host.mapped());
  std::vector<float> gpu_normalised(push.count);
  std::memcpy(gpu_normalised.data(), bytes, value_bytes);
  std::uint32_t gpu_above = 0;
  std::memcpy(&gpu_above, bytes + counter_offset, sizeof(gpu_above));
  const Expected cpu = on_cpu(values, push);
  float max_difference = 0.0f;
  for (std::size_t i = 0; i < gpu_normalised.size(); ++i)
    max_difference = std::max(max_difference, std::abs(gpu_normalised[i] - cpu.normalised[i]));

  sdfkit::render::Image image{static_cast<int>(kWidth), static_cast<int>(kHeight),
                              std::vector<std::uint8_t>(bytes + picture_offset, bytes + picture_offset + picture_bytes)};
  std::size_t drawn = 0;  // pixels that are not the white background
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (std::memcmp(image.pixel(x, y), "\xff\xff\xff", 3) != 0) ++drawn;
  if (argc > 1) sdfkit::render::write_png(argv[1], image);

  const bool counts_match = gpu_above == cpu.above;
  const bool values_match = max_difference <= 1e-6f;
  const bool picture_drawn = drawn > 0;
  const std::size_t validation_messages = ctx.validation_message_count();
  std::cout << "values above " << push.threshold << ": GPU " << gpu_above << ", CPU " << cpu.above
            << (counts_match ? " (match)" : " (MISMATCH)") << "\n"
            << "normalised values: max |GPU - CPU| = " << max_difference << (values_match ? " (match)" : " (MISMATCH)")
            << "\n"
            << "picture: " << drawn << " of " << kWidth * kHeight << " pixels drawn" << (picture_drawn ? "" : " (EMPTY)")
            << "\n"
            << "validation layer: " << (ctx.validation_enabled() ? "on" : "off") << ", " << validation_messages
            << " messages\n";
  for (const std::string& m : ctx.validation_messages()) std::cout << "  " << m << "\n";
  return counts_match && values_match && picture_drawn && validation_messages == 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::cerr << "custom_pass: " << e.what() << "\n";
  return 1;
}
