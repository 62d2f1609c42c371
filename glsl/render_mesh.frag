#version 450
// Figure render, mesh pass, fragment stage: the palette colour of the normalised value times
// headlight Lambert shading (two-sided, so open meshes show their inside).
layout(std430, set = 0, binding = 0) readonly buffer Palette { vec4 palette[]; };

layout(push_constant) uniform Push {
  mat4 view_projection;
  vec4 eye;
  vec4 scale;
} pc;

layout(location = 0) in vec3 in_normal;
layout(location = 1) in float in_value;
layout(location = 0) out vec4 out_color;

void main() {
  const float range = pc.scale.y - pc.scale.x;
  const float t = range > 0.0 ? clamp((in_value - pc.scale.x) / range, 0.0, 1.0) : 0.0;
  const int last = int(pc.scale.z) - 1;
  const float x = t * float(last);
  const int i = min(int(x), max(last - 1, 0));
  const vec3 c = mix(palette[i].rgb, palette[min(i + 1, last)].rgb, clamp(x - float(i), 0.0, 1.0));
  const float len = length(in_normal);
  const float lambert = len > 0.0 ? abs(dot(in_normal / len, pc.eye.xyz)) : 1.0;
  // scale.w fades the shaded colour towards white (skeleton pictures).
  out_color = vec4(mix(c * (0.3 + 0.7 * lambert), vec3(1.0), clamp(pc.scale.w, 0.0, 1.0)), 1.0);
}
