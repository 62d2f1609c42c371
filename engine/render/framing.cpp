// Where a figure's cameras look from: the model's orientation (which axis is drawn up, which
// faces the first view) and views framed tightly around what they show.

#include "sdfkit/render/figure.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

namespace sdfkit::render {
namespace {

glm::vec3 axis_vector(int axis, float sign = 1.0f) {
  glm::vec3 v(0.0f);
  v[axis] = sign;
  return v;
}

// Axes by decreasing extent; equal extents keep the order y, z, x.
std::array<int, 3> axes_by_extent(const Aabb& box) {
  std::array<int, 3> order{1, 2, 0};
  const glm::vec3 e = box.extent();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return e[a] > e[b]; });
  return order;
}

// The shortest axis other than `up`; equal extents keep the order z, x, y (glTF's +Z front
// for a cube).
int shortest_other(const Aabb& box, int up) {
  const glm::vec3 e = box.extent();
  int best = -1;
  for (const int a : {2, 0, 1})
    if (a != up && (best < 0 || e[a] < e[best])) best = a;
  return best;
}

}  // namespace

UpRule up_rule_for(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower.ends_with(".gltf") || lower.ends_with(".glb") ? UpRule::PlusY : UpRule::LongestAxis;
}

Orientation orient(std::span<const glm::vec3> points, UpRule rule) {
  Orientation o;
  if (rule == UpRule::PlusY || points.empty()) return o;
  const Aabb box = bounding_box(points);
  const int up = axes_by_extent(box)[0];
  o.up = axis_vector(up);
  o.front = axis_vector(shortest_other(box, up));
  return o;
}

Orientation orientation_with_up(std::span<const glm::vec3> points, const std::string& axis) {
  float sign = 1.0f;
  std::string name = axis;
  if (!name.empty() && (name[0] == '+' || name[0] == '-')) {
    sign = name[0] == '-' ? -1.0f : 1.0f;
    name = name.substr(1);
  }
  if (name.size() != 1 || (name[0] != 'x' && name[0] != 'y' && name[0] != 'z'))
    throw InputError("the up axis is one of x, y, z, optionally signed (+z, -y), not \"" + axis + "\"");
  const int up = name[0] == 'x' ? 0 : name[0] == 'y' ? 1 : 2;
  Orientation o;
  o.up = axis_vector(up, sign);
  // Front: the shortest remaining axis (the widest silhouette faces the first view).
  o.front = axis_vector(shortest_other(bounding_box(points), up));
  return o;
}

