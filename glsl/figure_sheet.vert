#version 450
// Figure render, sheet pass, vertex stage: corner v of the skeleton's sheet triangles (three
// per triangle, model units) through one view's view-projection.
layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };

layout(push_constant) uniform Push {
  mat4 view_projection;
  vec4 color;  // rgb: the flat fill colour
} pc;

void main() { gl_Position = pc.view_projection * vec4(corners[gl_VertexIndex].xyz, 1.0); }
