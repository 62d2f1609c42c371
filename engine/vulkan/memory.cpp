#include "sdfkit/vulkan/memory.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <algorithm>

namespace sdfkit::vk {

namespace {
VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) { return a ? (v + a - 1) / a * a : v; }
}  // namespace

Allocation::Allocation(Allocation&& o) noexcept
    : allocator_(std::exchange(o.allocator_, nullptr)), block_(o.block_), memory_(o.memory_),
      offset_(o.offset_), size_(o.size_), mapped_(o.mapped_) {}

Allocation& Allocation::operator=(Allocation&& o) noexcept {
  if (this != &o) {
    release();
    allocator_ = std::exchange(o.allocator_, nullptr);
    block_ = o.block_;
    memory_ = o.memory_;
    offset_ = o.offset_;
    size_ = o.size_;
    mapped_ = o.mapped_;
  }
  return *this;
}

void Allocation::release() {
  if (allocator_) allocator_->free(block_, offset_, size_);
  allocator_ = nullptr;
}

Allocator::Allocator(VkPhysicalDevice physical, VkDevice device, VkDeviceSize block_size)
    : device_(device), block_size_(block_size) {
  vkGetPhysicalDeviceMemoryProperties(physical, &props_);
}

Allocator::~Allocator() = default;

VkDeviceSize Allocator::bytes_reserved() const {
  VkDeviceSize s = 0;
  for (const auto& b : blocks_) s += b->size;
  return s;
}

std::uint32_t Allocator::find_type(std::uint32_t bits, MemoryUse use) const {
  VkMemoryPropertyFlags required = 0, preferred = 0;
  switch (use) {
    case MemoryUse::DeviceLocal: preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT; break;
    case MemoryUse::Upload:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      break;
    case MemoryUse::Readback:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
  }
  int best = -1;
  for (std::uint32_t i = 0; i < props_.memoryTypeCount; ++i) {
    if (!(bits & (1u << i))) continue;
    const VkMemoryPropertyFlags f = props_.memoryTypes[i].propertyFlags;
    if ((f & required) != required) continue;
    if ((f & preferred) == preferred) return i;
    if (best < 0) best = static_cast<int>(i);
  }
  if (best < 0) throw DeviceError("no Vulkan memory type fits the request (type bits " + std::to_string(bits) + ")");
  return static_cast<std::uint32_t>(best);
}

bool Allocator::try_place(Block& b, const VkMemoryRequirements& req, VkDeviceSize& offset) {
  for (std::size_t i = 0; i < b.free.size(); ++i) {
    Range& r = b.free[i];
    const VkDeviceSize start = align_up(r.offset, req.alignment);
    if (start + req.size > r.offset + r.size) continue;
    const Range before{r.offset, start - r.offset};
    const Range after{start + req.size, r.offset + r.size - (start + req.size)};
    b.free.erase(b.free.begin() + static_cast<std::ptrdiff_t>(i));
    auto pos = b.free.begin() + static_cast<std::ptrdiff_t>(i);
    if (after.size) pos = b.free.insert(pos, after);
    if (before.size) b.free.insert(pos, before);
    offset = start;
    return true;
  }
  return false;
}

