// MeshRenderer: the mesh views of a figure drawn by Vulkan through the render graph. The mesh
// is uploaded as a triangle soup (position, normal, value per corner) so per-vertex fields
// shade smoothly and per-face fields get one flat colour; the palette lives in a storage
// buffer read by the fragment stage; the skeleton overlay is a second graphics pass.

#include "sdfkit/render/figure.hpp"

#include "figure_passes.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace sdfkit::render {
namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct SoupVertex {
  glm::vec3 position, normal;
  float value;
};
static_assert(sizeof(SoupVertex) == 28);

// One screen-space quad of the overlay (glsl/render_overlay.vert): a.w = half width in pixels,
// color.w = layer (0 drawn over 1 over 2 over 3; depth orders within a layer).
struct Segment {
  glm::vec4 a, b, color;
};

glm::vec4 part_color(SkeletonPart part, float layer) {
  const std::array<std::uint8_t, 3> c = skeleton_color(part);
  return {static_cast<float>(c[0]) / 255.0f, static_cast<float>(c[1]) / 255.0f, static_cast<float>(c[2]) / 255.0f,
          layer};
}


vk::Pipeline make_mesh_pipeline(vk::Context& ctx) {
  vk::GraphicsPipelineDescription d;
  d.vertex_shader = "render_mesh.vert";
  d.fragment_shader = "render_mesh.frag";
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  d.push_bytes = sizeof(passes::MeshPush);
  d.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(SoupVertex, position)},
                  {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(SoupVertex, normal)},
                  {2, 0, VK_FORMAT_R32_SFLOAT, offsetof(SoupVertex, value)}};
  d.vertex_stride = sizeof(SoupVertex);
  d.color_formats = {kColorFormat};
  d.depth_format = kDepthFormat;
  return vk::create_graphics_pipeline(ctx, d);
}

vk::Pipeline make_overlay_pipeline(vk::Context& ctx) {
  vk::GraphicsPipelineDescription d;
  d.vertex_shader = "render_overlay.vert";
  d.fragment_shader = "render_overlay.frag";
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  d.push_bytes = sizeof(passes::OverlayPush);
  d.color_formats = {kColorFormat};
  d.depth_format = kDepthFormat;
  d.depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL;  // points, drawn last, win over line ends
  return vk::create_graphics_pipeline(ctx, d);
}

vk::Pipeline make_sheet_pipeline(vk::Context& ctx) {
  vk::GraphicsPipelineDescription d;
  d.vertex_shader = "figure_sheet.vert";
  d.fragment_shader = "figure_sheet.frag";
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  d.push_bytes = sizeof(passes::SheetPush);
  d.color_formats = {kColorFormat};
  d.depth_format = kDepthFormat;
  return vk::create_graphics_pipeline(ctx, d);
}

// A host-visible buffer holding `bytes`.
vk::Buffer upload(vk::Context& ctx, const void* data, std::size_t bytes, VkBufferUsageFlags usage) {
  vk::Buffer b = vk::create_buffer(ctx, bytes, usage, vk::MemoryUse::Upload);
  std::memcpy(b.mapped(), data, bytes);
  return b;
}

// Imported into a graph: written by the host before the submission.
vk::ExternalBuffer host_written(const vk::Buffer& b) {
  vk::ExternalBuffer e;
  e.buffer = b.get();
  e.initial = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
  return e;
}

}  // namespace

glm::vec3 ColorScale::color(float value) const {
  if (palette.empty()) return glm::vec3(0.5f);
  const float range = hi - lo;
  float t = range > 0.0f ? (value - lo) / range : 0.0f;
  if (!(t > 0.0f)) t = 0.0f;
  if (t > 1.0f) t = 1.0f;
  const int last = static_cast<int>(palette.size()) - 1;
  const float x = t * static_cast<float>(last);
  const int i = std::min(static_cast<int>(x), std::max(last - 1, 0));
  const float f = std::clamp(x - static_cast<float>(i), 0.0f, 1.0f);
  return palette[static_cast<std::size_t>(i)] * (1.0f - f) +
         palette[static_cast<std::size_t>(std::min(i + 1, last))] * f;
}

ColorScale sdf_scale(float lo, float hi) {
  ColorScale s;
  s.lo = lo;
  s.hi = hi;
  for (int i = 0; i < 256; ++i) s.palette.push_back(io::colormap(static_cast<float>(i) / 255.0f));
  return s;
}

