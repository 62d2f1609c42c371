#version 450
// Figure render, mesh pass, vertex stage: world-space positions (model units) through one
// view's view-projection; the normal and the SDF value go to the fragment stage.
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in float in_value;

layout(push_constant) uniform Push {
  mat4 view_projection;
  vec4 eye;    // xyz: unit direction towards the viewer (the headlight)
  vec4 scale;  // x: value at the palette's start, y: at its end, z: palette entries, w: fade to white
} pc;

layout(location = 0) out vec3 out_normal;
layout(location = 1) out float out_value;

void main() {
  gl_Position = pc.view_projection * vec4(in_position, 1.0);
  out_normal = in_normal;
  out_value = in_value;
}
