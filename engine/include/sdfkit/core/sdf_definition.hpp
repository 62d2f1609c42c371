#pragma once
// The Shape Diameter Function, defined once (Shapira, Shamir & Cohen-Or 2008).
//
// For a surface point p with outward unit normal n:
//  * N rays (default 30) leave p + kOriginOffset * diag * (-n) inside a cone of full aperture
//    alpha (default 120 degrees) around the inward normal -n. Ray i has
//        cos(theta_i) = 1 - (1 - cos(alpha/2)) * (i + 1/2) / N,   phi_i = i * golden_angle,
//    (a spherical Fibonacci set on the cone's cap) in the tangent frame tangent_frame(-n).
//  * Misses are dropped. A hit is a false intersection and is dropped:
//      FalseHitRule::Paper: when the hit triangle's outward normal makes an angle under 90
//        degrees with n (dot > 0);
//      FalseHitRule::Cgal: unless the ray leaves the solid there (dot(ray dir, hit normal) > 0).
//  * Of the k accepted lengths d_j: median m = sorted(d)[floor(k/2)], sigma = population
//    standard deviation; keep |d_j - m| <= sigma; value = sum(w_j d_j) / sum(w_j) over the kept
//    rays with w_j = 1 / max(theta_j, kMinRayAngle).
//  * No accepted ray: the point has no value and is filled afterwards (see sdf.hpp).
//
// The pieces the devices evaluate too (the false-hit rule, the cone test, the 1/theta weight and
// the constants) are written once in sdf_definition_shared.h, which the GLSL shaders and the
// OpenCL kernels include as well; the device versions are held to this file by tests.

#include "sdfkit/core/sdf_definition_shared.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace sdfkit {

enum class FalseHitRule : std::uint32_t {
  Paper = SDFKIT_RULE_PAPER,  // drop hits whose outward normal faces the same way as the start normal
  Cgal = SDFKIT_RULE_CGAL,    // keep only hits where the ray leaves the solid
};

inline constexpr int kDefaultRays = 30;
inline constexpr float kDefaultConeDegrees = 120.0f;
// Rays start this fraction of the bounding-box diagonal inside the surface, along -n.
inline constexpr float kOriginOffset = 1e-5f;
// Lower bound on a ray's angle to the cone axis in the 1/theta weight (radians); see
// SDFKIT_MIN_RAY_ANGLE.
inline constexpr float kMinRayAngle = SDFKIT_MIN_RAY_ANGLE;
// The golden angle pi * (3 - sqrt(5)) in radians.
inline constexpr double kGoldenAngle = 2.39996322972865332;

// One ray of the cone in the frame whose +z is the cone axis.
struct ConeRay {
  glm::vec3 local_dir;  // unit vector, z = cos(theta)
  float theta;          // angle to the axis, radians
  float weight;         // 1 / max(theta, kMinRayAngle)
};

// The N rays of a cone of full aperture `cone_degrees` (in (0, 180]). Throws on N < 1.
std::vector<ConeRay> cone_rays(int ray_count, float cone_degrees);

// A right-handed orthonormal frame (t, b, axis) built deterministically from a unit axis,
// continuous except across axis.z = 0 sign flips (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited").
struct Frame {
  glm::vec3 t, b, axis;
};
Frame tangent_frame(const glm::vec3& unit_axis);

// World direction of a cone ray around `inward_normal` (unit).
glm::vec3 world_direction(const Frame& frame, const ConeRay& ray);

// True when a hit with outward unit normal `hit_normal` is accepted by `rule` for a ray of
// direction `dir` that started at a point with outward unit normal `start_normal`.
bool accept_hit(FalseHitRule rule, const glm::vec3& start_normal, const glm::vec3& dir,
                const glm::vec3& hit_normal);

// True when the unit direction `dir` lies within the cone of full aperture `cone_degrees`
// around the unit `inward_normal` (dot >= cos(aperture / 2), the cosine rounded to float as the
// devices receive it). The depth-peeling backend keeps a camera's view of a point by this test.
bool in_cone(const glm::vec3& inward_normal, const glm::vec3& dir, float cone_degrees);
float cos_half_cone(float cone_degrees);

// The gather of one point: accepted lengths (any order) with their weights, same length.
struct GatherResult {
  float value = 0.0f;  // weighted mean of the kept lengths; 0 when kept == 0
  std::uint32_t accepted = 0;
  std::uint32_t kept = 0;
};

// Median (element floor(k/2) of the sorted lengths), population sigma, |d - m| <= sigma
// filter, weighted mean. All arithmetic in float, accumulating in input order after the sort
// by length, so device versions that sort the same way can match to rounding.
GatherResult gather(std::span<const float> lengths, std::span<const float> weights);

// Median as defined above (element floor(k/2) of the sorted values); 0 for empty input.
float median_of(std::span<const float> values);

}  // namespace sdfkit
