#version 450
// Engine self-test: out[i] = in[i] * 2 + i.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { float data_in[]; };
layout(std430, binding = 1) writeonly buffer Out { float data_out[]; };
layout(push_constant) uniform Push { uint count; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  data_out[i] = data_in[i] * 2.0 + float(i);
}
