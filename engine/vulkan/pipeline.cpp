#include "sdfkit/vulkan/pipeline.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <functional>
#include <map>
#include <string>

namespace sdfkit::vk {

namespace detail {
struct EmbeddedShader {
  const char* name;
  const std::uint32_t* words;
  std::size_t size;  // in words
};
// Defined in the generated embedded_shaders.cpp.
std::span<const EmbeddedShader> embedded_shaders();
}  // namespace detail

std::span<const std::uint32_t> embedded_spirv(std::string_view name) {
  for (const auto& s : detail::embedded_shaders())
    if (name == s.name) return {s.words, s.size};
  throw Error("no embedded shader named '" + std::string(name) + "'");
}

std::vector<std::string_view> embedded_shader_names() {
  std::vector<std::string_view> out;
  for (const auto& s : detail::embedded_shaders()) out.emplace_back(s.name);
  return out;
}

PushConstantLayout push_constant_layout(std::span<const std::uint32_t> spirv) {
  // SPIR-V opcodes and enumerants used here (SPIR-V specification, section 3).
  enum : std::uint32_t {
    kOpTypeInt = 21, kOpTypeFloat = 22, kOpTypeVector = 23, kOpTypeMatrix = 24, kOpTypeStruct = 30,
    kOpTypePointer = 32, kOpVariable = 59, kOpMemberDecorate = 72, kDecorationMatrixStride = 7,
    kDecorationOffset = 35, kStoragePushConstant = 9
  };
  if (spirv.size() < 5 || spirv[0] != 0x07230203u) throw Error("not a SPIR-V module");
  std::map<std::uint32_t, std::vector<std::uint32_t>> types;  // id -> instruction words
  std::map<std::uint32_t, std::uint32_t> pointee;             // push-constant pointer type -> pointee
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> offset, stride;
  std::uint32_t block = 0;
  for (std::size_t i = 5; i < spirv.size();) {
    const std::uint32_t count = spirv[i] >> 16, op = spirv[i] & 0xffffu;
    if (count == 0 || i + count > spirv.size()) throw Error("malformed SPIR-V module");
    const std::span<const std::uint32_t> w = spirv.subspan(i, count);
    if ((op >= kOpTypeInt && op <= kOpTypeMatrix) || op == kOpTypeStruct) types[w[1]] = {w.begin(), w.end()};
    if (op == kOpTypePointer && w[2] == kStoragePushConstant) pointee[w[1]] = w[3];
    if (op == kOpMemberDecorate && w[3] == kDecorationOffset) offset[{w[1], w[2]}] = w[4];
    if (op == kOpMemberDecorate && w[3] == kDecorationMatrixStride) stride[{w[1], w[2]}] = w[4];
    if (op == kOpVariable && w[3] == kStoragePushConstant) block = pointee.at(w[1]);
    i += count;
  }
  PushConstantLayout out;
  if (block == 0) return out;
  const std::vector<std::uint32_t>& st = types.at(block);
  const std::function<std::uint32_t(std::uint32_t, std::uint32_t)> size_of = [&](std::uint32_t type,
                                                                               std::uint32_t matrix_stride) {
    const std::vector<std::uint32_t>& t = types.at(type);
    switch (t[0] & 0xffffu) {
      case kOpTypeInt:
      case kOpTypeFloat: return t[2] / 8;
      case kOpTypeVector: return t[3] * size_of(t[2], 0);
      case kOpTypeMatrix: return t[3] * matrix_stride;
      default: throw Error("push_constant_layout: unsupported member type in the push-constant block");
    }
  };
  for (std::uint32_t m = 0; m + 2 < st.size(); ++m) out.offsets.push_back(offset.at({block, m}));
  if (!out.offsets.empty()) {
    const std::uint32_t last = static_cast<std::uint32_t>(out.offsets.size() - 1);
    const auto it = stride.find({block, last});
    out.size = out.offsets.back() + size_of(st[2 + last], it == stride.end() ? 0 : it->second);
  }
  return out;
}

UniqueShaderModule create_shader_module(VkDevice device, std::span<const std::uint32_t> spirv) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, nullptr, 0,
                              spirv.size_bytes(), spirv.data()};
  VkShaderModule m = VK_NULL_HANDLE;
  check(vkCreateShaderModule(device, &ci, nullptr, &m), "creating a shader module");
  return UniqueShaderModule(device, m);
}

