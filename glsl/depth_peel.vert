#version 450
// Peel pass, vertex stage. Non-indexed: vertex v is corner v % 3 of triangle v / 3; instance i
// is camera camera_base + i. Front-facing triangles go to layer 2i, back-facing ones (outward
// normal along the view direction) to layer 2i + 1; degenerate triangles are moved outside the
// view volume.
#extension GL_ARB_shader_viewport_layer_array : require
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

struct Triangle {
  vec4 p[3];   // corner positions (model units)
  vec4 n;      // outward unit normal, w = 1 (0 = degenerate)
};
layout(std430, set = 0, binding = 0) readonly buffer Triangles { Triangle tris[]; };
layout(std430, set = 0, binding = 1) readonly buffer Cameras { Camera cams[]; };

layout(push_constant) uniform Push {
  vec4 center_scale;  // bounding-sphere centre, 1 / framed radius
  uint camera_base;
  uint first_layer;
  float epsilon;
} pc;

layout(location = 0) flat out vec3 out_normal;
layout(location = 1) flat out int out_layer;

void main() {
  const uint t = uint(gl_VertexIndex) / 3u;
  const uint corner = uint(gl_VertexIndex) % 3u;
  const Camera cam = cams[pc.camera_base + uint(gl_InstanceIndex)];
  const vec4 n = tris[t].n;
  const vec3 p = (tris[t].p[corner].xyz - pc.center_scale.xyz) * pc.center_scale.w;
  const float facing = dot(n.xyz, cam.dir.xyz);
  gl_Position = vec4(dot(p, cam.right.xyz), dot(p, cam.up.xyz), dot(p, cam.dir.xyz) * 0.5 + 0.5, 1.0);
  if (n.w == 0.0 || facing == 0.0) gl_Position = vec4(-4.0, -4.0, -4.0, 1.0);
  const int layer = 2 * gl_InstanceIndex + (facing > 0.0 ? 1 : 0);
  gl_Layer = layer;
  out_layer = layer;
  out_normal = n.xyz;
}
