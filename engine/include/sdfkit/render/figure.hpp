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

// Which way a model is shown: `up` is drawn vertical (the orbit's axis), the first view looks
// from `front` (turned by the orbit's azimuth). Unit vectors, orthogonal.
struct Orientation {
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  glm::vec3 front{0.0f, 0.0f, 1.0f};
};
// How a file's up direction is decided: glTF declares +Y up and +Z front (PlusY); OBJ, OFF, PLY
// and point clouds declare nothing, so the bounding box's longest axis is drawn up and its
// shortest remaining axis faces the first view (LongestAxis: a standing figure stands, a worm
// lying on the floor is seen from above).
enum class UpRule { LongestAxis, PlusY };
// PlusY for .gltf / .glb (any case), LongestAxis otherwise.
UpRule up_rule_for(const std::string& path);
// The orientation of `points` under `rule`. Axes are taken positive; ties between equal extents
// prefer y, then z, then x. Empty input gives the default (+y up, +z front).
Orientation orient(std::span<const glm::vec3> points, UpRule rule);
// "x", "+y", "-z", ...: that axis up, front the shortest remaining axis of `points`.
// Throws InputError for anything else.
Orientation orientation_with_up(std::span<const glm::vec3> points, const std::string& axis);

// Where the cameras of a figure look from.
struct ViewSetup {
  Orientation orientation;
  float elevation_degrees = 20.0f;  // above the plane orthogonal to `up`
  float azimuth_degrees = 30.0f;    // of the first view, from `front` towards `up x front`
  // Empty border kept around the object in each view, as a fraction of the view's smaller side.
  float margin = 0.03f;
  // And this many pixels more: skeleton markers and point sprites (at most 6 pixels' half side)
  // drawn at the object's extremes stay inside the view.
  float margin_px = 8.0f;
};

// A skeleton drawn over a mesh or a point cloud: nodes, curve edges and sheet triangles (indices
// into nodes), as `sdfkit skeleton` writes them; an ordered polyline (pointcloud-skeleton) has
// edges i - i+1 and `ordered` set, so its first node is marked.
struct SkeletonOverlay {
  std::vector<glm::vec3> nodes;
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<std::array<std::uint32_t, 3>> sheet_triangles;
  bool ordered = false;
  bool empty() const { return nodes.empty(); }
};
// What a skeleton picture draws, each in its own flat colour (skeleton_color): curve edges, sheet
// triangles (filled, outlined), curve nodes, branch nodes (3 or more curve edges), leaves (one
// curve edge and no sheet triangle), and an ordered polyline's first node.
enum class SkeletonPart { Curve, Sheet, SheetOutline, Node, Branch, Leaf, First };
// The colour of a part as the PNG stores it (RGB bytes): tests count these exact pixels.
std::array<std::uint8_t, 3> skeleton_color(SkeletonPart part);
// The role of every node: Leaf, Branch, Node (a curve node), Sheet (a node of sheet triangles
// only) or First (an ordered polyline's first node). Throws InputError for an index out of range.
std::vector<SkeletonPart> node_parts(const SkeletonOverlay& skeleton);
// The overlay checked: finite positions, indices in range. Throws InputError naming what is wrong.
void validate(const SkeletonOverlay& skeleton);
// Reads a skeleton JSON: `sdfkit skeleton`'s {"nodes": [{"position"}...], "edges", "sheet_triangles"},
// or `sdfkit pointcloud-skeleton`'s ordered polyline {"nodes": [...]} (no edges: consecutive nodes
// are joined, `ordered` is set) or {"frames": [{"nodes": ...}, ...]}. One entry per frame. Throws
// InputError "<path>: <problem>" for anything else.
std::vector<SkeletonOverlay> read_skeleton_json(const std::string& path);

struct RenderOptions {
  int views = 4;                  // directions around the object (orbit axis: orientation.up)
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
  // A skeleton drawn with its parts in their own colours (on top of the mesh); the mesh is then
  // faded towards white by `fade` so the skeleton reads.
  SkeletonOverlay skeleton;
  float fade = 0.0f;  // 0 = the mesh's own colours, 1 = white
  ViewSetup setup;    // orientation, elevation, first azimuth and margin of the views
};

// One camera of a figure: where it draws inside the colour image and how it projects.
struct SceneView {
  glm::mat4 view_projection{1.0f};  // model units to Vulkan clip space (y down, depth 0..1)
  glm::vec3 eye{0.0f, 0.0f, 1.0f};  // unit direction from the object towards the viewer
  int x = 0, y = 0, width = 1, height = 1;  // viewport in the colour image, pixels
  float pixels_per_unit = 1.0f;     // orthographic scale: one model unit is this many pixels
};