ColorScale difference_scale(float limit) {
  ColorScale s;
  s.lo = 0.0f;
  s.hi = limit;
  s.palette = {glm::vec3(1.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
  return s;
}

MeshRenderer::MeshRenderer(vk::Context& ctx)
    : ctx_(ctx),
      mesh_pipeline_(make_mesh_pipeline(ctx)),
      overlay_pipeline_(make_overlay_pipeline(ctx)),
      sheet_pipeline_(make_sheet_pipeline(ctx)),
      transients_(ctx) {}

void MeshRenderer::set_mesh(const Mesh& mesh, std::span<const float> values, SdfDomain domain,
                            const ColorScale& scale) {
  const bool per_face = domain == SdfDomain::Face;
  const std::size_t expected = per_face ? mesh.face_count() : mesh.vertex_count();
  if (values.size() != expected)
    throw InputError("cannot render " + std::to_string(values.size()) + " values on a mesh with " +
                     std::to_string(expected) + (per_face ? " faces" : " vertices"));
  if (mesh.face_count() == 0) throw InputError("cannot render a mesh without faces");
  if (scale.palette.size() < 2) throw InputError("a colour scale needs at least two colours");

  const std::vector<glm::vec3> normals = per_face ? face_normals(mesh) : vertex_normals(mesh);
  const auto value_of = [&](std::size_t i) { return std::isfinite(values[i]) ? values[i] : scale.lo; };
  std::vector<SoupVertex> soup;
  soup.reserve(3 * mesh.face_count());
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    for (const std::uint32_t v : mesh.triangles[f]) {
      const std::size_t k = per_face ? f : v;
      soup.push_back({mesh.positions[v], normals[k], value_of(k)});
    }
  vertices_ = upload(ctx_, soup.data(), soup.size() * sizeof(SoupVertex), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  vertex_count_ = static_cast<std::uint32_t>(soup.size());

  std::vector<glm::vec4> palette;
  for (const glm::vec3& c : scale.palette) palette.emplace_back(c, 1.0f);
  palette_ = upload(ctx_, palette.data(), palette.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  palette_size_ = static_cast<std::uint32_t>(palette.size());
  lo_ = scale.lo;
  hi_ = scale.hi;
}

void MeshRenderer::set_overlay(std::span<const std::array<glm::vec3, 2>> lines,
                               std::span<const glm::vec3> points) {
  std::vector<Segment> segs;
  const glm::vec4 line_color(0.05f, 0.05f, 0.05f, 3.0f), point_color(0.55f, 0.0f, 0.55f, 2.0f);
  for (const auto& l : lines) segs.push_back({glm::vec4(l[0], 1.5f), glm::vec4(l[1], 0.0f), line_color});
  for (const glm::vec3& p : points) segs.push_back({glm::vec4(p, 3.0f), glm::vec4(p, 0.0f), point_color});
  segment_count_ = static_cast<std::uint32_t>(segs.size());
  sheet_vertex_count_ = 0;
  sheets_ = {};
  if (segs.empty()) {
    segments_ = {};
    return;
  }
  segments_ = upload(ctx_, segs.data(), segs.size() * sizeof(Segment), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

void MeshRenderer::set_skeleton(const SkeletonOverlay& s) {
  const std::vector<SkeletonPart> parts = node_parts(s);  // validates
  std::vector<Segment> segs;
  const auto line = [&](std::uint32_t i, std::uint32_t j, float half_width, SkeletonPart part, float layer) {
    segs.push_back({glm::vec4(s.nodes[i], half_width), glm::vec4(s.nodes[j], 0.0f), part_color(part, layer)});
  };
  // Sheet outlines under the curves, curves under the nodes, leaves and the first node on top.
  for (const auto& t : s.sheet_triangles)
    for (int k = 0; k < 3; ++k) line(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)], 0.75f,
                                     SkeletonPart::SheetOutline, 3.0f);
  for (const auto& e : s.edges) line(e[0], e[1], 1.5f, SkeletonPart::Curve, 2.0f);
  for (std::uint32_t i = 0; i < parts.size(); ++i) {
    switch (parts[i]) {
      case SkeletonPart::Node: line(i, i, 3.0f, SkeletonPart::Node, 1.0f); break;
      case SkeletonPart::Branch: line(i, i, 4.0f, SkeletonPart::Branch, 0.0f); break;
      case SkeletonPart::Leaf: line(i, i, 5.0f, SkeletonPart::Leaf, 0.0f); break;
      case SkeletonPart::First: line(i, i, 6.0f, SkeletonPart::First, 0.0f); break;
      default: break;  // sheet nodes: their triangles show them
    }
  }
  segment_count_ = static_cast<std::uint32_t>(segs.size());
  segments_ = segs.empty() ? vk::Buffer{}
                           : upload(ctx_, segs.data(), segs.size() * sizeof(Segment), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<glm::vec4> corners;
  for (const auto& t : s.sheet_triangles)
    for (const std::uint32_t k : t) corners.emplace_back(s.nodes[k], 1.0f);
  sheet_vertex_count_ = static_cast<std::uint32_t>(corners.size());
  sheets_ = corners.empty() ? vk::Buffer{}
                            : upload(ctx_, corners.data(), corners.size() * sizeof(glm::vec4),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

void MeshRenderer::set_points(std::span<const glm::vec3> points, float radius_px, glm::vec3 towards,
                              glm::vec3 near_color, glm::vec3 far_color) {
  for (const glm::vec3& p : points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError("cannot draw a point with a non-finite coordinate");
  float lo = INFINITY, hi = -INFINITY;
  for (const glm::vec3& p : points) {
    lo = std::min(lo, glm::dot(p, towards));
    hi = std::max(hi, glm::dot(p, towards));
  }
  std::vector<Segment> segs;
  segs.reserve(points.size());
  for (const glm::vec3& p : points) {
    const float t = hi > lo ? (glm::dot(p, towards) - lo) / (hi - lo) : 1.0f;
    segs.push_back({glm::vec4(p, radius_px), glm::vec4(p, 0.0f), glm::vec4(far_color + t * (near_color - far_color), 0.0f)});
  }
  point_count_ = static_cast<std::uint32_t>(segs.size());
  points_ = segs.empty() ? vk::Buffer{}
                         : upload(ctx_, segs.data(), segs.size() * sizeof(Segment), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

vk::ImageHandle MeshRenderer::add_passes(vk::RenderGraph& graph, std::uint32_t width, std::uint32_t height,
                                         std::span<const SceneView> views, glm::vec3 background) {
  if (vertex_count_ == 0 && point_count_ == 0) throw Error("MeshRenderer::add_passes before set_mesh or set_points");
  const std::uint32_t max_side = ctx_.capabilities().max_image_dimension_2d;
  if (max_side && (width > max_side || height > max_side))
    throw InputError("a " + std::to_string(width) + " x " + std::to_string(height) +
                     " image is larger than the device allows (" + std::to_string(max_side) + " pixels a side)");
  const std::vector<SceneView> v(views.begin(), views.end());
  passes::FigureOutput drawn;
  drawn.color = graph.create_image("figure.color", {kColorFormat, width, height, 1});
  drawn.depth = graph.create_image("figure.depth", {kDepthFormat, width, height, 1});
  bool cleared = false;

  if (vertex_count_ > 0) {
    passes::FigureMeshPass mp;
    mp.pipeline = &mesh_pipeline_;
    mp.color = drawn.color;
    mp.depth = drawn.depth;
    mp.vertices = graph.import_buffer("figure.vertices", vertices_.size, host_written(vertices_));
    mp.palette = graph.import_buffer("figure.palette", palette_.size, host_written(palette_));
    mp.views = v;
    mp.vertex_count = vertex_count_;
    mp.background = background;
    mp.scale = glm::vec4(lo_, hi_, static_cast<float>(palette_size_), fade_);
    drawn = passes::add_figure_mesh_pass(graph, mp);
    cleared = true;
  }
  const auto overlay = [&](const char* name, const vk::Buffer& buffer, std::uint32_t count) {
    passes::FigureOverlayPass op;
    op.pipeline = &overlay_pipeline_;
    op.color = drawn.color;
    op.depth = drawn.depth;
    op.segments = graph.import_buffer(name, buffer.size, host_written(buffer));
    op.views = v;
    op.segment_count = count;
    if (!cleared) op.clear_color = background;
    drawn = passes::add_figure_overlay_pass(graph, op);
    cleared = true;
  };
  if (point_count_ > 0) overlay("figure.points", points_, point_count_);
  if (sheet_vertex_count_ > 0) {
    passes::FigureSheetPass sp;
    sp.pipeline = &sheet_pipeline_;
    sp.color = drawn.color;
    sp.depth = drawn.depth;
    sp.corners = graph.import_buffer("figure.sheets", sheets_.size, host_written(sheets_));
    sp.views = v;
    sp.vertex_count = sheet_vertex_count_;
    const std::array<std::uint8_t, 3> c = skeleton_color(SkeletonPart::Sheet);
    sp.color_value = glm::vec4(c[0] / 255.0f, c[1] / 255.0f, c[2] / 255.0f, 1.0f);
    drawn = passes::add_figure_sheet_pass(graph, sp);
  }
  if (segment_count_ > 0) overlay("figure.skeleton", segments_, segment_count_);
  return drawn.color;
}

Image MeshRenderer::render(std::uint32_t width, std::uint32_t height, std::span<const SceneView> views,
                           glm::vec3 background) {
  const VkDeviceSize bytes = VkDeviceSize{width} * height * 4;
  vk::Buffer readback = vk::create_buffer(ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  vk::RenderGraph graph;
  const vk::ImageHandle color = add_passes(graph, width, height, views, background);
  auto rb = graph.import_buffer("figure.readback", bytes, {readback.get()});
  auto copy = graph.add_pass("figure.readback", vk::PassKind::Transfer);
  copy.transfer_src(color);
  rb = copy.transfer_dst(rb);
  copy.side_effect();
  copy.execute([color, rb, width, height](vk::PassContext& pc) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyImageToBuffer(pc.cmd, pc.image(color), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.buffer(rb), 1,
                           &region);
  });
  vk::execute(ctx_, graph.compile(), transients_);

  Image img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.rgba.resize(bytes);
  std::memcpy(img.rgba.data(), readback.mapped(), bytes);
  return img;
}

}  // namespace sdfkit::render
