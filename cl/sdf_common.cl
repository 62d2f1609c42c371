// sdfkit OpenCL kernels, part 1: the shared definition's ray set (see
// engine/include/sdfkit/core/sdf_definition.hpp). OpenCL C 1.2.
//
// Contraction of a*b+c into fma is off so every formula rounds like the C++ definition.
#pragma OPENCL FP_CONTRACT OFF

// Build options supply STACK_SIZE (traversal stack entries).
#ifndef STACK_SIZE
#define STACK_SIZE 128
#endif

#define MIN_RAY_ANGLE 1e-3f
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

// The cone table: ray i of n in the cone's local frame (xyz) and its weight 1/max(theta, min)
// (w). one_minus_cos = 1 - cos(aperture/2). The golden angle in turns is split into c_hi, whose
// products with i < 2^10 are exact in float, plus the small c_lo, so phi keeps full precision.
__kernel void make_cone(int n, float one_minus_cos, float c_hi, float c_lo,
                        __global float4* table) {
  const int i = get_global_id(0);
  if (i >= n) return;
  const float x = one_minus_cos * ((float)i + 0.5f) / (float)n;  // 1 - cos(theta)
  const float cos_t = 1.0f - x;
  const float sin_t = sqrt(x * (2.0f - x));
  const float hi = (float)i * c_hi;
  float turns = (hi - floor(hi)) + (float)i * c_lo;
  turns -= floor(turns);
  const float phi = turns * 6.283185307179586f;
  const float theta = 2.0f * asin(sqrt(0.5f * x));
  table[i] = (float4)(sin_t * cos(phi), sin_t * sin(phi), cos_t,
                      1.0f / fmax(theta, MIN_RAY_ANGLE));
}

// Test entry: the world directions (xyz) and weights (w) of every ray of every normal,
// point-major.
__kernel void ray_directions(__global const float4* normals, __global const float4* table,
                             int n_rays, uint n_points, __global float4* out) {
  const uint g = get_global_id(0);
  if (g >= n_points * (uint)n_rays) return;
  const uint p = g / (uint)n_rays, r = g - p * (uint)n_rays;
  out[g] = (float4)(ray_direction(normals[p].xyz, table[r].xyz), table[r].w);
}
