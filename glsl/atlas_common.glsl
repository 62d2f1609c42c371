// Shared by the atlas_* shaders (texture-space diffusion): the chart table, as
// passes/atlas_passes.hpp's GpuChart.
struct Chart {
  uvec4 rect;    // x0, y0, width, height (texels)
  uvec4 params;  // box radii 0, 1, 2 of the blur; wraps_x
  vec4 metric;   // x: the chart's mean model units per texel
};

// The blurred texel buffers are tiled: 64 x 64 texel tiles, row-major inside a tile and tiles
// row-major over the atlas, so that walking a column touches a new page every 8 texels instead
// of every texel (the column passes were TLB-bound on lavapipe). The rasterized buffer the first
// pass reads is plain row-major.
uint tiled_index(uint x, uint y, uint size) {
  const uint tiles = (size + 63u) >> 6;
  return (((y >> 6) * tiles + (x >> 6)) << 12) + ((y & 63u) << 6) + (x & 63u);
}
