#pragma once
// Shader modules from embedded SPIR-V, compute/graphics pipeline owners, and a descriptor-set
// helper. SPIR-V is compiled from glsl/ at build time and looked up by file name.

#include "sdfkit/vulkan/handles.hpp"

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace sdfkit::vk {

class Context;

// The SPIR-V words of an embedded shader ("gather.comp"); throws Error for an unknown name.
std::span<const std::uint32_t> embedded_spirv(std::string_view name);
std::vector<std::string_view> embedded_shader_names();

UniqueShaderModule create_shader_module(VkDevice device, std::span<const std::uint32_t> spirv);

// The push-constant block of a SPIR-V module as the shader sees it (reflection of its
// OpMemberDecorate Offset decorations): each member's byte offset in declaration order and the
// block's size (last offset + last member's size). Empty offsets when the module has none.
// Holds the C++ mirrors of the blocks to the GLSL (tests/vulkan/push_constants_test.cpp).
struct PushConstantLayout {
  std::vector<std::uint32_t> offsets;
  std::uint32_t size = 0;
};
PushConstantLayout push_constant_layout(std::span<const std::uint32_t> spirv);

// A pipeline with its layout and one descriptor-set layout (set 0).
struct Pipeline {
  UniqueDescriptorSetLayout set_layout;
  UniquePipelineLayout layout;
  UniquePipeline pipeline;
  VkPipeline get() const { return pipeline.get(); }
};

// Set-0 bindings in order 0..n-1, visible to `stages`.
UniqueDescriptorSetLayout create_set_layout(VkDevice device, std::span<const VkDescriptorType> bindings,
                                            VkShaderStageFlags stages);

// A compute pipeline from an embedded shader; `push_bytes` of push constants (0 = none).
Pipeline create_compute_pipeline(Context& ctx, std::string_view shader,
                                 std::span<const VkDescriptorType> bindings, std::uint32_t push_bytes);

// The same from the caller's own SPIR-V (entry point "main"), for embedding projects that compile
// their shaders themselves; `label` names the shader in error messages.
Pipeline create_compute_pipeline(Context& ctx, std::span<const std::uint32_t> spirv,
                                 std::span<const VkDescriptorType> bindings, std::uint32_t push_bytes,
                                 std::string_view label = "(caller's SPIR-V)");

// What a graphics pipeline for dynamic rendering needs beyond its shaders.
struct GraphicsPipelineDescription {
  std::string_view vertex_shader, fragment_shader;  // embedded shaders, by file name
  // The caller's own SPIR-V instead (entry point "main"); used when not empty. The names above
  // then only label error messages.
  std::span<const std::uint32_t> vertex_spirv, fragment_spirv;
  std::vector<VkDescriptorType> bindings;        // set 0
  std::uint32_t push_bytes = 0;                  // push constants for both stages
  std::vector<VkVertexInputAttributeDescription> attributes;  // binding 0
  std::uint32_t vertex_stride = 0;               // 0 = no vertex input
  std::vector<VkFormat> color_formats;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  VkCompareOp depth_compare = VK_COMPARE_OP_LESS;
  bool depth_write = true;
  VkCullModeFlags cull = VK_CULL_MODE_NONE;
};

// Viewport and scissor are dynamic state.
Pipeline create_graphics_pipeline(Context& ctx, const GraphicsPipelineDescription& description);

// A nearest-neighbour, clamp-to-edge sampler (texelFetch-style lookups).
UniqueSampler create_nearest_sampler(VkDevice device);

// A descriptor pool sized for `sets` sets of the given bindings.
UniqueDescriptorPool create_descriptor_pool(VkDevice device, std::span<const VkDescriptorType> bindings,
                                            std::uint32_t sets);
VkDescriptorSet allocate_set(VkDevice device, VkDescriptorPool pool, VkDescriptorSetLayout layout);

// Fills one descriptor set; each write names its binding and one buffer or image.
struct DescriptorWrite {
  std::uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  VkBuffer buffer = VK_NULL_HANDLE;  // buffers: whole range
  VkImageView view = VK_NULL_HANDLE; // images
  VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;
  VkSampler sampler = VK_NULL_HANDLE;
};
void write_set(VkDevice device, VkDescriptorSet set, std::span<const DescriptorWrite> writes);

}  // namespace sdfkit::vk
