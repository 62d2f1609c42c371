// The skinning fit without a device: the twist and the weights recover known values, the glb
// is played back exactly as the skinning it encodes, and bad files are clean errors.
#include "scratch.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/skinning.hpp"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace pc = sdfkit::pointcloud;

namespace {
glm::mat4 pose(const glm::quat& q, const glm::vec3& t) {
  glm::mat4 m = glm::mat4_cast(q);
  m[3] = glm::vec4(t, 1.0f);
  return m;
}
}  // namespace

TEST(PointcloudSkinning, TwistRecoversAKnownAngle) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1, 2, 3));
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> from, to;
  const glm::quat q = glm::angleAxis(0.7f, axis);
  for (int i = 0; i < 30; ++i) {
    from.push_back({g(rng), g(rng), g(rng)});
    to.push_back(q * from.back() + 0.3f * axis * g(rng));  // moves along the axis do not matter
  }
  EXPECT_NEAR(pc::fit_twist(axis, from, to), 0.7f, 1e-5f);
  EXPECT_NEAR(pc::fit_twist(axis, to, from), -0.7f, 1e-5f);
}

TEST(PointcloudSkinning, WeightsRecoverKnownBlendsAndStayConvex) {
  // Three bones moving rigidly over 20 frames; a point blended 0.2 / 0.5 / 0.3 is recovered,
  // and a point that follows one bone gets weight 1 there.
  std::mt19937 rng(4);
  std::normal_distribution<float> g;
  std::vector<std::vector<glm::mat4>> skin(20, std::vector<glm::mat4>(4));
  for (auto& f : skin)
    for (auto& m : f) m = pose(glm::normalize(glm::quat(1.0f, 0.3f * g(rng), 0.3f * g(rng), 0.3f * g(rng))), {g(rng), g(rng), g(rng)});
  const glm::vec3 rest(0.5f, -1.0f, 2.0f);
  std::vector<glm::vec3> blend(20), rigid(20);
  for (int f = 0; f < 20; ++f) {
    blend[f] = glm::vec3(0.2f * (skin[f][0] * glm::vec4(rest, 1)) + 0.5f * (skin[f][2] * glm::vec4(rest, 1)) +
                         0.3f * (skin[f][3] * glm::vec4(rest, 1)));
    rigid[f] = glm::vec3(skin[f][1] * glm::vec4(rest, 1));
  }
  const std::uint8_t cand[4] = {0, 1, 2, 3};
  const auto w = pc::fit_weights(skin, rest, blend, cand);
  EXPECT_NEAR(w[0], 0.2f, 1e-4f);
  EXPECT_NEAR(w[1], 0.0f, 1e-4f);
  EXPECT_NEAR(w[2], 0.5f, 1e-4f);
  EXPECT_NEAR(w[3], 0.3f, 1e-4f);
  const auto r = pc::fit_weights(skin, rest, rigid, cand);
  EXPECT_NEAR(r[1], 1.0f, 1e-5f);
  // A target outside the bones' convex hull: still non-negative and summing to 1.
  std::vector<glm::vec3> far = blend;
  for (auto& p : far) p = 3.0f * p + glm::vec3(5.0f);
  const auto c = pc::fit_weights(skin, rest, far, cand);
  float sum = 0.0f;
  for (float x : c) {
    EXPECT_GE(x, 0.0f);
    sum += x;
  }
  EXPECT_NEAR(sum, 1.0f, 1e-5f);
}

TEST(PointcloudSkinning, GlbPlaysBackAsItsSkinning) {
  // A hand-made animation: 6 bones, 50 points, 8 frames; the playback of the written file
  // equals sum_k w_k * world(f, j_k) * inverse_bind(j_k) * rest within the file's quantisation.
  std::mt19937 rng(9);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  pc::SkinnedAnimation a;
  a.frame_time = 0.04;
  const std::size_t B = 6, F = 8, V = 50;
  a.poses.assign(F, std::vector<pc::BonePose>(B));
  for (auto& f : a.poses)
    for (auto& p : f) p = {glm::normalize(glm::quat(1.0f, 0.4f * g(rng), 0.4f * g(rng), 0.4f * g(rng))), {g(rng), g(rng), g(rng)}};
  for (std::size_t b = 0; b < B; ++b) a.inverse_bind.push_back(glm::inverse(pose(a.poses[0][b].rotation, a.poses[0][b].translation)));
  for (std::size_t i = 0; i < V; ++i) {
    a.rest.push_back({g(rng), g(rng), g(rng)});
    a.joints.push_back({static_cast<std::uint8_t>(i % B), static_cast<std::uint8_t>((i + 1) % B), static_cast<std::uint8_t>((i + 2) % B),
                        static_cast<std::uint8_t>((i + 3) % B)});
    std::array<float, 4> w{u(rng), u(rng), i % 3 == 0 ? 0.0f : u(rng), 0.0f};
    const float s = w[0] + w[1] + w[2];
    for (float& x : w) x /= s;
    a.weights.push_back(w);
  }
  sdfkit::test::ScratchDir d;
  const std::string path = d.path("a.glb");
  const std::size_t bytes = pc::write_skinned_glb(a, path);
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const auto played = pc::play_skinned_glb(path);
  ASSERT_EQ(played.size(), F);
  double worst = 0.0;
  for (std::size_t f = 0; f < F; ++f)
    for (std::size_t i = 0; i < V; ++i) {
      glm::vec3 p(0.0f);
      for (int k = 0; k < 4; ++k)
        p += a.weights[i][k] * glm::vec3(pose(a.poses[f][a.joints[i][k]].rotation, a.poses[f][a.joints[i][k]].translation) *
                                         a.inverse_bind[a.joints[i][k]] * glm::vec4(a.rest[i], 1.0f));
      worst = std::max<double>(worst, glm::distance(p, played[f][i]));
    }
  // Weights as bytes (1/510 each) and rotations as 16-bit shorts: a small, bounded error.
  EXPECT_LT(worst, 0.05);
  EXPECT_GT(worst, 0.0);  // the file is quantised: this is the file, not the input
  // Frame 0 is the rest pose.
  for (std::size_t i = 0; i < V; ++i) EXPECT_LT(glm::distance(played[0][i], a.rest[i]), 0.02f);
  // The report on the played-back frames: exact inputs give zero error.
  const auto rep = pc::measure_compression(played, played, bytes, B, 10.0);
  EXPECT_EQ(rep.rmse, 0.0);
  EXPECT_EQ(rep.kg_error, 0.0);
  EXPECT_EQ(rep.raw_bytes, F * V * 12);
  EXPECT_NEAR(rep.ratio, static_cast<double>(F * V * 12) / bytes, 1e-12);
  // Files that are not playable glbs.
  std::ofstream(d.path("bad.glb")) << "glTF but not really";
  EXPECT_THROW(pc::play_skinned_glb(d.path("bad.glb")), sdfkit::InputError);
  EXPECT_THROW(pc::play_skinned_glb(d.path("missing.glb")), sdfkit::InputError);
}
