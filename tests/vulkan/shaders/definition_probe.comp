#version 450
// Test shader: the shared definition's false-hit rules and cone test, and the sample store, as
// the depth-peeling passes evaluate them (through peel_samples.glsl, which the diameter and
// fragment-list resolve passes include). Per case: three vec4, the start point's outward normal
// (w = cosine of the cone's half-angle), the view direction, the hit's outward normal.
#extension GL_GOOGLE_include_directive : require
#include "depth_peel_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Cases { vec4 cases[]; };
// Two "points" per case (the Paper rule's, the Cgal rule's), one slot each.
layout(std430, set = 0, binding = 1) buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Samples { vec2 samples[]; };
// Per case: bit 0 = sdfkit_accept_hit(Paper), bit 1 = (Cgal), bit 2 = view_point's cone test.
layout(std430, set = 0, binding = 3) writeonly buffer Bits { uint bits[]; };
#include "peel_samples.glsl"

layout(push_constant) uniform Push {
  uint case_count;
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.case_count) return;
  const vec4 start = cases[3u * i];
  const vec3 dir = cases[3u * i + 1u].xyz, hit = cases[3u * i + 2u].xyz;
  const vec3 inward = -start.xyz;
  Camera cam;
  cam.right = vec4(0.0);
  cam.up = vec4(0.0);
  cam.dir = vec4(dir, 0.0);
  uint b = 0u;
  if (sdfkit_accept_hit(SDFKIT_RULE_PAPER, start.xyz, dir, hit)) b |= 1u;
  if (sdfkit_accept_hit(SDFKIT_RULE_CGAL, start.xyz, dir, hit)) b |= 2u;
  // The point at the framed sphere's centre lands inside any image: only the cone decides.
  PointView v;
  if (view_point(cam, vec3(0.0), inward, start.w, 16, v)) b |= 4u;
  bits[i] = b;
  // The sample store of both rules for a hit 0.25 of the diameter behind the point (zp = 0.5):
  // length 0.25 * 2 / (1 / R) with R = 2, i.e. 1.
  v.zp = 0.5;
  store_hit(2u * i, SDFKIT_RULE_PAPER, inward, cam, v, 0.75, hit, 0.5, 1u);
  store_hit(2u * i + 1u, SDFKIT_RULE_CGAL, inward, cam, v, 0.75, hit, 0.5, 1u);
}
