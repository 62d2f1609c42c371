#version 450
// Atlas dilate: the normalized atlas of one chart (value = blurred value·coverage / blurred
// coverage) over its rectangle and `margin` texels around it; a texel outside the rectangle takes
// the nearest rectangle texel's place (wrapping in x for cylindrical charts), an uncovered one the
// nearest covered texel of the same chart within `reach` (else it stays NaN).
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, binding = 0) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 1) readonly buffer Texels { vec2 texels[]; };  // tiled (atlas_common.glsl)
layout(std430, binding = 2) buffer Atlas { float atlas[]; };

layout(push_constant) uniform Push {
  uint chart;
  uint size;
  uint reach;
  uint margin;
} pc;

const float kCovered = 1e-4;

void main() {
  const Chart c = charts[pc.chart];
  const int w = int(c.rect.z), h = int(c.rect.w), m = int(pc.margin);
  const ivec2 local = ivec2(gl_GlobalInvocationID.xy) - ivec2(m);
  if (local.x >= w + m || local.y >= h + m) return;
  const ivec2 at = ivec2(c.rect.xy) + local;
  if (at.x < 0 || at.y < 0 || at.x >= int(pc.size) || at.y >= int(pc.size)) return;
  const bool wrap = c.params.w != 0u;
  int cx = wrap ? ((local.x % w) + w) % w : clamp(local.x, 0, w - 1);
  int cy = clamp(local.y, 0, h - 1);
  const vec2 own = texels[tiled_index(c.rect.x + uint(cx), c.rect.y + uint(cy), pc.size)];
  if (own.y > kCovered) {
    atlas[uint(at.y) * pc.size + uint(at.x)] = own.x / own.y;
    return;
  }
  const int reach = int(pc.reach);
  float best = 1e30;
  float value = atlas[uint(at.y) * pc.size + uint(at.x)];
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const float d = float(dx * dx + dy * dy);
      if (d >= best) continue;
      int x = cx + dx, y = cy + dy;
      if (wrap) x = ((x % w) + w) % w;
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      const vec2 t = texels[tiled_index(c.rect.x + uint(x), c.rect.y + uint(y), pc.size)];
      if (t.y > kCovered) {
        best = d;
        value = t.x / t.y;
      }
    }
  }
  atlas[uint(at.y) * pc.size + uint(at.x)] = value;
}
