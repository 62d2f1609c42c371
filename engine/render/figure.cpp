// render_figure: the mesh views from MeshRenderer composed with a histogram of the values and
// a colour bar (CPU), a 5x7 bitmap font for the labels, and the PNG writer.

#include "sdfkit/render/figure.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/post/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace sdfkit::render {
namespace {

// 5x7 glyphs, one row per byte, bit 4 = leftmost column.
struct Glyph {
  char ch;
  std::uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {' ', {0, 0, 0, 0, 0, 0, 0}},
};

const Glyph* find_glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.ch == c) return &g;
  return nullptr;
}

std::array<std::uint8_t, 3> to_bytes(glm::vec3 c) {
  const auto b = [](float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  return {b(c.x), b(c.y), b(c.z)};
}

void fill_rect(Image& img, int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> c) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, img.width);
  y1 = std::min(y1, img.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      std::uint8_t* p = img.pixel(x, y);
      p[0] = c[0];
      p[1] = c[1];
      p[2] = c[2];
      p[3] = 255;
    }
}

std::string format_value(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", static_cast<double>(v));
  return buf;
}

// Layout of the strip under the views, pixels.
struct Layout {
  int margin = 4, font = 1;
  int panel_h = 0;           // views: rows [0, panel_h)
  int hist_y = 0, hist_h = 0;
  int bar_y = 0, bar_h = 0;
  int label_y = 0;
};

Layout plan(const RenderOptions& o) {
  Layout l;
  l.font = std::max(1, std::min(o.width, o.height) / 300);
  l.margin = std::max(4, 4 * l.font);
  int y = o.height;
  if (o.colorbar) {
    y -= l.margin + 7 * l.font;
    l.label_y = y;
    l.bar_h = std::max(8, o.height / 40);
    y -= l.margin / 2 + l.bar_h;
    l.bar_y = y;
  }
  if (o.histogram) {
    l.hist_h = std::max(24, o.height / 5);
    y -= (o.colorbar ? l.margin / 2 : l.margin) + l.hist_h;
    l.hist_y = y;
  }
  if (o.histogram || o.colorbar) y -= l.margin;
  l.panel_h = y;
  return l;
}

}  // namespace

int text_width(const std::string& text, int scale) {
  return text.empty() ? 0 : static_cast<int>(text.size()) * 6 * scale - scale;
}

int draw_text(Image& image, int x, int y, const std::string& text, int scale,
              std::array<std::uint8_t, 3> color) {
  int cx = x;
  for (const char c : text) {
    const Glyph* g = find_glyph(c);
    if (g) {
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (g->rows[row] & (0x10 >> col))
            fill_rect(image, cx + col * scale, y + row * scale, cx + (col + 1) * scale, y + (row + 1) * scale,
                      color);
    }
    cx += 6 * scale;
  }
  return text_width(text, scale);
}

