// Shared by the atlas_* shaders (texture-space diffusion): the chart table, as
// passes/atlas_passes.hpp's GpuChart.
struct Chart {
  uvec4 rect;    // x0, y0, width, height (texels)
  uvec4 params;  // box radii 0, 1, 2 of the blur; wraps_x
  vec4 metric;   // x: the chart's mean model units per texel
};

// Line `line` of chart c along `axis` (0: a row, which wraps where the chart does; 1: a column,
// which never wraps), as the blur passes walk it: its first texel, the step between texels, its
// length.
struct ChartLine {
  uvec2 origin;
  uvec2 step;
  int n;
  bool wrap;
};
ChartLine chart_line(Chart c, uint line, uint axis) {
  if (axis == 0u) return ChartLine(uvec2(c.rect.x, c.rect.y + line), uvec2(1u, 0u), int(c.rect.z), c.params.w != 0u);
  return ChartLine(uvec2(c.rect.x + line, c.rect.y), uvec2(0u, 1u), int(c.rect.w), false);
}

// The stretch-compensated blur's box half-width h = f + a (texels; f integer, 0 <= a < 1) where
// the map has m model units per texel along the axis, for a Gaussian whose variance left for the
// blur is `variance` (model units²): each of the three boxes gets a third of variance / m² less
// the bilinear read-back's 1/6 texel². A box of half-width f + a has weights 1 on |k| <= f and a
// on |k| = f + 1, total 2f + 1 + 2a and variance (f (f+1)(2f+1)/3 + 2a (f+1)²) / (2f + 1 + 2a),
// continuous and increasing in h, so a is solved in closed form. -1 where m is not a valid scale.
// (glsl/atlas_raster.frag per fragment, glsl/atlas_blur_stretch.comp for a chart's mean scale.)
float stretch_half_width(float m, float variance) {
  if (!(m > 0.0) || isinf(m)) return -1.0;
  const float v = clamp((variance / (m * m) - 1.0 / 6.0) / 3.0, 0.0, 1.0e8);
  int f = int(floor(0.5 * (sqrt(1.0 + 12.0 * v) - 1.0)));
  // Rounding of the square root: the largest f with f (f + 1) / 3 <= v.
  if (float(f) * float(f + 1) > 3.0 * v) --f;
  if (float(f + 1) * float(f + 2) <= 3.0 * v) ++f;
  f = max(f, 0);
  const float ff = float(f);
  const float a = (2.0 * ff + 1.0) * (v - ff * (ff + 1.0) / 3.0) / (2.0 * ((ff + 1.0) * (ff + 1.0) - v));
  return ff + clamp(a, 0.0, 0.999999);
}

// The blurred texel buffers are tiled: 64 x 64 texel tiles, row-major inside a tile and tiles
// row-major over the atlas, so that walking a column touches a new page every 8 texels instead
// of every texel (the column passes were TLB-bound on lavapipe). The rasterized buffer the first
// pass reads is plain row-major.
uint tiled_index(uint x, uint y, uint size) {
  const uint tiles = (size + 63u) >> 6;
  return (((y >> 6) * tiles + (x >> 6)) << 12) + ((y & 63u) << 6) + (x & 63u);
}
