#pragma once
// The figure renderer's render-graph passes (sdfkit::render::MeshRenderer), one file each:
// figure_mesh.cpp draws the coloured mesh into every view, figure_overlay.cpp the skeleton's
// segments and points over it. Like the depth-peeling passes they take handles, declare their
// uses, bind through what they declared and return the handles they wrote.

#include "sdfkit/render/figure.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace sdfkit::render::passes {

struct MeshPush {  // render_mesh.vert, render_mesh.frag
  glm::mat4 view_projection;
  glm::vec4 eye;
  glm::vec4 scale;  // lo, hi, palette size
};
struct OverlayPush {  // render_overlay.vert, render_overlay.frag
  glm::mat4 view_projection;
  glm::vec4 viewport;
};

struct FigureMeshPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle color, depth;      // cleared
  vk::BufferHandle vertices, palette;
  std::vector<SceneView> views;
  std::uint32_t vertex_count = 0;
  glm::vec3 background{1.0f};
  glm::vec4 scale{0.0f};             // lo, hi, palette size, 0
};
struct FigureOutput {
  vk::ImageHandle color, depth;
};
FigureOutput add_figure_mesh_pass(vk::RenderGraph& graph, const FigureMeshPass& pass);

struct FigureOverlayPass {
  const vk::Pipeline* pipeline = nullptr;
  vk::ImageHandle color, depth;      // colour loaded, depth cleared (drawn on top)
  vk::BufferHandle segments;
  std::vector<SceneView> views;
  std::uint32_t segment_count = 0;
};
FigureOutput add_figure_overlay_pass(vk::RenderGraph& graph, const FigureOverlayPass& pass);

// Viewport and scissor of one view.
void set_view(VkCommandBuffer cmd, const SceneView& view);

}  // namespace sdfkit::render::passes
