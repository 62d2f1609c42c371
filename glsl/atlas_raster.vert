#version 450
// Atlas raster, vertex stage: an atlas triangle's corner (texel coordinates) to clip space over
// the whole atlas, with its mesh vertex's current value; texel (x, y) covers [x, x+1) x [y, y+1),
// framebuffer row y = atlas row y. Also the range of the triangle's three corner values, which
// the fragment stage clamps the interpolated value to (RasterVertex::corners: a sliver's plane
// equation extrapolates at the texel centres its snapped corners cover outside it).
layout(location = 0) in vec2 in_uv;
layout(location = 1) in uint in_vertex;  // the mesh vertex whose value the corner carries
layout(location = 2) in uint in_chart;
layout(location = 3) in vec2 in_stretch;  // model units per texel along x, y (the triangle's)
layout(location = 4) in vec2 in_variance;  // the blur's variance left over the triangle along x, y, model units²
layout(location = 5) in uvec3 in_corners;  // the triangle's three mesh vertices

// One value per mesh vertex: the field, or the previous step's read-back (DiffuseOptions::steps).
layout(std430, binding = 1) readonly buffer Values { float values[]; };

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
  out_value = values[in_vertex];
  out_chart = in_chart;
  out_stretch = in_stretch;
  out_variance = in_variance;
  const float a = values[in_corners.x], b = values[in_corners.y], c = values[in_corners.z];
  out_range = vec2(min(a, min(b, c)), max(a, max(b, c)));
}
