// Shared by the depth-peeling shaders: camera records and the layer-image encoding.

// One orthographic camera: right and up span the image, dir is the viewing direction (depth
// grows along it). xyz used, w padding.
struct Camera {
  vec4 right;
  vec4 up;
  vec4 dir;
};

// Layer images are R32G32_UINT: x = depth bits (float, 0..1; kNoSurface where nothing was drawn),
// y = the outward unit normal, octahedral-encoded in two snorm16.
const float kNoSurface = 2.0;

vec2 oct_wrap(vec2 v) { return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

uint encode_normal(vec3 n) {
  n /= (abs(n.x) + abs(n.y) + abs(n.z));
  vec2 e = n.z >= 0.0 ? n.xy : oct_wrap(n.xy);
  return packSnorm2x16(e);
}

vec3 decode_normal(uint bits) {
  vec2 e = unpackSnorm2x16(bits);
  vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
  if (n.z < 0.0) n.xy = oct_wrap(n.xy);
  return normalize(n);
}
