#include "sdfkit/vulkan/render_graph.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

namespace sdfkit::vk {

// ---- accesses ------------------------------------------------------------------------------

const char* access_name(Access a) {
  switch (a) {
    case Access::ColorAttachment: return "color attachment";
    case Access::DepthAttachment: return "depth attachment";
    case Access::DepthReadOnly: return "read-only depth attachment";
    case Access::Sampled: return "sampled";
    case Access::StorageRead: return "storage read";
    case Access::StorageWrite: return "storage write";
    case Access::StorageReadWrite: return "storage read-write";
    case Access::Atomic: return "atomic";
    case Access::TransferSrc: return "transfer source";
    case Access::TransferDst: return "transfer destination";
    case Access::Indirect: return "indirect arguments";
    case Access::Vertex: return "vertex buffer";
    case Access::Index: return "index buffer";
    case Access::Uniform: return "uniform buffer";
  }
  return "?";
}

bool access_writes(Access a) {
  switch (a) {
    case Access::ColorAttachment:
    case Access::DepthAttachment:
    case Access::StorageWrite:
    case Access::StorageReadWrite:
    case Access::Atomic:
    case Access::TransferDst: return true;
    default: return false;
  }
}

bool access_reads(Access a) {
  switch (a) {
    case Access::StorageWrite:
    case Access::TransferDst: return false;
    default: return true;  // attachments: the load op decides (see uses_previous_contents)
  }
}

namespace {

VkPipelineStageFlags2 shader_stages(PassKind k) {
  switch (k) {
    case PassKind::Graphics: return VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    case PassKind::Compute: return VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    case PassKind::Transfer: return VK_PIPELINE_STAGE_2_TRANSFER_BIT;
  }
  return 0;
}

// Whether a use needs the contents of the version it starts from.
bool uses_previous_contents(const PassUse& u) {
  if (u.access == Access::ColorAttachment || u.access == Access::DepthAttachment)
    return u.load == LoadOp::Load;
  return access_reads(u.access);
}

}  // namespace

AccessState access_state(Access a, PassKind k, bool image) {
  AccessState s;
  const auto layout = [&](VkImageLayout l) { return image ? l : VK_IMAGE_LAYOUT_UNDEFINED; };
  switch (a) {
    case Access::ColorAttachment:
      s = {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
           VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
      break;
    case Access::DepthAttachment:
      s = {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
           VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
           VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
      break;
    case Access::DepthReadOnly:
      s = {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
           VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
      break;
    case Access::Sampled:
      s = {shader_stages(k), VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
      break;
    case Access::StorageRead:
      s = {shader_stages(k), VK_ACCESS_2_SHADER_STORAGE_READ_BIT, VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::StorageWrite:
      s = {shader_stages(k), VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::StorageReadWrite:
    case Access::Atomic:
      s = {shader_stages(k), VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
           VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::TransferSrc:
      s = {VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      break;
    case Access::TransferDst:
      s = {VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
      break;
    case Access::Indirect:
      s = {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::Vertex:
      s = {VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT, VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::Index:
      s = {VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT, VK_ACCESS_2_INDEX_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::Uniform:
      s = {shader_stages(k), VK_ACCESS_2_UNIFORM_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
  }
  s.layout = layout(s.layout);
  return s;
}

namespace {

VkFlags usage_of(Access a, bool image) {
  switch (a) {
    case Access::ColorAttachment: return VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    case Access::DepthAttachment:
    case Access::DepthReadOnly: return VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    case Access::Sampled: return VK_IMAGE_USAGE_SAMPLED_BIT;
    case Access::StorageRead:
    case Access::StorageWrite:
    case Access::StorageReadWrite:
    case Access::Atomic: return image ? VkFlags{VK_IMAGE_USAGE_STORAGE_BIT} : VkFlags{VK_BUFFER_USAGE_STORAGE_BUFFER_BIT};
    case Access::TransferSrc: return image ? VkFlags{VK_IMAGE_USAGE_TRANSFER_SRC_BIT} : VkFlags{VK_BUFFER_USAGE_TRANSFER_SRC_BIT};
    case Access::TransferDst: return image ? VkFlags{VK_IMAGE_USAGE_TRANSFER_DST_BIT} : VkFlags{VK_BUFFER_USAGE_TRANSFER_DST_BIT};
    case Access::Indirect: return VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    case Access::Vertex: return VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
    case Access::Index: return VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    case Access::Uniform: return VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
  }
  return 0;
}

bool image_only(Access a) {
  return a == Access::ColorAttachment || a == Access::DepthAttachment || a == Access::DepthReadOnly ||
         a == Access::Sampled;
}
bool buffer_only(Access a) {
  return a == Access::Atomic || a == Access::Indirect || a == Access::Vertex || a == Access::Index ||
         a == Access::Uniform;
}

}  // namespace

// ---- setup ---------------------------------------------------------------------------------

std::uint32_t RenderGraph::add_resource(Resource r) {
  const auto res = static_cast<std::uint32_t>(resources_.size());
  r.latest = static_cast<std::uint32_t>(versions_.size());
  resources_.push_back(std::move(r));
  versions_.push_back({res, 0, -1});
  return resources_.back().latest;
}

ImageHandle RenderGraph::create_image(std::string name, const ImageInfo& info) {
  Resource r;
  r.name = std::move(name);
  r.image = true;
  r.info = info;
  return {add_resource(std::move(r))};
}

BufferHandle RenderGraph::create_buffer(std::string name, VkDeviceSize size) {
  Resource r;
  r.name = std::move(name);
  r.size = size;
  return {add_resource(std::move(r))};
}

ImageHandle RenderGraph::import_image(std::string name, const ImageInfo& info, const ExternalImage& ext) {
  Resource r;
  r.name = std::move(name);
  r.image = true;
  r.imported = true;
  r.info = info;
  r.ext_image = ext;
  return {add_resource(std::move(r))};
}

BufferHandle RenderGraph::import_buffer(std::string name, VkDeviceSize size, const ExternalBuffer& ext) {
  Resource r;
  r.name = std::move(name);
  r.imported = true;
  r.size = size;
  r.ext_buffer = ext;
  return {add_resource(std::move(r))};
}

ImageHandle RenderGraph::import_history(std::string name, const ImageInfo& info, HistoryImage& history) {
  ExternalImage e{history.image, history.view};
  e.initial = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, history.layout};
  const ImageHandle h = import_image(std::move(name), info, e);
  resources_.back().history = &history;
  return h;
}

QueryPoolHandle RenderGraph::import_query_pool(std::string name, VkQueryPool pool) {
  query_pools_.emplace_back(std::move(name), pool);
  return {static_cast<std::uint32_t>(query_pools_.size() - 1)};
}

PassBuilder RenderGraph::add_pass(std::string name, PassKind kind) {
  Pass p;
  p.name = std::move(name);
  p.kind = kind;
  passes_.push_back(std::move(p));
  return PassBuilder(this, static_cast<std::uint32_t>(passes_.size() - 1));
}

std::string RenderGraph::version_name(std::uint32_t v) const {
  if (v >= versions_.size()) return "<invalid handle>";
  return resources_[versions_[v].resource].name + "#" + std::to_string(versions_[v].number);
}

std::uint32_t PassBuilder::use(std::uint32_t version, Access access, LoadOp load, VkClearValue clear) {
  RenderGraph& g = *graph_;
  RenderGraph::Pass& pass = g.passes_[pass_];
  if (version >= g.versions_.size()) {
    g.setup_errors_.push_back("pass '" + pass.name + "' uses an invalid handle as " + access_name(access));
    return UINT32_MAX;
  }
  const std::uint32_t res = g.versions_[version].resource;
  RenderGraph::Resource& r = g.resources_[res];
  if ((r.image && buffer_only(access)) || (!r.image && image_only(access)))
    g.setup_errors_.push_back("pass '" + pass.name + "' uses " + (r.image ? "image" : "buffer") + " '" +
                              r.name + "' as " + access_name(access));
  if ((access == Access::ColorAttachment || access == Access::DepthAttachment ||
       access == Access::DepthReadOnly) && pass.kind != PassKind::Graphics)
    g.setup_errors_.push_back("pass '" + pass.name + "' is not a graphics pass but uses '" + r.name +
                              "' as " + access_name(access));
  PassUse u;
  u.resource = res;
  u.access = access;
  u.load = load;
  u.clear = clear;
  u.read_version = version;
  if (access_writes(access)) {
    if (version != r.latest)
      g.setup_errors_.push_back("pass '" + pass.name + "': write to stale version '" + g.version_name(version) +
                                "' (the latest is '" + g.version_name(r.latest) + "')");
    const auto nv = static_cast<std::uint32_t>(g.versions_.size());
    g.versions_.push_back({res, g.versions_[r.latest].number + 1, static_cast<int>(pass_)});
    r.latest = nv;
    u.write_version = nv;
  }
  pass.uses.push_back(u);
  return u.write_version == UINT32_MAX ? version : u.write_version;
}

ImageHandle PassBuilder::color(ImageHandle h, LoadOp load, VkClearColorValue clear) {
  VkClearValue v{};
  v.color = clear;
  return {use(h.id, Access::ColorAttachment, load, v)};
}
ImageHandle PassBuilder::depth(ImageHandle h, LoadOp load, float clear_depth) {
  VkClearValue v{};
  v.depthStencil = {clear_depth, 0};
  return {use(h.id, Access::DepthAttachment, load, v)};
}
void PassBuilder::depth_read_only(ImageHandle h) { use(h.id, Access::DepthReadOnly, LoadOp::Load, {}); }
void PassBuilder::sampled(ImageHandle h) { use(h.id, Access::Sampled, LoadOp::Load, {}); }
void PassBuilder::storage_read(ImageHandle h) { use(h.id, Access::StorageRead, LoadOp::Load, {}); }
void PassBuilder::storage_read(BufferHandle h) { use(h.id, Access::StorageRead, LoadOp::Load, {}); }
ImageHandle PassBuilder::storage_write(ImageHandle h) { return {use(h.id, Access::StorageWrite, LoadOp::Load, {})}; }
BufferHandle PassBuilder::storage_write(BufferHandle h) { return {use(h.id, Access::StorageWrite, LoadOp::Load, {})}; }
ImageHandle PassBuilder::storage_read_write(ImageHandle h) { return {use(h.id, Access::StorageReadWrite, LoadOp::Load, {})}; }
BufferHandle PassBuilder::storage_read_write(BufferHandle h) { return {use(h.id, Access::StorageReadWrite, LoadOp::Load, {})}; }
BufferHandle PassBuilder::atomic(BufferHandle h) { return {use(h.id, Access::Atomic, LoadOp::Load, {})}; }
void PassBuilder::uniform(BufferHandle h) { use(h.id, Access::Uniform, LoadOp::Load, {}); }
void PassBuilder::transfer_src(ImageHandle h) { use(h.id, Access::TransferSrc, LoadOp::Load, {}); }
void PassBuilder::transfer_src(BufferHandle h) { use(h.id, Access::TransferSrc, LoadOp::Load, {}); }
ImageHandle PassBuilder::transfer_dst(ImageHandle h) { return {use(h.id, Access::TransferDst, LoadOp::Load, {})}; }
BufferHandle PassBuilder::transfer_dst(BufferHandle h) { return {use(h.id, Access::TransferDst, LoadOp::Load, {})}; }
void PassBuilder::indirect(BufferHandle h) { use(h.id, Access::Indirect, LoadOp::Load, {}); }
void PassBuilder::vertex(BufferHandle h) { use(h.id, Access::Vertex, LoadOp::Load, {}); }
void PassBuilder::index(BufferHandle h) { use(h.id, Access::Index, LoadOp::Load, {}); }
void PassBuilder::side_effect() { graph_->passes_[pass_].side_effect = true; }
void PassBuilder::queries(QueryPoolHandle h) {
  RenderGraph::Pass& p = graph_->passes_[pass_];
  if (h.id >= graph_->query_pools_.size())
    graph_->setup_errors_.push_back("pass '" + p.name + "' uses an invalid query pool handle");
  p.query_pools.push_back(h.id);
  p.side_effect = true;
}
void PassBuilder::execute(PassFunction fn) { graph_->passes_[pass_].fn = std::move(fn); }

// ---- compile -------------------------------------------------------------------------------

namespace {

// Per physical resource while walking the passes in order.
struct TrackState {
  VkPipelineStageFlags2 write_stages = 0;  // last write (or layout transition) not yet waited on by all
  VkAccessFlags2 write_access = 0;
  VkPipelineStageFlags2 read_stages = 0;   // reads since the last write
  VkPipelineStageFlags2 visible_stages = 0;  // stages/accesses the last write is visible to
  VkAccessFlags2 visible_access = 0;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

constexpr VkAccessFlags2 kWriteBits =
    VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
    VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;

}  // namespace

// The phases of compile(), in order. Each reads the declared graph (and the results of the
// phases before it) and is a plain function of data: tests run each one without a device.

void GraphCompiler::validate() const {
  const RenderGraph& g = graph_;
  if (!g.setup_errors_.empty()) throw GraphError(g.setup_errors_.front());
  const auto& passes = g.passes_;
  const auto& versions = g.versions_;
  const auto& resources = g.resources_;
  // Reads of versions nobody writes.
  for (const RenderGraph::Pass& p : passes)
    for (const PassUse& u : p.uses) {
      if (!uses_previous_contents(u)) continue;
      const RenderGraph::Version& v = versions[u.read_version];
      if (v.writer < 0 && !resources[v.resource].imported)
        throw GraphError("pass '" + p.name + "' reads '" + g.version_name(u.read_version) +
                         "' that nothing writes");
    }
}

compile_phase::Order GraphCompiler::order() const {
  const RenderGraph& g = graph_;
  const auto& passes = g.passes_;
  const auto& versions = g.versions_;
  const auto& resources = g.resources_;
  const std::size_t np = passes.size();
  // Edges: read after write (data), write after write and write after read (ordering only).
  std::vector<std::set<std::uint32_t>> succ(np), data_pred(np);
  std::vector<std::vector<std::uint32_t>> readers(versions.size());
  for (std::uint32_t pi = 0; pi < np; ++pi)
    for (const PassUse& u : passes[pi].uses)
      if (u.write_version == UINT32_MAX || uses_previous_contents(u)) readers[u.read_version].push_back(pi);
  for (std::uint32_t pi = 0; pi < np; ++pi) {
    for (const PassUse& u : passes[pi].uses) {
      const int w = versions[u.read_version].writer;
      if (w >= 0 && static_cast<std::uint32_t>(w) != pi) {
        succ[w].insert(pi);
        if (uses_previous_contents(u)) data_pred[pi].insert(static_cast<std::uint32_t>(w));
      }
      if (u.write_version != UINT32_MAX)
        for (std::uint32_t r : readers[u.read_version])
          if (r != pi) succ[r].insert(pi);
    }
  }

  // Passes declaring the same query pool keep their declaration order (a reset before the
  // queries it resets).
  std::vector<int> last_query_user(g.query_pools_.size(), -1);
  for (std::uint32_t pi = 0; pi < np; ++pi)
    for (std::uint32_t q : passes[pi].query_pools) {
      if (q >= last_query_user.size()) continue;
      if (last_query_user[q] >= 0 && static_cast<std::uint32_t>(last_query_user[q]) != pi)
        succ[static_cast<std::uint32_t>(last_query_user[q])].insert(pi);
      last_query_user[q] = static_cast<int>(pi);
    }

  // Culling: keep side-effect passes, writers of imported resources, and what they read from.
  std::vector<char> live(np, 0);
  std::vector<std::uint32_t> stack;
  for (std::uint32_t pi = 0; pi < np; ++pi) {
    bool root = passes[pi].side_effect;
    for (const PassUse& u : passes[pi].uses)
      if (u.write_version != UINT32_MAX && resources[u.resource].imported) root = true;
    if (root) {
      live[pi] = 1;
      stack.push_back(pi);
    }
  }
  while (!stack.empty()) {
    const std::uint32_t p = stack.back();
    stack.pop_back();
    for (std::uint32_t q : data_pred[p])
      if (!live[q]) {
        live[q] = 1;
        stack.push_back(q);
      }
  }

  // Topological order among live passes (Kahn, ties by declaration order).
  std::vector<int> indegree(np, 0);
  for (std::uint32_t p = 0; p < np; ++p)
    if (live[p])
      for (std::uint32_t q : succ[p])
        if (live[q]) ++indegree[q];
  std::set<std::uint32_t> ready;
  for (std::uint32_t p = 0; p < np; ++p)
    if (live[p] && indegree[p] == 0) ready.insert(p);
  std::vector<std::uint32_t> order;
  while (!ready.empty()) {
    const std::uint32_t p = *ready.begin();
    ready.erase(ready.begin());
    order.push_back(p);
    for (std::uint32_t q : succ[p])
      if (live[q] && --indegree[q] == 0) ready.insert(q);
  }
  const auto live_count = static_cast<std::size_t>(std::count(live.begin(), live.end(), 1));
  if (order.size() != live_count) {
    // Every pass left over has a left-over predecessor: walk predecessors until one repeats.
    std::vector<std::vector<std::uint32_t>> pred(np);
    for (std::uint32_t p = 0; p < np; ++p)
      for (std::uint32_t q : succ[p]) pred[q].push_back(p);
    std::uint32_t cur = 0;
    while (!(live[cur] && indegree[cur] > 0)) ++cur;
    std::vector<std::uint32_t> path;
    std::vector<int> seen(np, -1);
    while (seen[cur] < 0) {
      seen[cur] = static_cast<int>(path.size());
      path.push_back(cur);
      for (std::uint32_t q : pred[cur])
        if (live[q] && indegree[q] > 0) {
          cur = q;
          break;
        }
    }
    // path[seen[cur]..] walks backwards around the loop; reverse it to execution direction.
    std::vector<std::uint32_t> loop(path.begin() + seen[cur], path.end());
    std::reverse(loop.begin(), loop.end());
    std::string msg = "cycle detected between passes '" + passes[loop[0]].name + "' and '" +
                      passes[loop.size() > 1 ? loop[1] : loop[0]].name + "'";
    if (loop.size() > 2) {
      msg += " (";
      for (std::uint32_t p : loop) msg += "'" + passes[p].name + "' -> ";
      msg += "'" + passes[loop[0]].name + "')";
    }
    throw GraphError(msg);
  }
  compile_phase::Order out;
  out.passes = std::move(order);
  for (std::uint32_t p = 0; p < np; ++p)
    if (!live[p]) out.culled.push_back(p);
  return out;

}

compile_phase::Lifetimes GraphCompiler::lifetimes(const compile_phase::Order& ord) const {
  const RenderGraph& g = graph_;
  const auto& passes = g.passes_;
  const auto& resources = g.resources_;
  const std::vector<std::uint32_t>& order = ord.passes;
  // Lifetimes of logical resources over the execution order.
  const std::size_t nr = resources.size();
  compile_phase::Lifetimes lt;
  lt.first.assign(nr, -1);
  lt.last.assign(nr, -1);
  lt.usage.assign(nr, 0);
  auto& first = lt.first;
  auto& last = lt.last;
  auto& usage = lt.usage;
  for (std::size_t i = 0; i < order.size(); ++i)
    for (const PassUse& u : passes[order[i]].uses) {
      if (first[u.resource] < 0) first[u.resource] = static_cast<int>(i);
      last[u.resource] = static_cast<int>(i);
      usage[u.resource] |= usage_of(u.access, resources[u.resource].image);
    }

  return lt;
}

compile_phase::Physical GraphCompiler::assign_physical(const compile_phase::Lifetimes& lt) const {
  const RenderGraph& g = graph_;
  const auto& resources = g.resources_;
  const std::size_t nr = resources.size();
  const auto& first = lt.first;
  const auto& last = lt.last;
  const auto& usage = lt.usage;
  compile_phase::Physical out;
  // Physical resources: imported ones are their own; a transient reuses a physical resource of
  // the same description whose last use ended before its first use (aliasing), else a new one.
  out.physical_of.assign(nr, UINT32_MAX);
  std::vector<int> physical_last;
  std::vector<std::uint32_t> by_first;
  for (std::uint32_t r = 0; r < nr; ++r)
    if (first[r] >= 0) by_first.push_back(r);
  std::stable_sort(by_first.begin(), by_first.end(), [&](auto a, auto b) { return first[a] < first[b]; });
  for (std::uint32_t r : by_first) {
    const RenderGraph::Resource& res = resources[r];
    std::uint32_t slot = UINT32_MAX;
    if (!res.imported)
      for (std::uint32_t s = 0; s < out.physical.size(); ++s) {
        const PhysicalResource& ph = out.physical[s];
        if (!ph.imported && ph.image == res.image && physical_last[s] < first[r] &&
            (res.image ? ph.info == res.info : ph.size == res.size)) {
          slot = s;
          break;
        }
      }
    if (slot == UINT32_MAX) {
      PhysicalResource ph;
      ph.image = res.image;
      ph.imported = res.imported;
      ph.info = res.info;
      ph.size = res.size;
      ph.external_image = res.ext_image.image;
      ph.external_view = res.ext_image.view;
      ph.external_buffer = res.ext_buffer.buffer;
      slot = static_cast<std::uint32_t>(out.physical.size());
      out.physical.push_back(ph);
      physical_last.push_back(-1);
    }
    out.physical[slot].resources.push_back(r);
    out.physical[slot].usage |= usage[r];
    physical_last[slot] = last[r];
    out.physical_of[r] = slot;
  }

  return out;
}

void GraphCompiler::derive_barriers(const compile_phase::Order& ord, const compile_phase::Physical& phys,
                                    CompiledGraph& out) const {
  const RenderGraph& g = graph_;
  const auto& passes = g.passes_;
  const auto& resources = g.resources_;
  const std::vector<std::uint32_t>& order = ord.passes;
  out.physical = phys.physical;
  out.physical_of = phys.physical_of;
  // Barriers: walk the passes in order, tracking each physical resource's state.
  std::vector<TrackState> track(out.physical.size());
  for (std::uint32_t s = 0; s < out.physical.size(); ++s) {
    const PhysicalResource& ph = out.physical[s];
    if (ph.imported) {
      const RenderGraph::Resource& r = resources[ph.resources[0]];
      const AccessState& init = r.image ? r.ext_image.initial : r.ext_buffer.initial;
      track[s].write_stages = init.stages;
      track[s].write_access = init.access & kWriteBits;
      track[s].read_stages = (init.access & ~kWriteBits) ? init.stages : 0;
      track[s].layout = r.image ? init.layout : VK_IMAGE_LAYOUT_UNDEFINED;
    }
  }
  std::vector<std::uint32_t> current_resource(out.physical.size(), UINT32_MAX);

  for (std::uint32_t pi : order) {
    const RenderGraph::Pass& p = passes[pi];
    CompiledPass cp;
    cp.pass = pi;
    cp.name = p.name;
    cp.kind = p.kind;
    cp.uses = p.uses;
    cp.query_pools = p.query_pools;
    cp.fn = p.fn;
    // Merge the uses of each resource by this pass.
    std::map<std::uint32_t, std::vector<const PassUse*>> per_resource;
    for (const PassUse& u : p.uses) per_resource[u.resource].push_back(&u);
    for (const auto& [res, uses] : per_resource) {
      const bool image = resources[res].image;
      AccessState need{};
      bool writes = false, reads = false;
      std::uint32_t shown_version = uses.front()->read_version;
      for (const PassUse* u : uses) {
        const AccessState s = access_state(u->access, p.kind, image);
        if (need.stages && image && s.layout != need.layout)
          throw GraphError("pass '" + p.name + "' uses '" + resources[res].name + "' in two layouts (" +
                           layout_name(need.layout) + " and " + layout_name(s.layout) + ")");
        need.stages |= s.stages;
        need.access |= s.access;
        need.layout = s.layout;
        writes |= access_writes(u->access);
        reads |= uses_previous_contents(*u);
        if (u->write_version != UINT32_MAX) shown_version = u->write_version;
      }
      const std::uint32_t s = out.physical_of[res];
      TrackState& t = track[s];
      // A transient taking over an aliased physical resource (or a first use) starts from
      // undefined contents but must still wait for the previous user's accesses.
      VkImageLayout old_layout = t.layout;
      bool discard = false;
      if (current_resource[s] != res) {
        if (!resources[res].imported) {
          old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
          discard = true;
        }
        current_resource[s] = res;
      }
      if (!reads && image && !resources[res].imported) old_layout = VK_IMAGE_LAYOUT_UNDEFINED;

      bool need_barrier = false;
      AccessState src{};
      if (image && need.layout != t.layout) {
        need_barrier = true;
        src.stages = t.write_stages | t.read_stages;
        src.access = t.write_access;
      } else if (writes || discard) {
        if (t.write_stages | t.read_stages) {
          need_barrier = true;
          src.stages = t.write_stages | t.read_stages;
          src.access = t.write_access;
        }
      } else if (t.write_stages &&
                 ((need.stages & ~t.visible_stages) || (need.access & ~t.visible_access))) {
        need_barrier = true;
        src.stages = t.write_stages;
        src.access = t.write_access;
      }
      if (need_barrier) {
        Barrier b;
        b.physical = s;
        b.resource = g.version_name(shown_version);
        b.image = image;
        b.src = {src.stages ? src.stages : VK_PIPELINE_STAGE_2_NONE, src.access, image ? old_layout : VK_IMAGE_LAYOUT_UNDEFINED};
        b.dst = need;
        cp.barriers.push_back(b);
      }
      if (writes) {
        t.write_stages = need.stages;
        t.write_access = need.access & kWriteBits;
        t.read_stages = 0;
        t.visible_stages = 0;
        t.visible_access = 0;
      } else {
        if (need_barrier && image && need.layout != t.layout) {
          // The layout transition acts as a write that later stages wait on through a chain.
          t.write_stages = need.stages;
          t.write_access = 0;
          t.visible_stages = need.stages;
          t.visible_access = need.access;
        } else if (need_barrier) {
          t.visible_stages |= need.stages;
          t.visible_access |= need.access;
        }
        t.read_stages |= need.stages;
      }
      t.layout = image ? need.layout : VK_IMAGE_LAYOUT_UNDEFINED;
    }
    out.passes.push_back(std::move(cp));
  }

  // History images: the next graph starts from the layout this one leaves (after any final
  // transition below).
  for (std::uint32_t s = 0; s < out.physical.size(); ++s) {
    const PhysicalResource& ph = out.physical[s];
    if (!ph.imported || !ph.image) continue;
    const RenderGraph::Resource& r = resources[ph.resources[0]];
    if (!r.history) continue;
    const VkImageLayout fin = r.ext_image.final_layout;
    out.history_layouts.emplace_back(r.history, fin != VK_IMAGE_LAYOUT_UNDEFINED ? fin : track[s].layout);
  }

  // Imported images go to their final layouts.
  for (std::uint32_t s = 0; s < out.physical.size(); ++s) {
    const PhysicalResource& ph = out.physical[s];
    if (!ph.imported || !ph.image) continue;
    const RenderGraph::Resource& r = resources[ph.resources[0]];
    const VkImageLayout fin = r.ext_image.final_layout;
    if (fin == VK_IMAGE_LAYOUT_UNDEFINED || fin == track[s].layout) continue;
    Barrier b;
    b.physical = s;
    b.resource = g.version_name(r.latest);
    b.image = true;
    b.src = {track[s].write_stages | track[s].read_stages ? track[s].write_stages | track[s].read_stages
                                                          : VK_PIPELINE_STAGE_2_NONE,
             track[s].write_access, track[s].layout};
    b.dst = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, fin};
    out.final_barriers.push_back(b);
  }
}

CompiledGraph RenderGraph::compile() const {
  const GraphCompiler c(*this);
  c.validate();
  const compile_phase::Order order = c.order();
  const compile_phase::Lifetimes lifetimes = c.lifetimes(order);
  const compile_phase::Physical physical = c.assign_physical(lifetimes);
  CompiledGraph out;
  for (std::uint32_t p : order.culled) out.culled.push_back(passes_[p].name);
  for (const Resource& r : resources_) out.resource_names.push_back(r.name);
  for (std::uint32_t v = 0; v < versions_.size(); ++v) out.version_names.push_back(version_name(v));
  for (const auto& q : query_pools_) out.query_pools.push_back(q.second);
  c.derive_barriers(order, physical, out);
  return out;
}

std::size_t CompiledGraph::barrier_count() const {
  std::size_t n = final_barriers.size();
  for (const auto& p : passes) n += p.barriers.size();
  return n;
}

// ---- printing ------------------------------------------------------------------------------

std::string stage_names(VkPipelineStageFlags2 s) {
  static const std::pair<VkPipelineStageFlags2, const char*> names[] = {
      {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, "DRAW_INDIRECT"},
      {VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT, "INDEX_INPUT"},
      {VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT, "VERTEX_ATTRIBUTE_INPUT"},
      {VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, "VERTEX_SHADER"},
      {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, "FRAGMENT_SHADER"},
      {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT, "EARLY_FRAGMENT_TESTS"},
      {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, "LATE_FRAGMENT_TESTS"},
      {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, "COLOR_ATTACHMENT_OUTPUT"},
      {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, "COMPUTE_SHADER"},
      {VK_PIPELINE_STAGE_2_TRANSFER_BIT, "TRANSFER"},
      {VK_PIPELINE_STAGE_2_HOST_BIT, "HOST"},
      {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, "ALL_COMMANDS"}};
  if (s == 0) return "NONE";
  std::string out;
  for (const auto& [bit, name] : names)
    if (s & bit) out += (out.empty() ? "" : "|") + std::string(name);
  return out.empty() ? "OTHER" : out;
}

std::string access_names(VkAccessFlags2 a) {
  static const std::pair<VkAccessFlags2, const char*> names[] = {
      {VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, "INDIRECT_COMMAND_READ"},
      {VK_ACCESS_2_INDEX_READ_BIT, "INDEX_READ"},
      {VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT, "VERTEX_ATTRIBUTE_READ"},
      {VK_ACCESS_2_UNIFORM_READ_BIT, "UNIFORM_READ"},
      {VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, "SHADER_SAMPLED_READ"},
      {VK_ACCESS_2_SHADER_STORAGE_READ_BIT, "SHADER_STORAGE_READ"},
      {VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, "SHADER_STORAGE_WRITE"},
      {VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT, "COLOR_ATTACHMENT_READ"},
      {VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, "COLOR_ATTACHMENT_WRITE"},
      {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, "DEPTH_STENCIL_ATTACHMENT_READ"},
      {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, "DEPTH_STENCIL_ATTACHMENT_WRITE"},
      {VK_ACCESS_2_TRANSFER_READ_BIT, "TRANSFER_READ"},
      {VK_ACCESS_2_TRANSFER_WRITE_BIT, "TRANSFER_WRITE"},
      {VK_ACCESS_2_HOST_READ_BIT, "HOST_READ"},
      {VK_ACCESS_2_HOST_WRITE_BIT, "HOST_WRITE"},
      {VK_ACCESS_2_MEMORY_READ_BIT, "MEMORY_READ"},
      {VK_ACCESS_2_MEMORY_WRITE_BIT, "MEMORY_WRITE"}};
  if (a == 0) return "NONE";
  std::string out;
  for (const auto& [bit, name] : names)
    if (a & bit) out += (out.empty() ? "" : "|") + std::string(name);
  return out.empty() ? "OTHER" : out;
}

const char* layout_name(VkImageLayout l) {
  switch (l) {
    case VK_IMAGE_LAYOUT_UNDEFINED: return "UNDEFINED";
    case VK_IMAGE_LAYOUT_GENERAL: return "GENERAL";
    case VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL: return "COLOR_ATTACHMENT_OPTIMAL";
    case VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL: return "DEPTH_STENCIL_ATTACHMENT_OPTIMAL";
    case VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL: return "DEPTH_STENCIL_READ_ONLY_OPTIMAL";
    case VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL: return "SHADER_READ_ONLY_OPTIMAL";
    case VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL: return "TRANSFER_SRC_OPTIMAL";
    case VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL: return "TRANSFER_DST_OPTIMAL";
    default: return "OTHER";
  }
}

std::string CompiledGraph::describe() const {
  std::ostringstream o;
  auto barrier_line = [&](const Barrier& b) {
    o << "    barrier before: " << b.resource << ": " << stage_names(b.src.stages) << " (" << access_names(b.src.access)
      << ") -> " << stage_names(b.dst.stages) << " (" << access_names(b.dst.access) << ")";
    if (b.image && b.src.layout != b.dst.layout)
      o << ", layout " << layout_name(b.src.layout) << " -> " << layout_name(b.dst.layout);
    o << "\n";
  };
  o << "passes (" << passes.size() << "):\n";
  for (std::size_t i = 0; i < passes.size(); ++i) {
    const CompiledPass& p = passes[i];
    o << "  " << i << ". " << p.name << " ["
      << (p.kind == PassKind::Graphics ? "graphics" : p.kind == PassKind::Compute ? "compute" : "transfer") << "]:";
    for (const PassUse& u : p.uses) {
      o << " " << access_name(u.access) << " " << version_names[u.read_version];
      if (u.write_version != UINT32_MAX) o << "->" << version_names[u.write_version];
      o << ";";
    }
    o << "\n";
    // Recorded before the pass; listed under it.
    for (const Barrier& b : p.barriers) barrier_line(b);
  }
  if (!final_barriers.empty()) o << "  end:\n";
  for (const Barrier& b : final_barriers) barrier_line(b);
  if (!culled.empty()) {
    o << "culled:";
    for (const auto& c : culled) o << " " << c;
    o << "\n";
  }
  o << "resources (" << physical.size() << " physical):\n";
  for (std::size_t s = 0; s < physical.size(); ++s) {
    const PhysicalResource& ph = physical[s];
    o << "  [" << s << "] " << (ph.imported ? "imported " : "transient ") << (ph.image ? "image " : "buffer ");
    if (ph.image) o << ph.info.width << "x" << ph.info.height << "x" << ph.info.layers << " format " << ph.info.format;
    else o << ph.size << " bytes";
    o << ":";
    for (std::uint32_t r : ph.resources) o << " " << resource_names[r];
    o << "\n";
  }
  return o.str();
}

}  // namespace sdfkit::vk
