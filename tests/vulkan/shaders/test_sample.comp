#version 450
// Engine self-test: copies one row of a sampled R32F image into a buffer (+ 1 per pass call).
layout(local_size_x = 16) in;
layout(binding = 0) uniform sampler2DArray image;
layout(std430, binding = 1) buffer Out { float row[]; };
void main() {
  uint x = gl_GlobalInvocationID.x;
  row[x] += texelFetch(image, ivec3(int(x), 8, 0), 0).r;
}
