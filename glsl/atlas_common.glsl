// Shared by the atlas_* shaders (texture-space diffusion): the chart table, as
// passes/atlas_passes.hpp's GpuChart.
struct Chart {
  uvec4 rect;    // x0, y0, width, height (texels)
  uvec4 params;  // box radii 0, 1, 2 of the blur; wraps_x
};
