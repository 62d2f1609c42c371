#version 450
// Atlas sample: per vertex, the blurred atlas read back bilinearly at each of its queries (a uv
// inside a chart: clamped to the rectangle, wrapping in x for cylindrical charts), each read
// normalized by the blurred coverage: sum(w · value·coverage) / sum(w · coverage); the reads
// blended by the queries' weights (a partition of unity over the charts covering the vertex,
// AtlasMapping::samples), written over the vertex's value: one that no covered texel reaches keeps
// the value it had (the field's, or the previous step's).
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

struct Query {
  vec2 uv;
  uint chart;
  float weight;
};
struct Range {
  uint first;
  uint count;
};

layout(std430, binding = 0) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 1) readonly buffer Texels { vec2 texels[]; };  // tiled (atlas_common.glsl)
layout(std430, binding = 2) readonly buffer Queries { Query queries[]; };
layout(std430, binding = 3) readonly buffer Ranges { Range ranges[]; };
// In: each vertex's current value (what it keeps where nothing reaches its queries); out: the read.
layout(std430, binding = 4) buffer Values { float values[]; };

layout(push_constant) uniform Push {
  uint vertex_count;
  uint size;
} pc;

// The normalized bilinear read of query q; y = 0 where no covered texel reaches it.
vec2 read(const Query q) {
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
  return acc.y > 1e-6 ? vec2(acc.x / acc.y, 1.0) : vec2(0.0);
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.vertex_count) return;
  const Range r = ranges[i];
  float sum = 0.0, weight = 0.0;
  for (uint k = r.first; k < r.first + r.count; ++k) {
    const Query q = queries[k];
    const vec2 v = read(q);
    sum += q.weight * v.x * v.y;
    weight += q.weight * v.y;
  }
  if (weight > 0.0) values[i] = sum / weight;
}
