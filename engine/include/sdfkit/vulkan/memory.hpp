#pragma once
// A small device-memory sub-allocator (blocks per memory type, first-fit free lists with
// alignment, neighbours merged on free) and buffer/image owners built on it.

#include "sdfkit/vulkan/handles.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace sdfkit::vk {

class Context;
class Allocator;

// A range of one block. Returns itself to the allocator on destruction; the allocator must
// outlive every allocation it made.
class Allocation {
public:
  Allocation() = default;
  ~Allocation() { release(); }
  Allocation(Allocation&& o) noexcept;
  Allocation& operator=(Allocation&& o) noexcept;
  Allocation(const Allocation&) = delete;
  Allocation& operator=(const Allocation&) = delete;

  VkDeviceMemory memory() const { return memory_; }
  VkDeviceSize offset() const { return offset_; }
  VkDeviceSize size() const { return size_; }
  // Host pointer at offset() when the memory is host visible, else nullptr.
  void* mapped() const { return mapped_; }
  explicit operator bool() const { return allocator_ != nullptr; }
  void release();

private:
  friend class Allocator;
  Allocator* allocator_ = nullptr;
  std::uint32_t block_ = 0;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize offset_ = 0;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

enum class MemoryUse {
  DeviceLocal,  // prefer DEVICE_LOCAL, no host access
  Upload,       // HOST_VISIBLE | HOST_COHERENT, written by the host
  Readback,     // HOST_VISIBLE | HOST_COHERENT (prefer HOST_CACHED), read by the host
};

class Allocator {
public:
  // `block_size`: bytes per device allocation; larger requests get a block of their own.
  Allocator(VkPhysicalDevice physical, VkDevice device, VkDeviceSize block_size = 64ull << 20);
  ~Allocator();
  Allocator(const Allocator&) = delete;
  Allocator& operator=(const Allocator&) = delete;

  // `linear` separates buffers/linear images from optimal images (bufferImageGranularity).
  Allocation allocate(const VkMemoryRequirements& requirements, MemoryUse use, bool linear);

  VkDeviceSize bytes_in_use() const { return in_use_; }
  VkDeviceSize peak_bytes_in_use() const { return peak_; }
  VkDeviceSize bytes_reserved() const;  // sum of block sizes
  std::size_t block_count() const { return blocks_.size(); }
  void reset_peak() { peak_ = in_use_; }

private:
  friend class Allocation;
  struct Range {
    VkDeviceSize offset, size;
  };
  struct Block {
    UniqueMemory memory;
    VkDeviceSize size = 0;
    std::uint32_t type = 0;
    bool linear = false;
    void* mapped = nullptr;
    std::vector<Range> free;  // sorted by offset, never adjacent
  };
  std::uint32_t find_type(std::uint32_t type_bits, MemoryUse use) const;
  bool try_place(Block& b, const VkMemoryRequirements& req, VkDeviceSize& offset);
  void free(std::uint32_t block, VkDeviceSize offset, VkDeviceSize size);

  VkDevice device_;
  VkPhysicalDeviceMemoryProperties props_{};
  VkDeviceSize block_size_;
  std::vector<std::unique_ptr<Block>> blocks_;
  VkDeviceSize in_use_ = 0, peak_ = 0;
};

// A buffer with its memory; host-visible buffers stay mapped.
struct Buffer {
  Allocation memory;  // declared first: released after the buffer is destroyed
  UniqueBuffer buffer;
  VkDeviceSize size = 0;
  VkBuffer get() const { return buffer.get(); }
  void* mapped() const { return memory.mapped(); }
};

Buffer create_buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use);

struct ImageDescription {
  VkFormat format = VK_FORMAT_UNDEFINED;
  std::uint32_t width = 1, height = 1, layers = 1;
  VkImageUsageFlags usage = 0;
};

// A 2D (array) image with one view over all its layers (VK_IMAGE_VIEW_TYPE_2D_ARRAY).
struct Image {
  Allocation memory;  // declared first: released after the image and view are destroyed
  UniqueImage image;
  UniqueImageView view;
  ImageDescription description;
  VkImage get() const { return image.get(); }
};

Image create_image(Context& ctx, const ImageDescription& description);

VkImageAspectFlags aspect_of(VkFormat format);

}  // namespace sdfkit::vk
