// Compression of a particle animation by linear blend skinning: bones from the matched
// skeletons, per-bone rigid transforms (the polyline's segment direction plus a fitted twist and
// a least-squares translation), weights by constrained least squares over all frames.

#include "sdfkit/pointcloud/skinning.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"

#include <Eigen/Dense>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace sdfkit::pointcloud {
namespace {

// The shortest rotation taking unit a onto unit b.
glm::quat rotation_between(const glm::vec3& a, const glm::vec3& b) {
  const float d = glm::dot(a, b);
  if (d < -0.999999f) {
    glm::vec3 axis = glm::cross(glm::vec3(1, 0, 0), a);
    if (glm::dot(axis, axis) < 1e-6f) axis = glm::cross(glm::vec3(0, 1, 0), a);
    return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
  }
  const glm::vec3 c = glm::cross(a, b);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));  // glm::quat(w, x, y, z)
}

float segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float l2 = glm::dot(ab, ab);
  const float u = l2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
  return glm::distance(p, a + u * ab);
}

glm::mat4 pose_matrix(const BonePose& p) {
  glm::mat4 m = glm::mat4_cast(p.rotation);
  m[3] = glm::vec4(p.translation, 1.0f);
  return m;
}

}  // namespace

float fit_twist(const glm::vec3& axis, std::span<const glm::vec3> from, std::span<const glm::vec3> to) {
  double s = 0.0, c = 0.0;
  for (std::size_t i = 0; i < from.size() && i < to.size(); ++i) {
    const glm::vec3 f = from[i] - axis * glm::dot(axis, from[i]);
    const glm::vec3 t = to[i] - axis * glm::dot(axis, to[i]);
    s += glm::dot(axis, glm::cross(f, t));
    c += glm::dot(f, t);
  }
  return (s == 0.0 && c == 0.0) ? 0.0f : static_cast<float>(std::atan2(s, c));
}

