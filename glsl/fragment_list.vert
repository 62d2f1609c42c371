#version 450
// Fragment-list pass, vertex stage. Non-indexed draw of the non-degenerate triangles' corners
// (three per triangle, in draw order); instance i is camera camera_base + i (no layered
// rendering: the fragment stage indexes its camera's heads).
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

layout(location = 0) in vec3 position;  // model units
layout(std430, set = 0, binding = 1) readonly buffer Cameras { Camera cams[]; };

layout(push_constant) uniform Push {
  vec4 center_scale;  // bounding-sphere centre, 1 / framed radius
  uint camera_base;
  int resolution;
  uint capacity;
} pc;

layout(location = 0) flat out uint out_camera;    // index within the batch
layout(location = 1) flat out uint out_triangle;  // draw-order index of the triangle

void main() {
  const Camera cam = cams[pc.camera_base + uint(gl_InstanceIndex)];
  const vec3 p = (position - pc.center_scale.xyz) * pc.center_scale.w;
  gl_Position = vec4(dot(p, cam.right.xyz), dot(p, cam.up.xyz), dot(p, cam.dir.xyz) * 0.5 + 0.5, 1.0);
  out_camera = uint(gl_InstanceIndex);
  out_triangle = uint(gl_VertexIndex) / 3u;
}
