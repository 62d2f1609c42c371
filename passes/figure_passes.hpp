#pragma once
// The figure renderer's render-graph passes (sdfkit::render::MeshRenderer), one file each:
// figure_mesh.cpp draws the coloured mesh into every view, figure_sheet.cpp a skeleton's sheet
// triangles over it, figure_overlay.cpp segments and points (a skeleton's edges and nodes, or a
// point cloud's sprites) over that. Like the depth-peeling passes they take handles, declare their
// uses, bind through what they declared and return the handles they wrote.

#include "sdfkit/render/figure.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <optional>
#include <vector>

namespace sdfkit::render::passes {

struct MeshPush {  // render_mesh.vert, render_mesh.frag
  glm::mat4 view_projection;
  glm::vec4 eye;
  glm::vec4 scale;  // lo, hi, palette size, fade towards white
};
struct OverlayPush {  // render_overlay.vert, render_overlay.frag
  glm::mat4 view_projection;
  glm::vec4 viewport;
};
struct SheetPush {  // figure_sheet.vert, figure_sheet.frag
  glm::mat4 view_projection;
  glm::vec4 color;
};

struct FigureMeshPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle color, depth;      // cleared
  vk::BufferHandle vertices, palette;
  std::vector<SceneView> views;
  std::uint32_t vertex_count = 0;
  glm::vec3 background{1.0f};
  glm::vec4 scale{0.0f};             // lo, hi, palette size, fade (0..1)
};
struct FigureOutput {
  vk::ImageHandle color, depth;
};
FigureOutput add_figure_mesh_pass(vk::RenderGraph& graph, const FigureMeshPass& pass);

struct FigureOverlayPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle color, depth;      // colour loaded (cleared to clear_color when set), depth cleared
  vk::BufferHandle segments;
  std::vector<SceneView> views;
  std::uint32_t segment_count = 0;
  std::optional<glm::vec3> clear_color;  // the first pass of a picture without a mesh
};
FigureOutput add_figure_overlay_pass(vk::RenderGraph& graph, const FigureOverlayPass& pass);

struct FigureSheetPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle color, depth;      // colour loaded, depth cleared (drawn on top)
  vk::BufferHandle corners;          // vec4 per triangle corner (model units), 3 per triangle
  std::vector<SceneView> views;
  std::uint32_t vertex_count = 0;
  glm::vec4 color_value{1.0f};       // flat fill colour
};
FigureOutput add_figure_sheet_pass(vk::RenderGraph& graph, const FigureSheetPass& pass);

// Viewport and scissor of one view.
void set_view(VkCommandBuffer cmd, const SceneView& view);

}  // namespace sdfkit::render::passes
