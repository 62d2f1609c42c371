#version 450
// Atlas sample: per vertex, the blurred atlas read back bilinearly at the vertex's uv inside its
// own chart (clamped to the rectangle; wrapping in x for cylindrical charts), normalized by the
// blurred coverage: sum(w · value·coverage) / sum(w · coverage). A vertex no covered texel
// reaches keeps its fallback (its own value).
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

struct Query {
  vec2 uv;
  uint chart;
  float fallback;
};

layout(std430, binding = 0) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 1) readonly buffer Texels { vec2 texels[]; };  // tiled (atlas_common.glsl)
layout(std430, binding = 2) readonly buffer Queries { Query queries[]; };
layout(std430, binding = 3) writeonly buffer Values { float values[]; };

layout(push_constant) uniform Push {
  uint vertex_count;
  uint size;
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.vertex_count) return;
  const Query q = queries[i];
  const Chart c = charts[q.chart];
  const int w = int(c.rect.z), h = int(c.rect.w);
  const vec2 p = q.uv - vec2(c.rect.xy) - 0.5;
  const vec2 b = floor(p);
  const vec2 f = p - b;
  vec2 acc = vec2(0.0);
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      int x = int(b.x) + dx, y = int(b.y) + dy;
      if (c.params.w != 0u) {
        x %= w;
        if (x < 0) x += w;
      } else {
        x = clamp(x, 0, w - 1);
      }
      y = clamp(y, 0, h - 1);
      const float wgt = (dx == 0 ? 1.0 - f.x : f.x) * (dy == 0 ? 1.0 - f.y : f.y);
      acc += wgt * texels[tiled_index(c.rect.x + uint(x), c.rect.y + uint(y), pc.size)];
    }
  }
  values[i] = acc.y > 1e-6 ? acc.x / acc.y : q.fallback;
}
