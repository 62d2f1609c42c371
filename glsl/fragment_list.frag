#version 450
// Fragment-list pass, fragment stage: no depth test; every fragment is appended to its pixel's
// linked list (see fragment_list_common.glsl for the node layout). A fragment past the node
// capacity is only counted: the host sees counter > capacity, grows the node buffer and runs the
// batch again (the resolve pass ignores an overflowed batch).
#extension GL_GOOGLE_include_directive : require
#include "fragment_list_common.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Normals { vec4 normals[]; };  // per drawn triangle
layout(std430, set = 0, binding = 2) buffer Heads { uint heads[]; };  // per camera of the batch, per pixel
layout(std430, set = 0, binding = 3) writeonly buffer Nodes { uint nodes[]; };  // SDFKIT_NODE_WORDS per node
layout(std430, set = 0, binding = 4) buffer Counter { uint appended; };  // may exceed the capacity

layout(push_constant) uniform Push {
  vec4 center_scale;
  uint camera_base;
  int resolution;
  uint capacity;  // nodes
} pc;

layout(location = 0) flat in uint in_camera;
layout(location = 1) flat in uint in_triangle;  // draw-order index (not gl_PrimitiveID: see the backend)
layout(location = 0) out uint out_unused;  // the pass's attachment only sets the render area

void main() {
  out_unused = 0u;
  const uint node = atomicAdd(appended, 1u);
  if (node >= pc.capacity) return;
  const ivec2 px = ivec2(gl_FragCoord.xy);
  const uint head = (in_camera * uint(pc.resolution) + uint(px.y)) * uint(pc.resolution) + uint(px.x);
  nodes[SDFKIT_NODE_WORDS * node] = floatBitsToUint(gl_FragCoord.z) | (gl_FrontFacing ? SDFKIT_FRONT_BIT : 0u);
  nodes[SDFKIT_NODE_WORDS * node + 1u] = encode_normal(normals[in_triangle].xyz);
  nodes[SDFKIT_NODE_WORDS * node + 2u] = atomicExchange(heads[head], node);
}