std::vector<SceneView> orbit_views(std::span<const glm::vec3> points, int count, int width, int height,
                                   const ViewSetup& setup) {
  if (count < 1) throw InputError("a figure needs at least one view");
  if (width < 1 || height < 1) throw InputError("the image is empty");
  if (points.empty()) throw InputError("nothing to frame: no points");
  const glm::vec3 up = glm::normalize(setup.orientation.up);
  glm::vec3 front = setup.orientation.front - glm::dot(setup.orientation.front, up) * up;
  if (glm::length(front) < 1e-6f) throw InputError("the orientation's front is parallel to its up axis");
  front = glm::normalize(front);
  const glm::vec3 right = glm::cross(up, front);

  const Aabb box = bounding_box(points);
  const glm::vec3 center = box.center();
  const float radius = std::max(0.5f * box.diagonal(), 1e-6f);
  const float elevation = setup.elevation_degrees * std::numbers::pi_v<float> / 180.0f;

  // Each view's camera and the extent of the points in its image plane (model units).
  struct Camera {
    glm::vec3 eye_dir;
    glm::mat4 view;
    float x0, x1, y0, y1;
  };
  std::vector<Camera> cams;
  for (int i = 0; i < count; ++i) {
    const float azimuth = (setup.azimuth_degrees + 360.0f * static_cast<float>(i) / static_cast<float>(count)) *
                          std::numbers::pi_v<float> / 180.0f;
    const glm::vec3 eye_dir = std::cos(elevation) * (std::sin(azimuth) * right + std::cos(azimuth) * front) +
                              std::sin(elevation) * up;
    Camera c{eye_dir, glm::lookAtRH(center + eye_dir * (3.0f * radius), center, up), INFINITY, -INFINITY,
             INFINITY, -INFINITY};
    for (const glm::vec3& p : points) {
      const glm::vec4 q = c.view * glm::vec4(p, 1.0f);
      c.x0 = std::min(c.x0, q.x);
      c.x1 = std::max(c.x1, q.x);
      c.y0 = std::min(c.y0, q.y);
      c.y1 = std::max(c.y1, q.y);
    }
    cams.push_back(c);
  }

  // The grid and the common scale (pixels per unit): the largest at which every view's extent
  // fits its cell inside the margin; fewer rows on ties.
  const float min_extent = 1e-6f * radius;
  const auto scale_for = [&](int cell_w, int cell_h) {
    const float border = 2.0f * (setup.margin * static_cast<float>(std::min(cell_w, cell_h)) + setup.margin_px);
    float s = INFINITY;
    for (const Camera& c : cams) {
      s = std::min(s, (static_cast<float>(cell_w) - border) / std::max(c.x1 - c.x0, min_extent));
      s = std::min(s, (static_cast<float>(cell_h) - border) / std::max(c.y1 - c.y0, min_extent));
    }
    return s;
  };
  int cols = 1;
  float best = -1.0f;
  for (int c = 1; c <= count; ++c) {
    const int rows = (count + c - 1) / c;
    if (width / c < 1 || height / rows < 1) continue;
    const float s = scale_for(width / c, height / rows);
    if (s > best * 1.0001f) {
      best = s;
      cols = c;
    }
  }
  const int rows = (count + cols - 1) / cols;
  const int cell_w = width / cols, cell_h = height / rows;
  if (cell_w < 1 || cell_h < 1 || !(best > 0.0f))
    throw InputError("the image is too small for " + std::to_string(count) + " views");

  const float half_w = 0.5f * static_cast<float>(cell_w) / best, half_h = 0.5f * static_cast<float>(cell_h) / best;
  std::vector<SceneView> views;
  for (int i = 0; i < count; ++i) {
    const Camera& c = cams[static_cast<std::size_t>(i)];
    const float mx = 0.5f * (c.x0 + c.x1), my = 0.5f * (c.y0 + c.y1);
    glm::mat4 proj = glm::orthoRH_ZO(mx - half_w, mx + half_w, my - half_h, my + half_h, radius, 5.0f * radius);
    proj[1][1] = -proj[1][1];  // Vulkan's y points down
    proj[3][1] = -proj[3][1];
    SceneView v;
    v.view_projection = proj * c.view;
    v.eye = c.eye_dir;
    v.x = (i % cols) * cell_w;
    v.y = (i / cols) * cell_h;
    v.width = cell_w;
    v.height = cell_h;
    v.pixels_per_unit = best;
    views.push_back(v);
  }
  return views;
}

std::vector<SceneView> orbit_views(const Mesh& mesh, int count, int width, int height) {
  return orbit_views(mesh.positions, count, width, height, ViewSetup{});
}

std::array<int, 4> drawn_box(const Image& image, const SceneView& view, std::array<std::uint8_t, 3> background) {
  int x0 = view.width, y0 = view.height, x1 = 0, y1 = 0;
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) {
      const int ix = view.x + x, iy = view.y + y;
      if (ix < 0 || iy < 0 || ix >= image.width || iy >= image.height) continue;
      const std::uint8_t* p = image.pixel(ix, iy);
      if (p[0] == background[0] && p[1] == background[1] && p[2] == background[2]) continue;
      x0 = std::min(x0, x);
      y0 = std::min(y0, y);
      x1 = std::max(x1, x + 1);
      y1 = std::max(y1, y + 1);
    }
  if (x1 <= x0) return {0, 0, 0, 0};
  return {x0, y0, x1, y1};
}

}  // namespace sdfkit::render
