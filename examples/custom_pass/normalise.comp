#version 450
// The example's own compute pass: per-vertex SDF values in, the same values mapped to [0, 1]
// over [lo, hi] out, and the number of values above `threshold` counted with an atomic.

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Values { float values[]; };         // n, model units
layout(std430, set = 0, binding = 1) writeonly buffer Normalised { float normalised[]; }; // n, in [0, 1]
layout(std430, set = 0, binding = 2) buffer Counter { uint above; };                      // zeroed before

layout(push_constant) uniform Push {
  float lo, hi;     // range of the values, model units (hi > lo)
  float threshold;  // model units
  uint count;       // n
} push;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= push.count) return;
  const float v = values[i];
  normalised[i] = (v - push.lo) / (push.hi - push.lo);
  if (v > push.threshold) atomicAdd(above, 1u);
}
