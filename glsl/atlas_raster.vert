#version 450
// Atlas raster, vertex stage: an atlas triangle's corner (texel coordinates) to clip space over
// the whole atlas, with its mesh vertex's current value; texel (x, y) covers [x, x+1) x [y, y+1),
// framebuffer row y = atlas row y.
//
// Also the range of the triangle's three corner values, which the fragment stage clamps the
// interpolated value to. The rasterizer decides coverage on corners snapped to its sub-texel grid,
// so a sliver (a rim triangle seen edge-on by a chart) covers texel centres outside the triangle
// itself, where its plane equation extrapolates with a gradient as steep as the sliver is thin
// (cheese: -14 and 107 in a field of 0.4 to 1.7). A linear interpolant inside its triangle never
// leaves its corners' range, so the clamp only undoes the extrapolation, and every texel stays
// within the field's range (the maximum principle the blur, a positive normalized filter, then
// keeps). The range is a flat output, taken from the provoking vertex (the triangle's first in a
// list): only that corner reads the triangle's three mesh vertices, from the soup itself (the draw
// is non-indexed, so triangle t's corners are soup entries 3t, 3t+1, 3t+2).
layout(location = 0) in vec2 in_uv;
layout(location = 1) in uint in_vertex;  // the mesh vertex whose value the corner carries
layout(location = 2) in uint in_chart;
layout(location = 3) in vec2 in_stretch;  // model units per texel along x, y (the triangle's)
layout(location = 4) in vec2 in_variance;  // the blur's variance left over the triangle along x, y, model units²

// One value per mesh vertex: the field, or the previous step's read-back (DiffuseOptions::steps).
layout(std430, binding = 1) readonly buffer Values { float values[]; };

// The vertex buffer itself (passes::RasterVertex, 32 bytes).
struct Corner {
  vec2 uv;
  uint vertex;
  uint chart;
  vec2 stretch;
  vec2 variance;
};
layout(std430, binding = 2) readonly buffer Soup { Corner soup[]; };

layout(push_constant) uniform Push {
  vec4 scale;  // x: 2 / atlas size
} pc;

layout(location = 0) out float out_value;
layout(location = 1) flat out uint out_chart;
layout(location = 2) flat out vec2 out_stretch;
layout(location = 3) flat out vec2 out_variance;
layout(location = 4) flat out vec2 out_range;  // the lowest and highest of the triangle's corner values

void main() {
  gl_Position = vec4(in_uv * pc.scale.x - 1.0, 0.0, 1.0);
  const float value = values[in_vertex];
  out_value = value;
  out_chart = in_chart;
  out_stretch = in_stretch;
  out_variance = in_variance;
  out_range = vec2(value);
  if (gl_VertexIndex % 3 == 0) {
    const float b = values[soup[gl_VertexIndex + 1].vertex], c = values[soup[gl_VertexIndex + 2].vertex];
    out_range = vec2(min(value, min(b, c)), max(value, max(b, c)));
  }
}
