#pragma once
// A render graph: passes declare how they use images and buffers; the graph orders them,
// culls passes whose results nobody uses, derives every pipeline barrier and image layout
// transition, allocates (and aliases) transient resources, then records and submits.
//
//   setup:   RenderGraph g; auto depth = g.create_image("depth", {...});
//            auto pass = g.add_pass("peel", PassKind::Graphics);
//            depth = pass.depth(depth, LoadOp::Clear);       // writing returns a new version
//            pass.execute([=](PassContext& pc) { ... });
//   compile: CompiledGraph plan = g.compile();                // pure data, no device needed
//   execute: execute(ctx, plan, pool);                         // records, submits, waits
//
// Resources are versioned (Filament style): every write returns a new handle ("depth#2") and
// the handle written from becomes stale; writing through a stale handle is an error reported
// by compile(). Reads of a version order the reader after its writer (read after write); a
// write orders the writer after every reader of the previous version (write after read).
// A pass never records a barrier itself.
//
// Simplifications (documented): an image is tracked as a whole (all layers, one mip level);
// passes run on one queue in one command buffer.
//
// Every execution ends with a memory barrier from all device writes to host reads, so buffers
// in host-visible memory (read-backs, counters) can be read once execute() has returned.

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sdfkit::vk {

class Context;
class TransientPool;

// A graph that cannot be compiled: cycle, read of an unwritten version, stale write...
class GraphError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

enum class PassKind : std::uint8_t { Graphics, Compute, Transfer };

// How a pass uses a resource.
enum class Access : std::uint8_t {
  ColorAttachment,   // image, written (loaded or cleared)
  DepthAttachment,   // image, depth test + write
  DepthReadOnly,     // image, depth test without write
  Sampled,           // image, sampled in shaders
  StorageRead,       // image or buffer, storage read
  StorageWrite,      // image or buffer, storage write (does not read earlier contents)
  StorageReadWrite,  // image or buffer, storage read and write
  Atomic,            // buffer, atomics (read and write)
  TransferSrc,
  TransferDst,       // write
  Indirect,          // buffer, indirect draw/dispatch arguments
  Vertex,            // buffer, vertex attributes
  Index,             // buffer, indices
  Uniform,           // buffer, uniform block
};

enum class LoadOp : std::uint8_t { Load, Clear, DontCare };

const char* access_name(Access access);
bool access_reads(Access access);
bool access_writes(Access access);

// The synchronization scope and layout of one access by one kind of pass.
struct AccessState {
  VkPipelineStageFlags2 stages = 0;
  VkAccessFlags2 access = 0;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  // images only
};
AccessState access_state(Access access, PassKind kind, bool image);

// Handles are indices of resource versions; copying one is free.
struct ImageHandle {
  std::uint32_t id = UINT32_MAX;
  bool valid() const { return id != UINT32_MAX; }
};
struct BufferHandle {
  std::uint32_t id = UINT32_MAX;
  bool valid() const { return id != UINT32_MAX; }
};
// A query pool imported into the graph (occlusion queries...). Not versioned: the passes that
// declare one run in their declaration order.
struct QueryPoolHandle {
  std::uint32_t id = UINT32_MAX;
  bool valid() const { return id != UINT32_MAX; }
};

struct ImageInfo {
  VkFormat format = VK_FORMAT_UNDEFINED;
  std::uint32_t width = 1, height = 1, layers = 1;
  bool operator==(const ImageInfo&) const = default;
};

// The state an imported resource is in before the graph runs, and the layout it must be left in.
struct ExternalImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // a 2D-array view over all layers
  AccessState initial{VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
  VkImageLayout final_layout = VK_IMAGE_LAYOUT_UNDEFINED;  // UNDEFINED = leave as is
};
struct ExternalBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  AccessState initial{VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
};

// An image whose contents live across submissions (a ring of depth-peel layers: Granite's
// history inputs). The graph that imports it starts from the layout the previous graph left it
// in, and execute() records the layout this graph leaves it in: no layout is kept by hand.
struct HistoryImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // a 2D-array view over all layers
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  // updated by execute()
};