// `count` orthographic views around `points` (azimuths 360/count apart from setup's first one,
// setup's elevation above the plane orthogonal to `up`), framed tightly: every view has the same
// scale, the largest at which every view's projected extent (plus the margin) fits its cell, and
// each view is centred on its own extent. The grid of cells is the one giving the largest scale
// in a width x height image.
std::vector<SceneView> orbit_views(std::span<const glm::vec3> points, int count, int width, int height,
                                   const ViewSetup& setup);
// The same around a mesh's vertices, +y up.
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
  // Colours are faded towards white by `fade` (0..1) after shading.
  void set_fade(float fade) { fade_ = fade; }
  // Segments and points drawn over the mesh (model units).
  void set_overlay(std::span<const std::array<glm::vec3, 2>> lines, std::span<const glm::vec3> points);
  // A skeleton drawn over the mesh with its parts in their own colours (skeleton_color): sheet
  // triangles filled, then edges, outlines and nodes on top. Replaces set_overlay's segments.
  void set_skeleton(const SkeletonOverlay& skeleton);
  // A point cloud drawn as square sprites of `radius_px` pixels' half side, coloured from
  // `far_color` to `near_color` along the cloud's extent towards `towards` (a depth cue).
  // Without a mesh the points pass clears the image.
  void set_points(std::span<const glm::vec3> points, float radius_px, glm::vec3 towards,
                  glm::vec3 near_color = glm::vec3(0.74f, 0.76f, 0.80f),
                  glm::vec3 far_color = glm::vec3(0.44f, 0.47f, 0.53f));

  // Adds the passes drawing every view into a new width x height RGBA8 colour image (cleared
  // to `background`, linear RGB) and returns it. The renderer must outlive the graph's execution.
  vk::ImageHandle add_passes(vk::RenderGraph& graph, std::uint32_t width, std::uint32_t height,
                             std::span<const SceneView> views, glm::vec3 background = glm::vec3(1.0f));

  // Draws the views into a width x height image and reads it back.
  Image render(std::uint32_t width, std::uint32_t height, std::span<const SceneView> views,
               glm::vec3 background = glm::vec3(1.0f));

private:
  vk::Context& ctx_;
  vk::Pipeline mesh_pipeline_, overlay_pipeline_, sheet_pipeline_;
  vk::Buffer vertices_, palette_, segments_, sheets_, points_;
  std::uint32_t vertex_count_ = 0, segment_count_ = 0, palette_size_ = 0, sheet_vertex_count_ = 0,
                point_count_ = 0;
  float lo_ = 0.0f, hi_ = 1.0f, fade_ = 0.0f;
  vk::TransientPool transients_;
};

// The whole figure: views of the mesh, and below them the histogram of the values (bars in the
// colour of their value) and the colour bar with min / max labels.
Image render_figure(vk::Context& ctx, const Mesh& welded, std::span<const float> values,
                    SdfDomain domain, const RenderOptions& options = {});

// A point cloud (one frame) with its skeleton, as the paper's Figure 15 shows a worm frame.
struct PointFrame {
  std::vector<glm::vec3> points;
  SkeletonOverlay skeleton;  // may be empty
  std::string label;         // drawn under the frame in a strip (digits and . - + e % only)
};
// Options of point pictures: options.views views of one frame, or a strip of frames.
// Histogram, colour bar, range and palette do not apply (InputError when set).
Image render_points_figure(vk::Context& ctx, const PointFrame& frame, const RenderOptions& options);
// The frames side by side in one row, each in a panel of width / frames.size() pixels, one
// view each, all with the same orientation (of all frames' points together) and the same
// scale (the largest at which every frame fits its panel), each centred on its own frame;
// labels below. Throws InputError for no frames or panels under 16 pixels wide.
Image render_strip(vk::Context& ctx, std::span<const PointFrame> frames, const RenderOptions& options);
// The square sprite half side used for `points` at `pixels_per_unit`: 0.35 x the median
// nearest-neighbour spacing (over up to 256 points), at least 1 pixel, at most 6.
float point_radius_px(std::span<const glm::vec3> points, float pixels_per_unit);

// Pixel bounding box of the pixels of `image` inside `view` that differ from `background`
// (RGB bytes), as {x0, y0, x1, y1} exclusive, relative to the view; {0,0,0,0} when none.
std::array<int, 4> drawn_box(const Image& image, const SceneView& view, std::array<std::uint8_t, 3> background);

// Writes the image as PNG, atomically (io::write_file_atomically). Throws Error on failure.
void write_png(const std::string& path, const Image& image);

// Draws `text` (digits, '.', '-', '+', 'e', ' ', '%') with the built-in 5x7 font scaled by
// `scale`, top-left corner at (x, y), clipped to the image. Returns the text width in pixels.
int draw_text(Image& image, int x, int y, const std::string& text, int scale,
              std::array<std::uint8_t, 3> color);
int text_width(const std::string& text, int scale);

}  // namespace sdfkit::render
