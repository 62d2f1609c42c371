#version 450
// Diameter pass: one invocation per query point, looping over the cameras of the batch. For
// each camera whose view direction lies within the cone around the point's inward normal, the
// point is accepted when its depth lies strictly between back layer k-1 and back layer k at its
// pixel (back layer k is then the first exit behind it); see depth_peel.hpp for the rules.
// Accepted (length, theta) pairs go to the point's slots; the count is an atomic per point.
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Cameras { Camera cams[]; };
layout(std430, set = 0, binding = 1) readonly buffer Points {
  vec4 points[];  // per point: ray origin xyz (model units), w = 1 valid / 0 invalid; then inward normals
};
layout(std430, set = 0, binding = 2) buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Samples { vec2 samples[]; };
#include "peel_samples.glsl"
layout(set = 0, binding = 4) uniform usampler2DArray previous_layer;
layout(set = 0, binding = 5) uniform usampler2DArray current_layer;
// Per peel step of a submission: points whose exit may still lie in a deeper layer.
layout(std430, set = 0, binding = 6) buffer Pending { uint pending[]; };

layout(push_constant) uniform Push {
  vec4 center_scale;    // bounding-sphere centre, 1 / framed radius R
  uint camera_base;
  uint camera_count;
  uint first_layer;
  uint point_count;
  uint max_samples;
  float cos_half_cone;
  uint rule;            // SDFKIT_RULE_PAPER or SDFKIT_RULE_CGAL
  int resolution;
  float front_tolerance;  // normalised depth
  uint pending_slot;
} pc;

// Depth of the layer texel at `px`, moved along the surface plane to the sub-pixel position
// `pos` (pixels); SDFKIT_NO_SURFACE when the texel is empty. Returns the decoded normal too.
float layer_depth(usampler2DArray layer_image, ivec2 px, int layer, vec2 pos, Camera cam, out vec3 normal) {
  const uvec2 t = texelFetch(layer_image, ivec3(px, layer), 0).xy;
  const float z = uintBitsToFloat(t.x);
  normal = vec3(0.0);
  if (z >= SDFKIT_NO_SURFACE_BELOW) return SDFKIT_NO_SURFACE;
  normal = decode_normal(t.y);
  return corrected_depth(z, normal, px, pos, cam, pc.resolution);
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.point_count) return;
  const vec4 origin = points[i];
  if (origin.w == 0.0) return;
  const vec3 inward = points[pc.point_count + i].xyz;
  const vec3 q = (origin.xyz - pc.center_scale.xyz) * pc.center_scale.w;  // in units of R
  for (uint c = 0u; c < pc.camera_count; ++c) {
    const Camera cam = cams[pc.camera_base + c];
    PointView v;
    if (!view_point(cam, q, inward, pc.cos_half_cone, pc.resolution, v)) continue;
    const int back = int(2u * c + 1u);

    vec3 back_normal;
    const float z1 = layer_depth(current_layer, v.px, back, v.pos, cam, back_normal);
    if (z1 >= SDFKIT_NO_SURFACE_BELOW) continue;  // no back layer k here: none deeper either
    if (!(v.zp < z1)) {
      // The point lies behind back layer k: a later layer may hold its exit.
      atomicAdd(pending[pc.pending_slot], 1u);
      continue;
    }
    if (pc.first_layer == 0u) {
      vec3 n0;
      const float z0 = layer_depth(previous_layer, v.px, back, v.pos, cam, n0);
      if (!(z0 < v.zp)) continue;
    }
    // The closest hit: a front face of this layer between the point and the exit, if any.
    float z_hit = z1;
    vec3 hit_normal = back_normal;
    vec3 front_normal;
    const float zf = layer_depth(current_layer, v.px, back - 1, v.pos, cam, front_normal);
    if (zf < SDFKIT_NO_SURFACE_BELOW && zf > v.zp + pc.front_tolerance && zf < z1) {
      z_hit = zf;
      hit_normal = front_normal;
    }
    store_hit(i, pc.rule, inward, cam, v, z_hit, hit_normal, pc.center_scale.w, pc.max_samples);
  }
}