struct CompiledGraph;
struct CompiledPass;

// Given to a pass while it records. A pass reaches only what it declared: asking for a handle
// (a version) that the pass did not use throws GraphError naming the pass and the version.
class PassContext {
public:
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkImage image(ImageHandle h) const;
  VkImageView view(ImageHandle h) const;
  VkBuffer buffer(BufferHandle h) const;
  const ImageInfo& image_info(ImageHandle h) const;
  VkQueryPool query_pool(QueryPoolHandle h) const;

  // One descriptor binding of a declared resource: a buffer (storage buffer, or uniform buffer
  // when the pass declared it so) or an image (with a sampler: combined image sampler in
  // SHADER_READ_ONLY_OPTIMAL; without: storage image in GENERAL).
  struct Binding {
    std::uint32_t binding = 0;
    BufferHandle buffer;
    ImageHandle image;
    VkSampler sampler = VK_NULL_HANDLE;
  };
  // A descriptor set of `layout` holding the given declared resources, allocated for this
  // execution (the graph's descriptor pools are reset when the next execution starts): passes
  // bind through their declared handles, never through sets written ahead of time.
  VkDescriptorSet descriptor_set(VkDescriptorSetLayout layout, std::initializer_list<Binding> bindings) const;

private:
  friend class GraphExecutor;
  std::uint32_t declared_resource(std::uint32_t version) const;
  struct DescriptorAllocator* descriptors_ = nullptr;
  const struct ResolvedResources* resolved_ = nullptr;
  const CompiledGraph* graph_ = nullptr;
  const CompiledPass* pass_ = nullptr;
};

// Whether `pass` declared a use of resource version `version` (as the version it read or the
// one it wrote): what PassContext checks.
bool pass_declares(const CompiledPass& pass, std::uint32_t version);

using PassFunction = std::function<void(PassContext&)>;

struct PassUse {
  std::uint32_t read_version = UINT32_MAX;   // version id used as input (UINT32_MAX: none)
  std::uint32_t write_version = UINT32_MAX;  // version id produced (UINT32_MAX: none)
  std::uint32_t resource = 0;
  Access access = Access::Sampled;
  LoadOp load = LoadOp::Load;
  VkClearValue clear{};
};

class RenderGraph;

// Declares one pass's uses. Stays valid while the graph lives.
class PassBuilder {
public:
  // Attachments (graphics passes), in declaration order = attachment location.
  ImageHandle color(ImageHandle h, LoadOp load = LoadOp::Load, VkClearColorValue clear = {});
  ImageHandle depth(ImageHandle h, LoadOp load = LoadOp::Load, float clear_depth = 1.0f);
  void depth_read_only(ImageHandle h);
  // Shader access.
  void sampled(ImageHandle h);
  void storage_read(ImageHandle h);
  void storage_read(BufferHandle h);
  // storage_write starts a new version that does not depend on the earlier contents: a pass
  // writing only part of a resource that an earlier pass wrote, to be read together later,
  // declares storage_read_write, or the earlier writer is culled when nothing else reads it.
  ImageHandle storage_write(ImageHandle h);
  BufferHandle storage_write(BufferHandle h);
  ImageHandle storage_read_write(ImageHandle h);
  BufferHandle storage_read_write(BufferHandle h);
  BufferHandle atomic(BufferHandle h);
  void uniform(BufferHandle h);
  // Transfers and fixed-function inputs.
  void transfer_src(ImageHandle h);
  void transfer_src(BufferHandle h);
  ImageHandle transfer_dst(ImageHandle h);
  BufferHandle transfer_dst(BufferHandle h);
  void indirect(BufferHandle h);
  void vertex(BufferHandle h);
  void index(BufferHandle h);
  // A query pool the pass records queries into or resets (implies side_effect()).
  void queries(QueryPoolHandle h);
  // Keep the pass even when nothing reads what it writes (queries, host readback...).
  void side_effect();
  void execute(PassFunction fn);

private:
  friend class RenderGraph;
  PassBuilder(RenderGraph* g, std::uint32_t pass) : graph_(g), pass_(pass) {}
  std::uint32_t use(std::uint32_t version, Access access, LoadOp load, VkClearValue clear);
  RenderGraph* graph_;
  std::uint32_t pass_;
};

