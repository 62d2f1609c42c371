// Point-cloud pictures (the paper's Figure 15): a frame's points as square sprites with its
// skeleton on top, in several views or as a strip of frames side by side with one orientation
// and one scale.

#include "sdfkit/render/figure.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace sdfkit::render {
namespace {

void check_point_options(const RenderOptions& o) {
  if (o.width < 64 || o.height < 64) throw InputError("a figure must be at least 64 x 64 pixels");
  if (o.histogram || o.colorbar || !std::isnan(o.lo) || !std::isnan(o.hi) || !o.palette.empty())
    throw InputError("a point-cloud picture has no values: no histogram, colour bar, range or palette");
  if (!o.lines.empty() || !o.points.empty())
    throw InputError("a point-cloud picture draws its skeleton, not plain lines and points");
}

void check_frame(const PointFrame& f) {
  if (f.points.empty()) throw InputError("a point-cloud frame without points");
  validate(f.skeleton);
}

std::vector<glm::vec3> framed_points(const PointFrame& f) {
  std::vector<glm::vec3> all = f.points;
  all.insert(all.end(), f.skeleton.nodes.begin(), f.skeleton.nodes.end());
  return all;
}

// Draws one frame into the views and reads it back.
Image draw_frame(MeshRenderer& r, const PointFrame& f, std::span<const SceneView> views, int width, int height) {
  const float radius = point_radius_px(f.points, views.front().pixels_per_unit);
  r.set_points(f.points, radius, views.front().eye);
  r.set_skeleton(f.skeleton);
  return r.render(static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), views);
}

}  // namespace

float point_radius_px(std::span<const glm::vec3> points, float pixels_per_unit) {
  if (points.size() < 2) return 2.0f;
  const std::size_t samples = std::min<std::size_t>(256, points.size());
  std::vector<float> nearest;
  nearest.reserve(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    const std::size_t i = k * points.size() / samples;
    float best = INFINITY;
    for (std::size_t j = 0; j < points.size(); ++j) {
      const float d = glm::distance(points[i], points[j]);
      if (j != i && d > 0.0f) best = std::min(best, d);
    }
    if (std::isfinite(best)) nearest.push_back(best);
  }
  if (nearest.empty()) return 2.0f;
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2), nearest.end());
  return std::clamp(0.35f * nearest[nearest.size() / 2] * pixels_per_unit, 1.0f, 6.0f);
}

Image render_points_figure(vk::Context& ctx, const PointFrame& frame, const RenderOptions& options) {
  check_point_options(options);
  check_frame(frame);
  const std::vector<SceneView> views =
      orbit_views(framed_points(frame), options.views, options.width, options.height, options.setup);
  MeshRenderer r(ctx);
  return draw_frame(r, frame, views, options.width, options.height);
}

Image render_strip(vk::Context& ctx, std::span<const PointFrame> frames, const RenderOptions& options) {
  check_point_options(options);
  if (frames.empty()) throw InputError("a strip needs at least one frame");
  for (const PointFrame& f : frames) check_frame(f);
  const int n = static_cast<int>(frames.size());
  const int panel_w = options.width / n;
  if (panel_w < 16)
    throw InputError("a " + std::to_string(options.width) + "-pixel-wide strip cannot hold " + std::to_string(n) +
                     " frames (at least 16 pixels each)");
  const int font = std::max(1, std::min(panel_w, options.height) / 100);
  const bool labels = std::any_of(frames.begin(), frames.end(), [](const PointFrame& f) { return !f.label.empty(); });
  const int label_h = labels ? 7 * font + 8 * font : 0;
  const int panel_h = options.height - label_h;
  if (panel_h < 16) throw InputError("the strip is too low for its labels");

  // One camera for all: the orientation, then each frame's own tight view; the common scale is
  // the smallest of theirs, so that every frame fits its panel at the same scale.
  std::vector<std::vector<SceneView>> per_frame;
  float scale = INFINITY;
  for (const PointFrame& f : frames) {
    per_frame.push_back(orbit_views(framed_points(f), 1, panel_w, panel_h, options.setup));
    scale = std::min(scale, per_frame.back().front().pixels_per_unit);
  }

  Image strip;
  strip.width = options.width;
  strip.height = options.height;
  strip.rgba.assign(static_cast<std::size_t>(strip.width) * strip.height * 4, 255);
  MeshRenderer r(ctx);
  for (int i = 0; i < n; ++i) {
    SceneView v = per_frame[static_cast<std::size_t>(i)].front();
    // Rescale about the view's centre: clip x, y shrink by scale / own scale.
    const float k = scale / v.pixels_per_unit;
    glm::mat4 shrink(1.0f);
    shrink[0][0] = shrink[1][1] = k;
    v.view_projection = shrink * v.view_projection;
    v.pixels_per_unit = scale;
    const Image panel = draw_frame(r, frames[static_cast<std::size_t>(i)], std::span<const SceneView>(&v, 1), panel_w,
                                   panel_h);
    for (int y = 0; y < panel_h; ++y)
      std::copy_n(&panel.rgba[static_cast<std::size_t>(y) * panel_w * 4], static_cast<std::size_t>(panel_w) * 4,
                  strip.pixel(i * panel_w, y));
    const std::string& label = frames[static_cast<std::size_t>(i)].label;
    if (!label.empty())
      draw_text(strip, i * panel_w + (panel_w - text_width(label, font)) / 2, panel_h + 4 * font, label, font,
                {40, 40, 40});
    // A thin separator between panels.
    if (i > 0)
      for (int y = 0; y < panel_h; ++y) {
        std::uint8_t* p = strip.pixel(i * panel_w, y);
        p[0] = p[1] = p[2] = 200;
      }
  }
  return strip;
}

}  // namespace sdfkit::render
