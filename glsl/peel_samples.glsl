// Shared by the passes that turn layers or fragment lists into samples (diameter.comp,
// fragment_list.comp): a camera's view of a query point (the definition's cone test) and the
// per-point sample store (the definition's false-hit rule, then one (length, theta) slot).
// Declare before including: buffers `counts` (uint per point, atomic) and `samples` (vec2 per
// slot, max_samples slots per point).
#ifndef SDFKIT_PEEL_SAMPLES_GLSL
#define SDFKIT_PEEL_SAMPLES_GLSL
#include "depth_peel_common.glsl"

// How a camera sees a query point: cos_theta = dot(inward normal, view direction); pos = the
// point's framebuffer position (pixels) and px its texel; zp = its normalised depth.
struct PointView {
  float cos_theta;
  vec2 pos;
  ivec2 px;
  float zp;
};

// Camera `cam`'s view of the query point q (relative to the framed sphere's centre, in units of
// its radius R) with unit inward normal `inward`: false when the view direction lies outside the
// cone (sdfkit_in_cone) or the point outside the image.
bool view_point(Camera cam, vec3 q, vec3 inward, float cos_half_cone, int resolution, out PointView v) {
  v.cos_theta = dot(inward, cam.dir.xyz);
  v.pos = vec2(0.0);
  v.px = ivec2(0);
  v.zp = 0.0;
  if (!sdfkit_in_cone(inward, cam.dir.xyz, cos_half_cone)) return false;
  const vec2 ndc = vec2(dot(q, cam.right.xyz), dot(q, cam.up.xyz));
  v.pos = (ndc * 0.5 + 0.5) * float(resolution);  // framebuffer position in pixels
  v.px = ivec2(floor(v.pos));
  if (any(lessThan(v.px, ivec2(0))) || any(greaterThanEqual(v.px, ivec2(resolution)))) return false;
  v.zp = dot(q, cam.dir.xyz) * 0.5 + 0.5;
  return true;
}

// The closest hit behind the point along the camera's view, at normalised depth z_hit with
// outward normal hit_normal: dropped by the false-hit rule (sdfkit_accept_hit, the start normal
// is -inward), else its length (model units; inv_radius = 1 / R) and angle to the inward normal
// go to the point's next slot. Slots past max_samples are counted, not stored.
void store_hit(uint point, uint rule, vec3 inward, Camera cam, PointView v, float z_hit, vec3 hit_normal,
               float inv_radius, uint max_samples) {
  if (!sdfkit_accept_hit(rule, -inward, cam.dir.xyz, hit_normal)) return;
  const float length_model = (z_hit - v.zp) * 2.0 / inv_radius;
  const float theta = acos(clamp(v.cos_theta, -1.0, 1.0));
  const uint slot = atomicAdd(counts[point], 1u);
  if (slot < max_samples) samples[point * max_samples + slot] = vec2(length_model, theta);
}

#endif  // SDFKIT_PEEL_SAMPLES_GLSL