// One barrier derived by compile(), recorded before a pass (or at the end of the graph).
struct Barrier {
  std::uint32_t physical = 0;  // index into CompiledGraph::physical
  std::string resource;        // version name, "depth#2"
  bool image = false;
  AccessState src, dst;        // src.layout = old layout, dst.layout = new layout
};

struct PhysicalResource {
  bool image = false;
  bool imported = false;
  ImageInfo info;              // images
  VkDeviceSize size = 0;       // buffers
  VkFlags usage = 0;           // VkImageUsageFlags or VkBufferUsageFlags over every alias
  std::vector<std::uint32_t> resources;  // logical resources sharing it (aliases), in order
  VkImage external_image = VK_NULL_HANDLE;
  VkImageView external_view = VK_NULL_HANDLE;
  VkBuffer external_buffer = VK_NULL_HANDLE;
};

struct CompiledPass {
  std::uint32_t pass = 0;  // declaration index
  std::string name;
  PassKind kind = PassKind::Compute;
  std::vector<Barrier> barriers;  // recorded before the pass
  std::vector<PassUse> uses;
  std::vector<std::uint32_t> query_pools;  // QueryPoolHandle ids the pass declared
  PassFunction fn;
};

struct CompiledGraph {
  std::vector<CompiledPass> passes;      // execution order
  std::vector<std::string> culled;       // names of passes removed as unused
  std::vector<PhysicalResource> physical;
  std::vector<std::uint32_t> physical_of;  // logical resource -> physical index
  std::vector<std::string> resource_names;   // logical resource names
  std::vector<std::string> version_names;    // version id -> "name#v"
  std::vector<Barrier> final_barriers;   // imported resources to their final layouts
  std::vector<VkQueryPool> query_pools;  // by QueryPoolHandle id
  // History images and the layout this graph leaves each in (applied by execute()).
  std::vector<std::pair<HistoryImage*, VkImageLayout>> history_layouts;
  std::size_t barrier_count() const;
  // Human-readable listing: passes in order with their barriers, resources and aliases.
  std::string describe() const;
};

class RenderGraph;

// The phases of RenderGraph::compile(), exposed so that each can be read and tested on its own
// (no device needed). compile() runs them in this order:
//   validate()        setup errors, reads of versions nothing writes
//   order()           dependencies (read after write, write after read/write), culling of passes
//                     nothing needs, topological order (ties by declaration), cycle detection
//   lifetimes()       first and last use of each logical resource in that order, usage flags
//   assign_physical() imported resources keep their own; transients alias a physical resource of
//                     the same description whose last use ended before their first use
//   derive_barriers() walks the passes in order, tracking each physical resource's state, and
//                     derives every barrier and layout transition, then the final layouts
namespace compile_phase {
struct Order {
  std::vector<std::uint32_t> passes;  // live passes (declaration indices) in execution order
  std::vector<std::uint32_t> culled;  // passes removed as unused, declaration order
};
struct Lifetimes {
  std::vector<int> first, last;       // per logical resource: positions in Order::passes (-1 unused)
  std::vector<VkFlags> usage;         // per logical resource: image or buffer usage flags
};
struct Physical {
  std::vector<PhysicalResource> physical;
  std::vector<std::uint32_t> physical_of;  // logical resource -> physical index (UINT32_MAX unused)
};
}  // namespace compile_phase

