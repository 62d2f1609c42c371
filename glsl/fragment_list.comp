#version 450
// Fragment-list resolve pass: one invocation per query point, looping over the cameras of the
// batch. For each camera whose view direction lies within the cone around the point's inward
// normal, the point's pixel list gives the nearest back face strictly behind the point (the
// exit) and the nearest front face behind it by more than front_tolerance; the closest hit is
// the front face when it lies before the exit, else the exit; no exit, no sample. Depths are
// moved to the point's sub-pixel position as in the diameter pass (corrected_depth). The
// false-intersection rule and the stored (length, theta) pairs are the diameter pass's.
#extension GL_GOOGLE_include_directive : require
#include "fragment_list_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Cameras { Camera cams[]; };
layout(std430, set = 0, binding = 1) readonly buffer Points {
  vec4 points[];  // per point: ray origin xyz (model units), w = 1 valid / 0 invalid; then inward normals
};
layout(std430, set = 0, binding = 2) buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Samples { vec2 samples[]; };
#include "peel_samples.glsl"
layout(std430, set = 0, binding = 4) readonly buffer Heads { uint heads[]; };
layout(std430, set = 0, binding = 5) readonly buffer Nodes { uint nodes[]; };
layout(std430, set = 0, binding = 6) readonly buffer Counter { uint appended; };

layout(push_constant) uniform Push {
  vec4 center_scale;    // bounding-sphere centre, 1 / framed radius R
  uint camera_base;
  uint camera_count;
  uint point_count;
  uint max_samples;
  float cos_half_cone;
  uint rule;            // SDFKIT_RULE_PAPER or SDFKIT_RULE_CGAL
  int resolution;
  float front_tolerance;  // normalised depth
  uint capacity;        // nodes
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.point_count) return;
  if (appended > pc.capacity) return;  // overflowed batch: run again by the host
  const vec4 origin = points[i];
  if (origin.w == 0.0) return;
  const vec3 inward = points[pc.point_count + i].xyz;
  const vec3 q = (origin.xyz - pc.center_scale.xyz) * pc.center_scale.w;  // in units of R
  for (uint c = 0u; c < pc.camera_count; ++c) {
    const Camera cam = cams[pc.camera_base + c];
    PointView v;
    if (!view_point(cam, q, inward, pc.cos_half_cone, pc.resolution, v)) continue;

    float z_back = SDFKIT_NO_SURFACE, z_front = SDFKIT_NO_SURFACE;
    vec3 n_back = vec3(0.0), n_front = vec3(0.0);
    uint node = heads[(c * uint(pc.resolution) + uint(v.px.y)) * uint(pc.resolution) + uint(v.px.x)];
    while (node != SDFKIT_END_OF_LIST) {
      const uint bits = nodes[SDFKIT_NODE_WORDS * node];
      const vec3 n = decode_normal(nodes[SDFKIT_NODE_WORDS * node + 1u]);
      const float z = corrected_depth(uintBitsToFloat(bits & ~SDFKIT_FRONT_BIT), n, v.px, v.pos, cam, pc.resolution);
      if ((bits & SDFKIT_FRONT_BIT) != 0u) {
        if (z > v.zp + pc.front_tolerance && z < z_front) {
          z_front = z;
          n_front = n;
        }
      } else if (z > v.zp && z < z_back) {
        z_back = z;
        n_back = n;
      }
      node = nodes[SDFKIT_NODE_WORDS * node + 2u];
    }
    if (z_back >= SDFKIT_NO_SURFACE_BELOW) continue;  // no exit behind the point
    const bool front_hit = z_front < z_back;
    store_hit(i, pc.rule, inward, cam, v, front_hit ? z_front : z_back, front_hit ? n_front : n_back,
              pc.center_scale.w, pc.max_samples);
  }
}
