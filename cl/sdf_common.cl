// sdfkit OpenCL kernels, part 1: the shared definition's ray set (see
// engine/include/sdfkit/core/sdf_definition.hpp). OpenCL C 1.2.
//
// Contraction of a*b+c into fma is off so every formula rounds like the C++ definition.
#pragma OPENCL FP_CONTRACT OFF

// The definition's constants, false-hit rule, cone test and weight, shared with C++ and GLSL
// (expanded in place when the kernels are embedded).
#include "sdfkit/core/sdf_definition_shared.h"

// Build options supply STACK_SIZE (traversal stack entries).
#ifndef STACK_SIZE
#define STACK_SIZE 128
#endif

#define NO_HIT_KEY 0xFFFFFFFFFFFFFFFFUL

// Duff et al. 2017 orthonormal frame around a unit axis, as sdfkit::tangent_frame.
inline void tangent_frame(float3 n, float3* t, float3* b) {
  const float sign = copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float bb = n.x * n.y * a;
  *t = (float3)(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
  *b = (float3)(bb, sign + n.y * n.y * a, -n.y);
}

// World direction of a cone ray (local xyz) around the inward normal -n, summed in the order
// of sdfkit::world_direction.
inline float3 ray_direction(float3 outward_normal, float3 local_dir) {
  const float3 axis = -outward_normal;
  float3 t, b;
  tangent_frame(axis, &t, &b);
  return t * local_dir.x + b * local_dir.y + axis * local_dir.z;
}

// The cone table (computed on the host by sdfkit::cone_rays and uploaded): ray i in the cone's
// local frame (xyz) and its weight 1/max(theta, SDFKIT_MIN_RAY_ANGLE) (w).

// Test entry: the world directions (xyz) and weights (w) of every ray of every normal,
// point-major.
__kernel void ray_directions(__global const float4* normals, __global const float4* table,
                             int n_rays, uint n_points, __global float4* out) {
  const uint g = get_global_id(0);
  if (g >= n_points * (uint)n_rays) return;
  const uint p = g / (uint)n_rays, r = g - p * (uint)n_rays;
  out[g] = (float4)(ray_direction(normals[p].xyz, table[r].xyz), table[r].w);
}

// Test entry: the shared false-hit rule and cone test on the device. Per case: start normal
// (outward), ray direction, hit normal (outward), each xyz of a float4, and in the start
// normal's w the cosine of the cone's half-angle. Writes bit 0 = sdfkit_accept_hit(Paper),
// bit 1 = sdfkit_accept_hit(Cgal), bit 2 = sdfkit_in_cone(-start normal, direction, cos).
__kernel void definition_probe(__global const float4* cases, uint n, __global uint* out) {
  const uint g = get_global_id(0);
  if (g >= n) return;
  const float4 start = cases[3 * g], dir = cases[3 * g + 1], hit = cases[3 * g + 2];
  uint bits = 0;
  if (sdfkit_accept_hit(SDFKIT_RULE_PAPER, start.xyz, dir.xyz, hit.xyz)) bits |= 1u;
  if (sdfkit_accept_hit(SDFKIT_RULE_CGAL, start.xyz, dir.xyz, hit.xyz)) bits |= 2u;
  if (sdfkit_in_cone(-start.xyz, dir.xyz, start.w)) bits |= 4u;
  out[g] = bits;
}
