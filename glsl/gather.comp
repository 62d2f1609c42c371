#version 450
// Gather pass: the shared statistics of sdfkit::gather (sdf_definition.hpp) per point, on the
// stored (length, theta) samples: sort by length (ties by slot), median = sorted[k / 2],
// population sigma, keep |d - median| <= sigma, weights sdfkit_ray_weight(theta), weighted
// mean. Sums are `precise` (no fused multiply-add) and accumulate in sorted order, like the C++.
#extension GL_GOOGLE_include_directive : require
#include "sdfkit/core/sdf_definition_shared.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 1) buffer Samples { vec2 samples[]; };
// Per point: value bits, kept samples, accepted samples (may exceed max_samples), 0.
layout(std430, set = 0, binding = 2) writeonly buffer Result { uvec4 result[]; };

layout(push_constant) uniform Push {
  uint point_count;
  uint max_samples;
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.point_count) return;
  const uint accepted = counts[i];
  const uint k = min(accepted, pc.max_samples);
  if (k == 0u) {
    result[i] = uvec4(floatBitsToUint(0.0), 0u, accepted, 0u);
    return;
  }
  const uint base = i * pc.max_samples;
  // Insertion sort by length: stable, so equal lengths keep their slot order.
  for (uint a = 1u; a < k; ++a) {
    const vec2 s = samples[base + a];
    uint b = a;
    while (b > 0u && samples[base + b - 1u].x > s.x) {
      samples[base + b] = samples[base + b - 1u];
      --b;
    }
    samples[base + b] = s;
  }
  const float median = samples[base + k / 2u].x;
  precise float sum = 0.0;
  for (uint a = 0u; a < k; ++a) sum += samples[base + a].x;
  const float mean = sum / float(k);
  precise float var = 0.0;
  for (uint a = 0u; a < k; ++a) {
    precise float d = samples[base + a].x - mean;
    var += d * d;
  }
  const float sigma = sqrt(var / float(k));
  precise float wsum = 0.0;
  precise float wdsum = 0.0;
  uint kept = 0u;
  for (uint a = 0u; a < k; ++a) {
    const vec2 s = samples[base + a];
    if (abs(s.x - median) <= sigma) {
      precise float w = sdfkit_ray_weight(s.y);
      wsum += w;
      wdsum += w * s.x;
      ++kept;
    }
  }
  result[i] = uvec4(floatBitsToUint(wdsum / wsum), kept, accepted, 0u);
}
