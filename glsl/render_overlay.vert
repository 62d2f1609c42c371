#version 450
// Figure render, overlay pass: screen-space quads for skeleton segments and points. Vertex v
// is corner v % 6 of segment v / 6; a segment whose ends coincide is drawn as a square point.
struct Segment {
  vec4 a;      // xyz: first end (model units), w: half width in pixels
  vec4 b;      // xyz: second end
  vec4 color;  // rgb; w: layer, 0 drawn over 1 over 2 over 3 (depth orders within a layer)
};
layout(std430, set = 0, binding = 0) readonly buffer Segments { Segment segments[]; };

layout(push_constant) uniform Push {
  mat4 view_projection;
  vec4 viewport;  // xy: the view's size in pixels
} pc;

layout(location = 0) flat out vec3 out_color;

void main() {
  const Segment s = segments[gl_VertexIndex / 6];
  // (along, across) in half widths: two triangles spanning the segment plus end caps.
  const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1),
                                 vec2(-1, 1));
  const vec2 k = corners[gl_VertexIndex % 6];
  const vec4 ca = pc.view_projection * vec4(s.a.xyz, 1.0);
  const vec4 cb = pc.view_projection * vec4(s.b.xyz, 1.0);
  const vec2 pa = ca.xy / ca.w * pc.viewport.xy;
  const vec2 pb = cb.xy / cb.w * pc.viewport.xy;
  const vec2 d = pb - pa;
  const vec2 dir = dot(d, d) > 1e-8 ? normalize(d) : vec2(1.0, 0.0);
  const vec2 perp = vec2(-dir.y, dir.x);
  const vec4 c = k.x < 0.0 ? ca : cb;
  const vec2 offset_px = (dir * k.x + perp * k.y) * s.a.w;
  gl_Position = c + vec4(2.0 * offset_px / pc.viewport.xy * c.w, 0.0, 0.0);
  // Layers: depth in [0, 1] squeezed into [layer / 4, (layer + 1) / 4].
  const float z = clamp(gl_Position.z / gl_Position.w, 0.0, 1.0);
  gl_Position.z = 0.25 * (z + clamp(s.color.w, 0.0, 3.0)) * gl_Position.w;
  out_color = s.color.rgb;
}
