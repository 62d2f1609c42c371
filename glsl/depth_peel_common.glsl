// Shared by the depth-peeling shaders: camera records and the layer-image encoding. The
// definition's constants and rules come from the header C++ and OpenCL C include too.
#ifndef SDFKIT_DEPTH_PEEL_COMMON_GLSL
#define SDFKIT_DEPTH_PEEL_COMMON_GLSL
#include "sdfkit/core/sdf_definition_shared.h"

// One orthographic camera: right and up span the image, dir is the viewing direction (depth
// grows along it). xyz used, w padding.
struct Camera {
  vec4 right;
  vec4 up;
  vec4 dir;
};

// Layer images are R32G32_UINT: x = depth bits (float, 0..1; SDFKIT_NO_SURFACE where nothing was
// drawn), y = the outward unit normal, octahedral-encoded in two snorm16.

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

// A fragment's depth (stored at the centre of texel `px`), moved along the plane of its surface
// (outward unit normal `normal`) to the sub-pixel position `pos` (pixels) of a query point, the
// move limited to two pixels' depth. Plane: d(depth)/d(image x) = -n_right / n_dir (model
// units); one pixel is 2R/res model units, one unit of normalised depth is 2R model units.
float corrected_depth(float z, vec3 normal, ivec2 px, vec2 pos, Camera cam, int resolution) {
  const float nd = dot(normal, cam.dir.xyz);
  const float nd_safe = nd >= 0.0 ? max(nd, 0.2) : min(nd, -0.2);
  const vec2 delta = clamp(pos - (vec2(px) + 0.5), vec2(-0.5), vec2(0.5));
  const float slope_r = -dot(normal, cam.right.xyz) / nd_safe;
  const float slope_u = -dot(normal, cam.up.xyz) / nd_safe;
  const float dz = (slope_r * delta.x + slope_u * delta.y) / float(resolution);
  return z + clamp(dz, -2.0 / float(resolution), 2.0 / float(resolution));
}

#endif  // SDFKIT_DEPTH_PEEL_COMMON_GLSL