std::array<float, 4> fit_weights(const std::vector<std::vector<glm::mat4>>& skin, const glm::vec3& rest,
                                 std::span<const glm::vec3> trajectory, std::span<const std::uint8_t> candidates) {
  const std::size_t m = std::min<std::size_t>(candidates.size(), 4);
  if (m == 0) throw InputError("fit_weights needs at least one candidate bone");
  // Normal equations of min |sum_k w_k (S_fk rest) - y_f|^2 over all frames f.
  Eigen::Matrix4d G = Eigen::Matrix4d::Zero();
  Eigen::Vector4d h = Eigen::Vector4d::Zero();
  double yy = 0.0;
  const glm::vec4 r(rest, 1.0f);
  for (std::size_t f = 0; f < skin.size() && f < trajectory.size(); ++f) {
    glm::dvec3 col[4];
    for (std::size_t k = 0; k < m; ++k) col[k] = glm::dvec3(glm::vec3(skin[f][candidates[k]] * r));
    const glm::dvec3 y(trajectory[f]);
    yy += glm::dot(y, y);
    for (std::size_t k = 0; k < m; ++k) {
      h(static_cast<Eigen::Index>(k)) += glm::dot(col[k], y);
      for (std::size_t l = 0; l < m; ++l) G(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(l)) += glm::dot(col[k], col[l]);
    }
  }
  std::array<float, 4> best{0.0f, 0.0f, 0.0f, 0.0f};
  double best_cost = std::numeric_limits<double>::infinity();
  for (unsigned mask = 1; mask < (1u << m); ++mask) {
    std::vector<int> idx;
    for (std::size_t k = 0; k < m; ++k)
      if (mask & (1u << k)) idx.push_back(static_cast<int>(k));
    const int s = static_cast<int>(idx.size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(s + 1, s + 1);
    Eigen::VectorXd rhs(s + 1);
    for (int a = 0; a < s; ++a) {
      for (int b = 0; b < s; ++b) K(a, b) = G(idx[a], idx[b]);
      K(a, s) = K(s, a) = 1.0;
      rhs(a) = h(idx[a]);
    }
    rhs(s) = 1.0;
    const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
    if (!sol.allFinite()) continue;
    bool feasible = true;
    Eigen::Vector4d w = Eigen::Vector4d::Zero();
    for (int a = 0; a < s; ++a) {
      if (sol(a) < -1e-9) feasible = false;
      w(idx[a]) = std::max(0.0, sol(a));
    }
    if (!feasible) continue;
    w /= w.sum();
    const double cost = w.dot(G * w) - 2.0 * h.dot(w) + yy;
    if (cost < best_cost) {
      best_cost = cost;
      for (std::size_t k = 0; k < m; ++k) best[k] = static_cast<float>(w(static_cast<Eigen::Index>(k)));
    }
  }
  if (!(best_cost < std::numeric_limits<double>::infinity())) best[0] = 1.0f;
  return best;
}

Compression compress_animation(const std::vector<std::vector<glm::vec3>>& frames,
                               const std::vector<std::vector<glm::vec3>>& skeleton_points, SdfBackend& backend,
                               const CompressionOptions& options) {
  if (options.bones < 4 || options.bones > 255) throw InputError("--bones must be in [4, 255]");
  if (!(options.frame_time > 0.0) || !std::isfinite(options.frame_time))
    throw InputError("--frame-time must be a positive number of seconds");
  if (frames.size() < 2) throw InputError("an animation needs at least 2 frames");
  if (skeleton_points.size() != frames.size()) throw InputError("one skeleton cloud per frame is needed");
  const std::size_t V = frames[0].size(), F = frames.size(), B = static_cast<std::size_t>(options.bones);
  for (const auto& f : frames)
    if (f.size() != V) throw InputError("every frame must have the same number of points (" + std::to_string(V) + ")");
  using Clock = std::chrono::steady_clock;
  Compression out;
  auto t0 = Clock::now();
  // Matched skeletons: the same end first in every frame, N + 1 nodes equally spaced.
  SkeletonOptions so = options.skeleton;
  so.segments = std::max(options.bones, 12);
  const SequenceSkeleton seq = skeleton_sequence(skeleton_points, backend, so, options.bones + 1);
  out.bones_per_frame = seq.subdivided;
  out.skeleton_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  t0 = Clock::now();
  const auto& bones = out.bones_per_frame;

  SkinnedAnimation& anim = out.animation;
  anim.frame_time = options.frame_time;
  anim.rest = frames[0];
  // Each particle's nearest bones at rest.
  std::vector<std::array<std::uint8_t, 4>> nearest(V);
  std::vector<std::vector<std::uint32_t>> owned(B);
  for (std::size_t i = 0; i < V; ++i) {
    std::vector<std::pair<float, std::uint8_t>> d(B);
    for (std::size_t b = 0; b < B; ++b)
      d[b] = {segment_distance(anim.rest[i], bones[0].nodes[b].position, bones[0].nodes[b + 1].position),
              static_cast<std::uint8_t>(b)};
    std::partial_sort(d.begin(), d.begin() + 4, d.end());
    for (int k = 0; k < 4; ++k) nearest[i][k] = d[k].second;
    owned[d[0].second].push_back(static_cast<std::uint32_t>(i));
  }
  // Rest frames of the bones: x along the segment, y from the world's y made perpendicular.
  std::vector<glm::quat> rest_rotation(B);
  std::vector<glm::vec3> rest_axis(B);
  for (std::size_t b = 0; b < B; ++b) {
    glm::vec3 x = bones[0].nodes[b + 1].position - bones[0].nodes[b].position;
    x = glm::length(x) > 0.0f ? glm::normalize(x) : glm::vec3(1, 0, 0);
    glm::vec3 y = glm::vec3(0, 1, 0) - x * x.y;
    if (glm::length(y) < 1e-3f) y = glm::vec3(0, 0, 1) - x * x.z;
    y = glm::normalize(y);
    rest_axis[b] = x;
    rest_rotation[b] = glm::quat_cast(glm::mat3(x, y, glm::cross(x, y)));
  }
  // Per frame and bone: rotation = twist about the current segment * the shortest rotation of
  // the rest segment onto it; translation = least squares given the rotation.
  anim.poses.assign(F, std::vector<BonePose>(B));
  std::vector<std::vector<glm::mat4>> skin(F, std::vector<glm::mat4>(B));
  anim.inverse_bind.resize(B);
  parallel_for(F, [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec3> from, to;
    for (std::size_t f = begin; f < end; ++f)
      for (std::size_t b = 0; b < B; ++b) {
        glm::vec3 axis = bones[f].nodes[b + 1].position - bones[f].nodes[b].position;
        axis = glm::length(axis) > 0.0f ? glm::normalize(axis) : rest_axis[b];
        const glm::quat bend = rotation_between(rest_axis[b], axis);
        glm::quat rel = bend;
        glm::vec3 c0(0.0f), cf(0.0f);
        const auto& own = owned[b];
        if (!own.empty()) {
          for (std::uint32_t i : own) {
            c0 += anim.rest[i];
            cf += frames[f][i];
          }
          c0 /= static_cast<float>(own.size());
          cf /= static_cast<float>(own.size());
          from.clear();
          to.clear();
          for (std::uint32_t i : own) {
            from.push_back(bend * (anim.rest[i] - c0));
            to.push_back(frames[f][i] - cf);
          }
          if (options.rotation == CompressionOptions::Rotation::Procrustes && own.size() >= 3) {
            // Kabsch on the bone's particles: R = V diag(1, 1, det) U^T of sum from to^T.
            Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
            for (std::uint32_t i : own) {
              const glm::vec3 x = anim.rest[i] - c0, y = frames[f][i] - cf;
              H += Eigen::Vector3d(x.x, x.y, x.z) * Eigen::Vector3d(y.x, y.y, y.z).transpose();
            }
            Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
            Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
            D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
            const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
            glm::mat3 m;
            for (int r = 0; r < 3; ++r)
              for (int cc = 0; cc < 3; ++cc) m[cc][r] = static_cast<float>(R(r, cc));
            rel = glm::normalize(glm::quat_cast(m));
          } else {
            rel = glm::angleAxis(fit_twist(axis, from, to), axis) * bend;
          }
        } else {
          c0 = bones[0].nodes[b].position;
          cf = bones[f].nodes[b].position;
        }
        // S(p) = rel * p + d with d = cf - rel * c0; the joint's world = S * rest world.
        const glm::vec3 d = cf - rel * c0;
        BonePose& pose = anim.poses[f][b];
        pose.rotation = glm::normalize(rel * rest_rotation[b]);
        pose.translation = rel * bones[0].nodes[b].position + d;
      }
  }, 4);
  for (std::size_t b = 0; b < B; ++b) {
    // Keep consecutive keyframes' quaternions on the same hemisphere (interpolation).
    for (std::size_t f = 1; f < F; ++f)
      if (glm::dot(anim.poses[f][b].rotation, anim.poses[f - 1][b].rotation) < 0.0f)
        anim.poses[f][b].rotation = -anim.poses[f][b].rotation;
    anim.inverse_bind[b] = glm::inverse(pose_matrix(anim.poses[0][b]));
  }
  for (std::size_t f = 0; f < F; ++f)
    for (std::size_t b = 0; b < B; ++b) skin[f][b] = pose_matrix(anim.poses[f][b]) * anim.inverse_bind[b];
  // Weights per particle over all frames.
  anim.joints.resize(V);
  anim.weights.resize(V);
  parallel_for(V, [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec3> traj(F);
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t f = 0; f < F; ++f) traj[f] = frames[f][i];
      anim.joints[i] = nearest[i];
      anim.weights[i] = fit_weights(skin, anim.rest[i], traj, nearest[i]);
    }
  }, 256);
  out.fit_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return out;
}

