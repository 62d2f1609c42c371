/* The pieces of the SDF definition (sdf_definition.hpp) that the devices evaluate too, written
 * once for three languages: C++ (through sdf_definition.hpp), GLSL 4.50 (the shaders in glsl/, #include with
 * GL_GOOGLE_include_directive; include path engine/include) and OpenCL C 1.2 (the kernels in cl/, the
 * #include is expanded when the kernels are embedded, engine/opencl/embed_sources.cmake).
 * Only the common subset of the three languages: macros for constants, scalar and vec3
 * arithmetic, dot(), no references, no pointers. Tests hold each device's evaluation of these
 * functions to the C++ one (tests/core/sdf_definition_test.cpp, tests/vulkan/definition_test.cpp,
 * tests/opencl/definition_test.cpp). */
#ifndef SDFKIT_SDF_DEFINITION_SHARED_H
#define SDFKIT_SDF_DEFINITION_SHARED_H

#if defined(__cplusplus)
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <algorithm>
#include <cstdint>
#define SDFKIT_FN inline
#define SDFKIT_VEC3 glm::vec3
#define SDFKIT_UINT std::uint32_t
#define SDFKIT_DOT glm::dot
#define SDFKIT_MAX std::max
#elif defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)  // the device version (required), or the language version (clang alone defines only this one)
#define SDFKIT_FN inline
#define SDFKIT_VEC3 float3
#define SDFKIT_UINT uint
#define SDFKIT_DOT dot
#define SDFKIT_MAX max
#elif defined(VULKAN)
#define SDFKIT_FN
#define SDFKIT_VEC3 vec3
#define SDFKIT_UINT uint
#define SDFKIT_DOT dot
#define SDFKIT_MAX max
#else
#error "sdf_definition_shared.h: unknown language (C++, OpenCL C or Vulkan GLSL)"
#endif

/* ---- constants ------------------------------------------------------------------------------ */

/* Lower bound on a ray's angle to the cone axis in the 1/theta weight (radians). Fibonacci rays
 * never come near it (theta_0 > 0.1 rad at the defaults); it guards the view-direction weights
 * of the depth-peeling backend. */
#define SDFKIT_MIN_RAY_ANGLE 1e-3f

/* False-hit rules (sdfkit::FalseHitRule): the value a device sees for each. */
#define SDFKIT_RULE_PAPER 0u
#define SDFKIT_RULE_CGAL 1u

/* Depth-peeling layer images and fragment lists: a depth (normalised, 0..1) of SDFKIT_NO_SURFACE
 * marks a texel where nothing was drawn; any depth from SDFKIT_NO_SURFACE_BELOW up counts as
 * none (sub-pixel corrected depths stay below 1 + 2 / 16). */
#define SDFKIT_NO_SURFACE 2.0f
#define SDFKIT_NO_SURFACE_BITS 0x40000000u /* the bits of 2.0f */
#define SDFKIT_NO_SURFACE_BELOW 1.5f

/* Fragment lists: a node is SDFKIT_NODE_WORDS 32-bit words (depth bits with SDFKIT_FRONT_BIT
 * set for a front face, the octahedral-encoded outward normal, the next node); a pixel's list
 * ends at SDFKIT_END_OF_LIST. */
#define SDFKIT_NODE_WORDS 3u
#define SDFKIT_FRONT_BIT 0x80000000u
#define SDFKIT_END_OF_LIST 0xFFFFFFFFu

/* ---- functions ------------------------------------------------------------------------------ */

/* The false-hit rule: true when a hit with outward unit normal `hit_normal` is kept for a ray of
 * direction `dir` that started at a point with outward unit normal `start_normal`.
 *   Paper (SDFKIT_RULE_PAPER): dropped when the hit faces the same way as the start
 *     (dot(hit_normal, start_normal) > 0);
 *   Cgal (SDFKIT_RULE_CGAL): kept only where the ray leaves the solid (dot(dir, hit_normal) > 0).
 * Any other rule value keeps nothing. */
SDFKIT_FN bool sdfkit_accept_hit(SDFKIT_UINT rule, SDFKIT_VEC3 start_normal, SDFKIT_VEC3 dir,
                                 SDFKIT_VEC3 hit_normal) {
  if (rule == SDFKIT_RULE_PAPER) return SDFKIT_DOT(hit_normal, start_normal) <= 0.0f;
  if (rule == SDFKIT_RULE_CGAL) return SDFKIT_DOT(dir, hit_normal) > 0.0f;
  return false;
}

/* The cone test: a direction `dir` (unit) lies in the cone of half-angle acos(cos_half_cone)
 * around the unit inward normal `inward` when their dot product is at least cos_half_cone. */
SDFKIT_FN bool sdfkit_in_cone(SDFKIT_VEC3 inward, SDFKIT_VEC3 dir, float cos_half_cone) {
  return SDFKIT_DOT(inward, dir) >= cos_half_cone;
}

/* The 1/theta weight of a ray at angle `theta` (radians) to the cone axis. */
SDFKIT_FN float sdfkit_ray_weight(float theta) {
  return 1.0f / SDFKIT_MAX(theta, SDFKIT_MIN_RAY_ANGLE);
}

#endif /* SDFKIT_SDF_DEFINITION_SHARED_H */