class GraphCompiler {
public:
  explicit GraphCompiler(const RenderGraph& graph) : graph_(graph) {}
  void validate() const;  // throws GraphError
  compile_phase::Order order() const;  // throws GraphError on a cycle
  compile_phase::Lifetimes lifetimes(const compile_phase::Order& order) const;
  compile_phase::Physical assign_physical(const compile_phase::Lifetimes& lifetimes) const;
  // Fills out.passes (with their barriers), out.final_barriers, out.physical and out.physical_of.
  void derive_barriers(const compile_phase::Order& order, const compile_phase::Physical& physical,
                       CompiledGraph& out) const;

private:
  const RenderGraph& graph_;
};

class RenderGraph {
public:
  RenderGraph() = default;

  ImageHandle create_image(std::string name, const ImageInfo& info);
  BufferHandle create_buffer(std::string name, VkDeviceSize size);
  ImageHandle import_image(std::string name, const ImageInfo& info, const ExternalImage& external);
  BufferHandle import_buffer(std::string name, VkDeviceSize size, const ExternalBuffer& external);
  // An image living across submissions; `history` must outlive the execution.
  ImageHandle import_history(std::string name, const ImageInfo& info, HistoryImage& history);
  QueryPoolHandle import_query_pool(std::string name, VkQueryPool pool);

  PassBuilder add_pass(std::string name, PassKind kind);

  // "name#version" of a handle.
  std::string version_name(std::uint32_t version) const;

  // Orders, culls, derives barriers and plans transient memory (the phases of GraphCompiler).
  // Throws GraphError.
  CompiledGraph compile() const;

private:
  friend class PassBuilder;
  friend class GraphCompiler;
  struct Resource {
    std::string name;
    bool image = false;
    bool imported = false;
    ImageInfo info;
    VkDeviceSize size = 0;
    ExternalImage ext_image;
    ExternalBuffer ext_buffer;
    HistoryImage* history = nullptr;
    std::uint32_t latest = 0;  // latest version id
  };
  struct Version {
    std::uint32_t resource = 0;
    std::uint32_t number = 0;
    int writer = -1;  // pass index, -1 for the initial version
  };
  struct Pass {
    std::string name;
    PassKind kind = PassKind::Compute;
    std::vector<PassUse> uses;
    std::vector<std::uint32_t> query_pools;
    bool side_effect = false;
    PassFunction fn;
  };
  std::uint32_t add_resource(Resource r);
  std::vector<std::pair<std::string, VkQueryPool>> query_pools_;
  std::vector<Resource> resources_;
  std::vector<Version> versions_;
  std::vector<Pass> passes_;
  std::vector<std::string> setup_errors_;
};

// Owns the transient images and buffers of executed graphs, keyed by description, so that
// graphs rebuilt every frame/iteration reuse them; also the timestamp query pool.
class TransientPool {
public:
  explicit TransientPool(Context& ctx);
  ~TransientPool();
  TransientPool(const TransientPool&) = delete;
  TransientPool& operator=(const TransientPool&) = delete;
  std::size_t image_count() const;
  std::size_t buffer_count() const;

private:
  friend class GraphExecutor;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct ExecuteOptions {
  bool profile = false;  // per-pass GPU timestamps (when the device has them)
};

struct PassTiming {
  std::string pass;
  double gpu_milliseconds = 0.0;
};

// Records every pass (barriers first) into one command buffer, submits and waits. With
// profile, returns the GPU time of each pass.
std::vector<PassTiming> execute(Context& ctx, const CompiledGraph& graph, TransientPool& pool,
                                const ExecuteOptions& options = {});

// Stage and access names for printing ("FRAGMENT_SHADER", "SHADER_SAMPLED_READ").
std::string stage_names(VkPipelineStageFlags2 stages);
std::string access_names(VkAccessFlags2 access);
const char* layout_name(VkImageLayout layout);

}  // namespace sdfkit::vk