CompressionReport measure_compression(const std::vector<std::vector<glm::vec3>>& original,
                                      const std::vector<std::vector<glm::vec3>>& played, std::size_t glb_bytes,
                                      std::size_t bones, double body_length) {
  if (original.size() != played.size() || original.empty() || original[0].size() != played[0].size())
    throw InputError("the played-back animation has " + std::to_string(played.size()) + " frames of " +
                     std::to_string(played.empty() ? 0 : played[0].size()) + " points; the original " +
                     std::to_string(original.size()) + " of " + std::to_string(original.empty() ? 0 : original[0].size()));
  CompressionReport r;
  r.frames = original.size();
  r.points = original[0].size();
  r.bones = bones;
  r.raw_bytes = r.frames * r.points * 3 * sizeof(float);
  r.compressed_bytes = glb_bytes;
  r.ratio = glb_bytes > 0 ? static_cast<double>(r.raw_bytes) / static_cast<double>(glb_bytes) : 0.0;
  r.body_length = body_length;
  double se = 0.0, spread = 0.0;
  for (std::size_t f = 0; f < r.frames; ++f) {
    glm::dvec3 mean(0.0);
    for (const glm::vec3& p : original[f]) mean += glm::dvec3(p);
    mean /= static_cast<double>(r.points);
    for (std::size_t i = 0; i < r.points; ++i) {
      const glm::dvec3 d = glm::dvec3(original[f][i]) - glm::dvec3(played[f][i]);
      const double e2 = glm::dot(d, d);
      se += e2;
      r.max_error = std::max(r.max_error, std::sqrt(e2));
      const glm::dvec3 c = glm::dvec3(original[f][i]) - mean;
      spread += glm::dot(c, c);
    }
  }
  r.rmse = std::sqrt(se / static_cast<double>(r.frames * r.points));
  r.rmse_percent = body_length > 0.0 ? 100.0 * r.rmse / body_length : 0.0;
  r.max_percent = body_length > 0.0 ? 100.0 * r.max_error / body_length : 0.0;
  r.kg_error = spread > 0.0 ? 100.0 * std::sqrt(se) / std::sqrt(spread) : 0.0;
  return r;
}

}  // namespace sdfkit::pointcloud