UniqueDescriptorSetLayout create_set_layout(VkDevice device, std::span<const VkDescriptorType> bindings,
                                            VkShaderStageFlags stages) {
  std::vector<VkDescriptorSetLayoutBinding> b(bindings.size());
  for (std::uint32_t i = 0; i < bindings.size(); ++i) b[i] = {i, bindings[i], 1, stages, nullptr};
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, nullptr, 0,
                                     static_cast<std::uint32_t>(b.size()), b.data()};
  VkDescriptorSetLayout l = VK_NULL_HANDLE;
  check(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), "creating a descriptor set layout");
  return UniqueDescriptorSetLayout(device, l);
}

namespace {
UniquePipelineLayout make_layout(VkDevice device, VkDescriptorSetLayout set, std::uint32_t push_bytes,
                                 VkShaderStageFlags stages) {
  VkPushConstantRange range{stages, 0, push_bytes};
  VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, nullptr, 0, 1, &set,
                                push_bytes ? 1u : 0u, push_bytes ? &range : nullptr};
  VkPipelineLayout l = VK_NULL_HANDLE;
  check(vkCreatePipelineLayout(device, &ci, nullptr, &l), "creating a pipeline layout");
  return UniquePipelineLayout(device, l);
}
}  // namespace

Pipeline create_compute_pipeline(Context& ctx, std::string_view shader,
                                 std::span<const VkDescriptorType> bindings, std::uint32_t push_bytes) {
  return create_compute_pipeline(ctx, embedded_spirv(shader), bindings, push_bytes, shader);
}

Pipeline create_compute_pipeline(Context& ctx, std::span<const std::uint32_t> spirv,
                                 std::span<const VkDescriptorType> bindings, std::uint32_t push_bytes,
                                 std::string_view label) {
  if (spirv.empty()) throw Error("the SPIR-V of compute shader " + std::string(label) + " is empty");
  VkDevice dev = ctx.device();
  Pipeline p;
  p.set_layout = create_set_layout(dev, bindings, VK_SHADER_STAGE_COMPUTE_BIT);
  p.layout = make_layout(dev, p.set_layout.get(), push_bytes, VK_SHADER_STAGE_COMPUTE_BIT);
  UniqueShaderModule module = create_shader_module(dev, spirv);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_COMPUTE_BIT,
              module.get(), "main", nullptr};
  ci.layout = p.layout.get();
  VkPipeline pl = VK_NULL_HANDLE;
  check(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pl),
        ("creating the compute pipeline " + std::string(label)).c_str());
  p.pipeline = UniquePipeline(dev, pl);
  return p;
}

