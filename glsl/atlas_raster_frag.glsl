// Atlas raster, fragment stage, shared by its two variants: atlas_raster.frag (value and
// coverage, and from the triangle's stretch, model units per texel along x, y, the
// stretch-compensated blur's box half-widths there: stretch_half_width) and
// atlas_raster_value.frag (ATLAS_RASTER_VALUE_ONLY: value and coverage alone, one colour
// attachment, for a blur with one width in texels that never reads the half-widths). Only
// inside the triangle's own chart rectangle (a triangle across a wrapping chart's seam is drawn
// once per side and clipped here).
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(std430, binding = 0) readonly buffer Charts { Chart charts[]; };

layout(location = 0) in float in_value;
layout(location = 1) flat in uint in_chart;
layout(location = 2) flat in vec2 in_stretch;
layout(location = 3) flat in vec2 in_variance;  // the blur's variance left over this triangle along x, y (RasterVertex::variance)
layout(location = 4) flat in vec2 in_range;  // the triangle's lowest and highest corner value
layout(location = 0) out vec2 out_texel;
#ifndef ATLAS_RASTER_VALUE_ONLY
layout(location = 1) out vec2 out_half_width;
#endif

layout(push_constant) uniform Push {
  vec4 scale;  // x: 2 / atlas size (the vertex stage's)
} pc;

void main() {
  const uvec4 r = charts[in_chart].rect;
  const uvec2 p = uvec2(gl_FragCoord.xy);
  if (p.x < r.x || p.y < r.y || p.x >= r.x + r.z || p.y >= r.y + r.w) discard;
  // Within the triangle's corner values: interpolation never leaves them, extrapolation at the
  // texels a sliver's snapped corners cover outside it does (glsl/atlas_raster.vert).
  out_texel = vec2(clamp(in_value, in_range.x, in_range.y), 1.0);
#ifndef ATLAS_RASTER_VALUE_ONLY
  out_half_width = vec2(stretch_half_width(in_stretch.x, in_variance.x), stretch_half_width(in_stretch.y, in_variance.y));
#endif
}
