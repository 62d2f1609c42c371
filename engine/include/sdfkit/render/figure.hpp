#pragma once
// Pictures of SDF fields, as in the paper's Figures 5, 6 and 9: the mesh coloured by its values
// from several directions (rendered headless by Vulkan through the render graph), with a
// histogram of the values and a colour bar, composed on the CPU into one RGBA8 image.
//
//   vk::Context ctx;
//   render::Image img = render::render_figure(ctx, asset.mesh, field.values, field.domain, {});
//   render::write_png("figure.png", img);
//
// Embedding tools that want the views inside their own render graph use MeshRenderer directly:
// add_passes() adds the mesh (and overlay) passes and returns the colour image, which later
// passes of the caller may read.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::vk {
class Context;
}

namespace sdfkit::render {

// An 8-bit RGBA image, rows top to bottom, 4 bytes per pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  std::uint8_t* pixel(int x, int y) { return &rgba[4 * (static_cast<std::size_t>(y) * width + x)]; }
  const std::uint8_t* pixel(int x, int y) const {
    return &rgba[4 * (static_cast<std::size_t>(y) * width + x)];
  }
};

// Values to colours: `palette` sampled linearly over [lo, hi] (values outside are clamped).
struct ColorScale {
  float lo = 0.0f, hi = 1.0f;
  std::vector<glm::vec3> palette;  // >= 2 entries, linear RGB in [0, 1]
  glm::vec3 color(float value) const;
};
// io::colormap (the colour map of every sdfkit output) over [lo, hi], 256 entries.
ColorScale sdf_scale(float lo, float hi);
// White at 0 to red at `limit` and above (relative differences, Figures 6 and 9).
ColorScale difference_scale(float limit);

struct RenderOptions {
  int views = 4;                  // directions around the object (vertical axis +y)
  int width = 1600, height = 900; // the whole figure, pixels
  bool histogram = true;
  bool colorbar = true;
  // Range of the colour map; NaN = the values' min / max.
  float lo = std::numeric_limits<float>::quiet_NaN();
  float hi = std::numeric_limits<float>::quiet_NaN();
  // Replaces the SDF colour map (io::colormap) when not empty; sampled over [lo, hi] as above.
  std::vector<glm::vec3> palette;
  // Skeleton overlay in model units: segments and points, drawn over the mesh (on top, depth
  // tested among themselves).
  std::vector<std::array<glm::vec3, 2>> lines;
  std::vector<glm::vec3> points;
};

// One camera of a figure: where it draws inside the colour image and how it projects.
struct SceneView {
  glm::mat4 view_projection{1.0f};  // model units to Vulkan clip space (y down, depth 0..1)
  glm::vec3 eye{0.0f, 0.0f, 1.0f};  // unit direction from the object towards the viewer
  int x = 0, y = 0, width = 1, height = 1;  // viewport in the colour image, pixels
  float pixels_per_unit = 1.0f;     // orthographic scale: one model unit is this many pixels
};

// `count` orthographic views around `mesh` (azimuths 360/count apart, 20 degrees above the
// horizon), laid out in the grid of cells that keeps them largest in a width x height image.
std::vector<SceneView> orbit_views(const Mesh& mesh, int count, int width, int height);

// A renderer session: pipelines and uploaded geometry on one context.
class MeshRenderer {
public:
  explicit MeshRenderer(vk::Context& ctx);

  // Uploads `mesh` with one value per vertex (smooth shading) or per face (flat colour) for
  // `domain`, coloured by `scale`. Non-finite values take scale.lo. Throws InputError when the
  // value count does not fit.
  void set_mesh(const Mesh& mesh, std::span<const float> values, SdfDomain domain,
                const ColorScale& scale);
  // Segments and points drawn over the mesh (model units).
  void set_overlay(std::span<const std::array<glm::vec3, 2>> lines, std::span<const glm::vec3> points);

  // Adds the passes drawing every view into a new width x height RGBA8 colour image (cleared
  // to `background`, linear RGB) and returns it. The renderer must outlive the graph's execution.
  vk::ImageHandle add_passes(vk::RenderGraph& graph, std::uint32_t width, std::uint32_t height,
                             std::span<const SceneView> views, glm::vec3 background = glm::vec3(1.0f));

  // Draws the views into a width x height image and reads it back.
  Image render(std::uint32_t width, std::uint32_t height, std::span<const SceneView> views,
               glm::vec3 background = glm::vec3(1.0f));

private:
  vk::Context& ctx_;
  vk::Pipeline mesh_pipeline_, overlay_pipeline_;
  vk::Buffer vertices_, palette_, segments_;
  std::uint32_t vertex_count_ = 0, segment_count_ = 0, palette_size_ = 0;
  float lo_ = 0.0f, hi_ = 1.0f;
  vk::TransientPool transients_;
};

// The whole figure: views of the mesh, and below them the histogram of the values (bars in the
// colour of their value) and the colour bar with min / max labels.
Image render_figure(vk::Context& ctx, const Mesh& welded, std::span<const float> values,
                    SdfDomain domain, const RenderOptions& options = {});

// Writes the image as PNG, atomically (io::write_file_atomically). Throws Error on failure.
void write_png(const std::string& path, const Image& image);

// Draws `text` (digits, '.', '-', '+', 'e', ' ', '%') with the built-in 5x7 font scaled by
// `scale`, top-left corner at (x, y), clipped to the image. Returns the text width in pixels.
int draw_text(Image& image, int x, int y, const std::string& text, int scale,
              std::array<std::uint8_t, 3> color);
int text_width(const std::string& text, int scale);

}  // namespace sdfkit::render
