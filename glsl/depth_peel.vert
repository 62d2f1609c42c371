#version 450
// Peel pass, vertex stage. Non-indexed draw of the non-degenerate triangles' corners; instance i is camera
// camera_base + i. The pass draws twice: front faces (back faces culled) into layer 2i, then back
// faces (front faces culled) into layer 2i + 1.
#extension GL_ARB_shader_viewport_layer_array : require
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

layout(location = 0) in vec3 position;  // model units
layout(std430, set = 0, binding = 1) readonly buffer Cameras { Camera cams[]; };

layout(push_constant) uniform Push {
  vec4 center_scale;  // bounding-sphere centre, 1 / framed radius
  uint camera_base;
  uint first_layer;
  float epsilon;
  uint back;          // 0: front faces of this draw, 1: back faces
} pc;

layout(location = 0) flat out int out_layer;
layout(location = 1) flat out uint out_triangle;  // draw-order index of the triangle

void main() {
  const Camera cam = cams[pc.camera_base + uint(gl_InstanceIndex)];
  const vec3 p = (position - pc.center_scale.xyz) * pc.center_scale.w;
  gl_Position = vec4(dot(p, cam.right.xyz), dot(p, cam.up.xyz), dot(p, cam.dir.xyz) * 0.5 + 0.5, 1.0);
  const int layer = 2 * gl_InstanceIndex + int(pc.back);
  gl_Layer = layer;
  out_layer = layer;
  out_triangle = uint(gl_VertexIndex) / 3u;
}
