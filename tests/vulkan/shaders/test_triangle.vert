#version 450
// Engine self-test: a triangle covering the left half of the viewport (x < 0 in NDC).
void main() {
  const vec2 p[3] = vec2[](vec2(-3.0, -1.0), vec2(0.0, -1.0), vec2(0.0, 3.0));
  gl_Position = vec4(p[gl_VertexIndex], 0.5, 1.0);
}