Pipeline create_graphics_pipeline(Context& ctx, const GraphicsPipelineDescription& d) {
  VkDevice dev = ctx.device();
  const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  Pipeline p;
  p.set_layout = create_set_layout(dev, d.bindings, stages);
  p.layout = make_layout(dev, p.set_layout.get(), d.push_bytes, stages);
  UniqueShaderModule vs =
      create_shader_module(dev, d.vertex_spirv.empty() ? embedded_spirv(d.vertex_shader) : d.vertex_spirv);
  UniqueShaderModule fs =
      create_shader_module(dev, d.fragment_spirv.empty() ? embedded_spirv(d.fragment_shader) : d.fragment_spirv);
  VkPipelineShaderStageCreateInfo st[2] = {
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT, vs.get(), "main", nullptr},
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT, fs.get(), "main", nullptr}};

  VkVertexInputBindingDescription vb{0, d.vertex_stride, VK_VERTEX_INPUT_RATE_VERTEX};
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  if (d.vertex_stride) {
    vi.vertexBindingDescriptionCount = 1;
    vi.pVertexBindingDescriptions = &vb;
    vi.vertexAttributeDescriptionCount = static_cast<std::uint32_t>(d.attributes.size());
    vi.pVertexAttributeDescriptions = d.attributes.data();
  }
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO, nullptr, 0,
                                            VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, VK_FALSE};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO, nullptr, 0, 1, nullptr, 1, nullptr};
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = d.cull;
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = d.depth_format != VK_FORMAT_UNDEFINED;
  ds.depthWriteEnable = d.depth_format != VK_FORMAT_UNDEFINED && d.depth_write;
  ds.depthCompareOp = d.depth_compare;
  std::vector<VkPipelineColorBlendAttachmentState> blend(d.color_formats.size());
  for (auto& b : blend) b.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = static_cast<std::uint32_t>(blend.size());
  cb.pAttachments = blend.data();
  const VkDynamicState dyn[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO, nullptr, 0, 2, dyn};
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = static_cast<std::uint32_t>(d.color_formats.size());
  ri.pColorAttachmentFormats = d.color_formats.data();
  ri.depthAttachmentFormat = d.depth_format;

  VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  ci.pNext = &ri;
  ci.stageCount = 2;
  ci.pStages = st;
  ci.pVertexInputState = &vi;
  ci.pInputAssemblyState = &ia;
  ci.pViewportState = &vp;
  ci.pRasterizationState = &rs;
  ci.pMultisampleState = &ms;
  ci.pDepthStencilState = &ds;
  ci.pColorBlendState = &cb;
  ci.pDynamicState = &dy;
  ci.layout = p.layout.get();
  VkPipeline pl = VK_NULL_HANDLE;
  check(vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pl),
        ("creating the graphics pipeline " + std::string(d.vertex_shader) + "/" + std::string(d.fragment_shader)).c_str());
  p.pipeline = UniquePipeline(dev, pl);
  return p;
}

UniqueSampler create_nearest_sampler(VkDevice device) {
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_NEAREST;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler s = VK_NULL_HANDLE;
  check(vkCreateSampler(device, &si, nullptr, &s), "creating a sampler");
  return UniqueSampler(device, s);
}

UniqueDescriptorPool create_descriptor_pool(VkDevice device, std::span<const VkDescriptorType> bindings,
                                            std::uint32_t sets) {
  std::map<VkDescriptorType, std::uint32_t> counts;
  for (auto t : bindings) counts[t] += sets;
  std::vector<VkDescriptorPoolSize> sizes;
  for (auto [t, n] : counts) sizes.push_back({t, n});
  VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0, sets,
                                static_cast<std::uint32_t>(sizes.size()), sizes.data()};
  VkDescriptorPool pool = VK_NULL_HANDLE;
  check(vkCreateDescriptorPool(device, &ci, nullptr, &pool), "creating a descriptor pool");
  return UniqueDescriptorPool(device, pool);
}

VkDescriptorSet allocate_set(VkDevice device, VkDescriptorPool pool, VkDescriptorSetLayout layout) {
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, pool, 1, &layout};
  VkDescriptorSet set = VK_NULL_HANDLE;
  check(vkAllocateDescriptorSets(device, &ai, &set), "allocating a descriptor set");
  return set;
}

void write_set(VkDevice device, VkDescriptorSet set, std::span<const DescriptorWrite> writes) {
  std::vector<VkDescriptorBufferInfo> buffers(writes.size());
  std::vector<VkDescriptorImageInfo> images(writes.size());
  std::vector<VkWriteDescriptorSet> w(writes.size());
  for (std::size_t i = 0; i < writes.size(); ++i) {
    const DescriptorWrite& d = writes[i];
    w[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, set, d.binding, 0, 1, d.type, nullptr, nullptr, nullptr};
    if (d.buffer != VK_NULL_HANDLE) {
      buffers[i] = {d.buffer, 0, VK_WHOLE_SIZE};
      w[i].pBufferInfo = &buffers[i];
    } else {
      images[i] = {d.sampler, d.view, d.layout};
      w[i].pImageInfo = &images[i];
    }
  }
  vkUpdateDescriptorSets(device, static_cast<std::uint32_t>(w.size()), w.data(), 0, nullptr);
}

}  // namespace sdfkit::vk