Image render_figure(vk::Context& ctx, const Mesh& welded, std::span<const float> values, SdfDomain domain,
                    const RenderOptions& options) {
  if (options.width < 64 || options.height < 64)
    throw InputError("a figure must be at least 64 x 64 pixels");
  float lo = options.lo, hi = options.hi;
  if (std::isnan(lo) || std::isnan(hi)) {
    float mn = INFINITY, mx = -INFINITY;
    for (const float v : values)
      if (std::isfinite(v)) {
        mn = std::min(mn, v);
        mx = std::max(mx, v);
      }
    if (mn > mx) mn = mx = 0.0f;
    if (std::isnan(lo)) lo = mn;
    if (std::isnan(hi)) hi = mx;
  }
  ColorScale scale = sdf_scale(lo, hi);
  if (!options.palette.empty()) scale.palette = options.palette;

  const Layout l = plan(options);
  if (l.panel_h < 32) throw InputError("the figure is too small for its histogram and colour bar");
  std::vector<glm::vec3> framed = welded.positions;
  framed.insert(framed.end(), options.points.begin(), options.points.end());
  framed.insert(framed.end(), options.skeleton.nodes.begin(), options.skeleton.nodes.end());
  const std::vector<SceneView> views = orbit_views(framed, options.views, options.width, l.panel_h, options.setup);

  MeshRenderer renderer(ctx);
  renderer.set_mesh(welded, values, domain, scale);
  renderer.set_fade(options.fade);
  if (!options.skeleton.empty()) {
    if (!options.lines.empty() || !options.points.empty())
      throw InputError("a figure takes either a skeleton or plain lines and points, not both");
    renderer.set_skeleton(options.skeleton);
  } else {
    renderer.set_overlay(options.lines, options.points);
  }
  const Image panel = renderer.render(static_cast<std::uint32_t>(options.width),
                                      static_cast<std::uint32_t>(l.panel_h), views);

  Image fig;
  fig.width = options.width;
  fig.height = options.height;
  fig.rgba.assign(static_cast<std::size_t>(fig.width) * fig.height * 4, 255);
  std::copy(panel.rgba.begin(), panel.rgba.end(), fig.rgba.begin());

  const int x0 = l.margin, x1 = options.width - l.margin;  // histogram and bar share this axis
  const float fade = std::clamp(options.fade, 0.0f, 1.0f);  // as the mesh's colours
  const auto shown = [&](float v) { return to_bytes(scale.color(v) * (1.0f - fade) + glm::vec3(fade)); };
  const std::array<std::uint8_t, 3> ink{40, 40, 40}, axis{150, 150, 150};
  if (options.histogram) {
    const int bins = std::clamp((x1 - x0) / 8, 8, 64);
    std::vector<float> finite;
    finite.reserve(values.size());
    for (const float v : values)
      if (std::isfinite(v)) finite.push_back(v);
    const std::vector<std::size_t> counts = histogram(finite, lo, hi, bins);
    const std::size_t top = std::max<std::size_t>(1, *std::max_element(counts.begin(), counts.end()));
    const int base = l.hist_y + l.hist_h;
    for (int b = 0; b < bins; ++b) {
      const int bx0 = x0 + (x1 - x0) * b / bins, bx1 = x0 + (x1 - x0) * (b + 1) / bins - 1;
      const int h = static_cast<int>(std::lround(static_cast<double>(counts[static_cast<std::size_t>(b)]) /
                                                 static_cast<double>(top) * l.hist_h));
      const float centre = lo + (hi - lo) * (static_cast<float>(b) + 0.5f) / static_cast<float>(bins);
      fill_rect(fig, bx0, base - h, std::max(bx1, bx0 + 1), base, shown(centre));
    }
    fill_rect(fig, x0, base, x1, base + 1, axis);
  }
  if (options.colorbar) {
    for (int x = x0; x < x1; ++x) {
      const float t = static_cast<float>(x - x0) / static_cast<float>(std::max(1, x1 - x0 - 1));
      fill_rect(fig, x, l.bar_y, x + 1, l.bar_y + l.bar_h, shown(lo + t * (hi - lo)));
    }
    const std::string lo_text = format_value(lo), hi_text = format_value(hi),
                      mid_text = format_value(0.5f * (lo + hi));
    draw_text(fig, x0, l.label_y, lo_text, l.font, ink);
    draw_text(fig, x1 - text_width(hi_text, l.font), l.label_y, hi_text, l.font, ink);
    const int mid_w = text_width(mid_text, l.font);
    const int mid_x = (x0 + x1 - mid_w) / 2;
    if (mid_x > x0 + text_width(lo_text, l.font) + 4 * l.font &&
        mid_x + mid_w < x1 - text_width(hi_text, l.font) - 4 * l.font)
      draw_text(fig, mid_x, l.label_y, mid_text, l.font, ink);
  }
  return fig;
}

void write_png(const std::string& path, const Image& image) {
  io::write_png(path, image.width, image.height, 4, image.rgba);
}

}  // namespace sdfkit::render