Allocation Allocator::allocate(const VkMemoryRequirements& req, MemoryUse use, bool linear) {
  const std::uint32_t type = find_type(req.memoryTypeBits, use);
  Allocation a;
  VkDeviceSize offset = 0;
  std::uint32_t index = 0;
  bool placed = false;
  for (; index < blocks_.size(); ++index) {
    Block& b = *blocks_[index];
    if (b.type == type && b.linear == linear && try_place(b, req, offset)) {
      placed = true;
      break;
    }
  }
  if (!placed) {
    auto b = std::make_unique<Block>();
    b->size = std::max(block_size_, align_up(req.size, 1 << 16));
    b->type = type;
    b->linear = linear;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, b->size, type};
    VkDeviceMemory mem = VK_NULL_HANDLE;
    const VkResult r = vkAllocateMemory(device_, &ai, nullptr, &mem);
    if (r != VK_SUCCESS)
      throw DeviceError("could not allocate " + std::to_string(b->size >> 20) +
                        " MiB of device memory (" + result_name(r) + ")");
    b->memory = UniqueMemory(device_, mem);
    if (props_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
      check(vkMapMemory(device_, mem, 0, VK_WHOLE_SIZE, 0, &b->mapped), "mapping device memory");
    b->free.push_back({0, b->size});
    index = static_cast<std::uint32_t>(blocks_.size());
    blocks_.push_back(std::move(b));
    try_place(*blocks_.back(), req, offset);
  }
  Block& b = *blocks_[index];
  a.allocator_ = this;
  a.block_ = index;
  a.memory_ = b.memory.get();
  a.offset_ = offset;
  a.size_ = req.size;
  a.mapped_ = b.mapped ? static_cast<char*>(b.mapped) + offset : nullptr;
  in_use_ += req.size;
  peak_ = std::max(peak_, in_use_);
  return a;
}

void Allocator::free(std::uint32_t block, VkDeviceSize offset, VkDeviceSize size) {
  Block& b = *blocks_[block];
  in_use_ -= size;
  auto it = std::lower_bound(b.free.begin(), b.free.end(), offset,
                             [](const Range& r, VkDeviceSize o) { return r.offset < o; });
  it = b.free.insert(it, Range{offset, size});
  // Merge with the next range, then with the previous one.
  if (auto next = it + 1; next != b.free.end() && it->offset + it->size == next->offset) {
    it->size += next->size;
    b.free.erase(next);
  }
  if (it != b.free.begin()) {
    auto prev = it - 1;
    if (prev->offset + prev->size == it->offset) {
      prev->size += it->size;
      b.free.erase(it);
    }
  }
}

Buffer create_buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use) {
  Buffer out;
  out.size = size;
  VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  ci.size = std::max<VkDeviceSize>(size, 4);
  ci.usage = usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buf = VK_NULL_HANDLE;
  check(vkCreateBuffer(ctx.device(), &ci, nullptr, &buf), "creating a buffer");
  out.buffer = UniqueBuffer(ctx.device(), buf);
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(ctx.device(), buf, &req);
  out.memory = ctx.allocator().allocate(req, use, true);
  check(vkBindBufferMemory(ctx.device(), buf, out.memory.memory(), out.memory.offset()),
        "binding buffer memory");
  return out;
}

VkImageAspectFlags aspect_of(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_X8_D24_UNORM_PACK32: return VK_IMAGE_ASPECT_DEPTH_BIT;
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
    case VK_FORMAT_D16_UNORM_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    default: return VK_IMAGE_ASPECT_COLOR_BIT;
  }
}

Image create_image(Context& ctx, const ImageDescription& d) {
  Image out;
  out.description = d;
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = d.format;
  ci.extent = {d.width, d.height, 1};
  ci.mipLevels = 1;
  ci.arrayLayers = d.layers;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = d.usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage img = VK_NULL_HANDLE;
  check(vkCreateImage(ctx.device(), &ci, nullptr, &img), "creating an image");
  out.image = UniqueImage(ctx.device(), img);
  VkMemoryRequirements req{};
  vkGetImageMemoryRequirements(ctx.device(), img, &req);
  out.memory = ctx.allocator().allocate(req, MemoryUse::DeviceLocal, false);
  check(vkBindImageMemory(ctx.device(), img, out.memory.memory(), out.memory.offset()),
        "binding image memory");
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = img;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vi.format = d.format;
  vi.subresourceRange = {aspect_of(d.format), 0, 1, 0, d.layers};
  VkImageView view = VK_NULL_HANDLE;
  check(vkCreateImageView(ctx.device(), &vi, nullptr, &view), "creating an image view");
  out.view = UniqueImageView(ctx.device(), view);
  return out;
}

}  // namespace sdfkit::vk
