#version 450
// Atlas raster, fragment stage: (value, coverage 1) and the triangle's stretch (model units per
// texel along x, y), only inside the triangle's own chart rectangle (a triangle across a wrapping
// chart's seam is drawn once per side and clipped here).
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(std430, binding = 0) readonly buffer Charts { Chart charts[]; };

layout(location = 0) in float in_value;
layout(location = 1) flat in uint in_chart;
layout(location = 2) flat in vec2 in_stretch;
layout(location = 0) out vec2 out_texel;
layout(location = 1) out vec2 out_stretch;

void main() {
  const uvec4 r = charts[in_chart].rect;
  const uvec2 p = uvec2(gl_FragCoord.xy);
  if (p.x < r.x || p.y < r.y || p.x >= r.x + r.z || p.y >= r.y + r.w) discard;
  out_texel = vec2(in_value, 1.0);
  out_stretch = in_stretch;
}
