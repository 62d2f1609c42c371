#version 450
// Figure render, sheet pass, fragment stage: one flat colour (both sides).
layout(push_constant) uniform Push {
  mat4 view_projection;
  vec4 color;
} pc;

layout(location = 0) out vec4 out_color;

void main() { out_color = vec4(pc.color.rgb, 1.0); }
