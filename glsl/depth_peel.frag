#version 450
// Peel pass, fragment stage: keeps only fragments strictly behind the previous layer of the
// same kind (front or back) at this pixel, by more than `epsilon` in normalised depth, and
// stores their depth and the triangle's outward normal.
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Normals { vec4 normals[]; };  // per drawn triangle
layout(set = 0, binding = 2) uniform usampler2DArray previous_layer;

layout(push_constant) uniform Push {
  vec4 center_scale;
  uint camera_base;
  uint first_layer;
  float epsilon;
  uint back;
} pc;

layout(location = 0) flat in int in_layer;
layout(location = 1) flat in uint in_triangle;  // draw-order index (not gl_PrimitiveID: see the backend)
layout(location = 0) out uvec2 out_layer_texel;

void main() {
  const float z = gl_FragCoord.z;
  if (pc.first_layer == 0u) {
    const uint prev = texelFetch(previous_layer, ivec3(ivec2(gl_FragCoord.xy), in_layer), 0).x;
    if (z <= uintBitsToFloat(prev) + pc.epsilon) discard;
  }
  out_layer_texel = uvec2(floatBitsToUint(z), encode_normal(normals[in_triangle].xyz));
}
