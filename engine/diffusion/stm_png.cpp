// write_atlas_png: the atlas as a picture (the paper's Figure 10).
#include "sdfkit/diffusion/stm.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/asset.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sdfkit::diffusion {

void write_atlas_png(const AtlasMapping& mapping, const Mesh& mesh, std::span<const float> values,
                     const std::string& path) {
  if (values.size() != mesh.positions.size())
    throw InputError(path + ": " + std::to_string(values.size()) + " values for a mesh of " +
                     std::to_string(mesh.positions.size()) + " vertices");
  if (mapping.size == 0 || mapping.size > 16384) throw InputError(path + ": the atlas size is out of range");
  const std::size_t S = mapping.size;
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float v : values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(hi > lo)) hi = lo + 1.0f;
  // Gutter and unused texels: black outside charts, dark grey inside a chart's rectangle.
  std::vector<std::uint8_t> rgb(S * S * 3, 0);
  const auto put = [&](std::size_t x, std::size_t y, const glm::vec3& c) {
    unsigned char* px = &rgb[((S - 1 - y) * S + x) * 3];  // y up in the atlas, down in the PNG
    for (int k = 0; k < 3; ++k) px[k] = static_cast<unsigned char>(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255.0f));
  };
  for (const Chart& ch : mapping.charts)
    for (std::size_t y = ch.y0; y < std::min<std::size_t>(S, ch.y0 + ch.height); ++y)
      for (std::size_t x = ch.x0; x < std::min<std::size_t>(S, ch.x0 + ch.width); ++x) put(x, y, glm::vec3(0.12f));
  for (const AtlasTriangle& at : mapping.triangles) {
    if (at.chart >= mapping.charts.size() || at.face >= mesh.triangles.size()) continue;
    const Chart& ch = mapping.charts[at.chart];
    const Triangle& t = mesh.triangles[at.face];
    float val[3];
    for (int k = 0; k < 3; ++k) val[k] = std::isfinite(values[t[k]]) ? (values[t[k]] - lo) / (hi - lo) : 0.0f;
    const int shifts = ch.wraps_x ? 3 : 1;
    for (int s = 0; s < shifts; ++s) {
      const float dx = s == 0 ? 0.0f : (s == 1 ? -1.0f : 1.0f) * static_cast<float>(ch.width);
      glm::vec2 a = at.uv[0], b = at.uv[1], c = at.uv[2];
      a.x += dx, b.x += dx, c.x += dx;
      const float den = (b.y - c.y) * (a.x - c.x) + (c.x - b.x) * (a.y - c.y);
      if (!(std::abs(den) > 0)) continue;
      const long x0 = std::max<long>(ch.x0, std::lround(std::floor(std::min({a.x, b.x, c.x}) - 0.5f)));
      const long x1 = std::min<long>(static_cast<long>(ch.x0 + ch.width) - 1, std::lround(std::ceil(std::max({a.x, b.x, c.x}))));
      const long y0 = std::max<long>(ch.y0, std::lround(std::floor(std::min({a.y, b.y, c.y}) - 0.5f)));
      const long y1 = std::min<long>(static_cast<long>(ch.y0 + ch.height) - 1, std::lround(std::ceil(std::max({a.y, b.y, c.y}))));
      for (long y = y0; y <= y1; ++y)
        for (long x = x0; x <= x1; ++x) {
          const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
          const float w0 = ((b.y - c.y) * (px - c.x) + (c.x - b.x) * (py - c.y)) / den;
          const float w1 = ((c.y - a.y) * (px - c.x) + (a.x - c.x) * (py - c.y)) / den;
          const float w2 = 1.0f - w0 - w1;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          if (x < 0 || y < 0 || static_cast<std::size_t>(x) >= S || static_cast<std::size_t>(y) >= S) continue;
          put(static_cast<std::size_t>(x), static_cast<std::size_t>(y), io::colormap(w0 * val[0] + w1 * val[1] + w2 * val[2]));
        }
    }
  }
  io::write_png(path, static_cast<int>(S), static_cast<int>(S), 3, rgb);
}

}  // namespace sdfkit::diffusion
