#pragma once
// Compression of a particle animation (every frame: the same points in the same order) as a
// skinned glTF: bones from the matched per-frame linear skeletons, a rigid transform per bone
// per frame, linear blend skinning weights fitted over all frames, written as a validator-clean
// .glb and measured by playing the file back as a viewer does.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sdfkit::pointcloud {

// One bone's pose in one frame: world rotation and translation of its joint.
struct BonePose {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 translation{0.0f};
};

struct SkinnedAnimation {
  std::vector<glm::vec3> rest;                     // V rest positions (frame 0), model units
  std::vector<std::vector<BonePose>> poses;        // [F][B] joint world poses
  std::vector<glm::mat4> inverse_bind;             // B: inverse of each joint's frame-0 world matrix
  std::vector<std::array<std::uint8_t, 4>> joints; // V: four distinct bone indices
  std::vector<std::array<float, 4>> weights;       // V: non-negative, sum 1 (zero for unused slots)
  double frame_time = 0.0;                         // seconds between frames
  std::size_t bone_count() const { return inverse_bind.size(); }
};

// Per particle: the least-squares weights over all frames (non-negative, summing to 1) of the
// candidate bones `candidates` (1 to 4), given each bone's skinning matrix per frame
// (skin[f][b] = world(f, b) * inverse_bind(b)), the particle's rest position and its position in
// every frame (trajectory[f]). Exact: the best of the equality-constrained solutions over every
// subset of the candidates whose weights are all non-negative. Returns the weights in the
// candidates' order (unused entries 0). Exposed for tests.
std::array<float, 4> fit_weights(const std::vector<std::vector<glm::mat4>>& skin, const glm::vec3& rest,
                                 std::span<const glm::vec3> trajectory, std::span<const std::uint8_t> candidates);

// The rotation about unit `axis` (radians) that best maps the offsets `from` onto `to` in the
// least-squares sense (the twist of a bone about its segment). Exposed for tests.
float fit_twist(const glm::vec3& axis, std::span<const glm::vec3> from, std::span<const glm::vec3> to);

struct CompressionOptions {
  int bones = 16;              // N segments of the skeleton = N bones, in [1, 255]
  double frame_time = 0.0;     // seconds between frames (> 0)
  SkeletonOptions skeleton{};  // segments is set from `bones` (at least 12 for the polyline)
  // How each bone's rotation per frame is found. Polyline: the rest segment turned onto the
  // frame's segment, then the twist about it fitted to the bone's particles (the paper's way).
  // Procrustes: the least-squares rotation of the bone's particles (Kabsch), the polyline only
  // choosing which particles a bone owns. Procrustes is the default: on the shared worm at 16
  // bones the played-back max error is 1.3 units against 17 (the head tip), RMSE 0.25 vs 0.43.
  enum class Rotation { Polyline, Procrustes } rotation = Rotation::Procrustes;
};

struct Compression {
  SkinnedAnimation animation;
  std::vector<Polyline> bones_per_frame;  // the resampled, matched skeletons: N + 1 nodes each
  double skeleton_ms = 0.0, fit_ms = 0.0;
};

// frames: every frame's particles (all of them, same order); skeleton_points: per frame the
// points whose skeleton gives the bones (the outer surface; may be `frames` itself).
Compression compress_animation(const std::vector<std::vector<glm::vec3>>& frames,
                               const std::vector<std::vector<glm::vec3>>& skeleton_points, SdfBackend& backend,
                               const CompressionOptions& options);

// Writes a .glb: one POINTS primitive (vertex i = particle i) with JOINTS_0 / WEIGHTS_0 (unsigned
// bytes, weights normalized to sum exactly 255), a skin (joints under one root node, inverse bind
// matrices) and one animation with a translation and a rotation channel per joint (LINEAR,
// keyframes at f * frame_time; rotations as normalized shorts). Written through a temporary
// file. Returns the file's size in bytes.
std::size_t write_skinned_glb(const SkinnedAnimation& animation, const std::string& path);

// Plays a .glb back as a viewer does: reads the file, decodes accessors, evaluates the animation
// samplers at each keyframe time of the first animation, the joints' world matrices through the
// node hierarchy, the inverse bind matrices and the weights of the first skinned primitive.
// Returns [keyframes][vertices] positions. Throws InputError for a file it cannot play.
std::vector<std::vector<glm::vec3>> play_skinned_glb(const std::string& path);

// Errors of a played-back animation against the original frames.
struct CompressionReport {
  std::size_t frames = 0, points = 0, bones = 0;
  std::size_t raw_bytes = 0, compressed_bytes = 0;
  double ratio = 0.0;
  double body_length = 0.0;  // mean length of the skeletons (end node to end node)
  double rmse = 0.0, max_error = 0.0;  // model units
  double rmse_percent = 0.0, max_percent = 0.0;  // of body_length
  double kg_error = 0.0;  // 100 * |A - A'|_F / |A - mean_per_frame(A)|_F
};
CompressionReport measure_compression(const std::vector<std::vector<glm::vec3>>& original,
                                      const std::vector<std::vector<glm::vec3>>& played, std::size_t glb_bytes,
                                      std::size_t bones, double body_length);
std::string report_json(const CompressionReport& report);

}  // namespace sdfkit::pointcloud
