// Welding by grid hashing: the default tolerance, agreement with the definition (greedy in input
// order, checked by brute force), and a large shuffled cloud whose answer is known, so the
// parallel path is exercised.
#include "sdfkit/core/weld.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

using namespace sdfkit;

namespace {

// The definition, O(n^2): vertex i joins the earliest earlier welded vertex within tol.
std::vector<std::uint32_t> brute_force_reps(const std::vector<glm::vec3>& p, float tol) {
  std::vector<std::uint32_t> rep(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    rep[i] = static_cast<std::uint32_t>(i);
    for (std::size_t j = 0; j < i; ++j) {
      const glm::vec3 d = p[i] - p[j];
      const bool close = tol > 0.0f ? glm::dot(d, d) <= tol * tol : p[i] == p[j];
      if (rep[j] == j && close) {
        rep[i] = static_cast<std::uint32_t>(j);
        break;
      }
    }
  }
  return rep;
}

}  // namespace

TEST(Weld, DefaultToleranceIsAMillionthOfTheBoxOrTheCoordinates) {
  const std::vector<glm::vec3> unit = {{0, 0, 0}, {3, 4, 0}};
  EXPECT_FLOAT_EQ(default_weld_tolerance(unit), 5e-6f);
  // Far from the origin float rounding grows with the coordinates, and so does the tolerance.
  const std::vector<glm::vec3> far = {{1000, 0, 0}, {1003, 4, 0}};
  EXPECT_FLOAT_EQ(default_weld_tolerance(far), 1003e-6f);
  EXPECT_EQ(default_weld_tolerance({}), 0.0f);
}

TEST(Weld, MatchesTheGreedyDefinitionOnChainsAndClusters) {
  // Points on a line at spacing 0.6 tol (chains: i+1 is within tol of i, i+2 is not) plus
  // random clusters: the greedy order decides, and the hash must find every neighbour cell.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const float tol = 0.01f;
  std::vector<glm::vec3> p;
  for (int i = 0; i < 200; ++i) p.push_back({0.5f + 0.6f * tol * static_cast<float>(i), 0.25f, -0.3f});
  for (int c = 0; c < 300; ++c) {
    const glm::vec3 centre(u(rng), u(rng), u(rng));
    for (int k = 0; k < 4; ++k) p.push_back(centre + glm::vec3(u(rng), u(rng), u(rng)) * (0.7f * tol));
  }
  std::shuffle(p.begin(), p.end(), rng);
  for (float t : {0.0f, tol, 3 * tol}) {
    SCOPED_TRACE(t);
    const WeldResult w = weld(p, {}, t);
    const auto rep = brute_force_reps(p, t);
    std::size_t welded = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      welded += rep[i] == i;
      EXPECT_EQ(w.input_to_welded[i], w.input_to_welded[rep[i]]) << i;
      EXPECT_EQ(w.mesh.positions[w.input_to_welded[i]], p[rep[i]]) << i;
    }
    EXPECT_EQ(w.mesh.positions.size(), welded);
  }
}

TEST(Weld, LargeShuffledCloudWeldsToItsLatticePoints) {
  // 40^3 lattice points 1 apart, each with 3 copies jittered by < tol/2 (so every copy is
  // within tol of its own point and no other), shuffled: 256k vertices, the parallel path.
  const float tol = 1e-3f;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.28f * tol, 0.28f * tol);
  std::vector<glm::vec3> p;
  std::vector<std::uint32_t> lattice;
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 40; ++y)
      for (int z = 0; z < 40; ++z)
        for (int k = 0; k < 4; ++k) {
          p.push_back(glm::vec3(x, y, z) + glm::vec3(u(rng), u(rng), u(rng)));
          lattice.push_back(static_cast<std::uint32_t>((x * 40 + y) * 40 + z));
        }
  std::vector<std::size_t> perm(p.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<glm::vec3> q(p.size());
  std::vector<std::uint32_t> q_lattice(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) q[i] = p[perm[i]], q_lattice[i] = lattice[perm[i]];
  const std::vector<Triangle> tris = {{0, 1, 2}, {3, 4, 5}};
  const WeldResult w = weld(q, tris, tol);
  ASSERT_EQ(w.mesh.positions.size(), 40u * 40u * 40u);
  // Same lattice point <=> same welded vertex; welded vertices numbered in input order.
  std::vector<std::uint32_t> of_lattice(64000, UINT32_MAX);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    std::uint32_t& w_of = of_lattice[q_lattice[i]];
    if (w_of == UINT32_MAX) {
      ASSERT_EQ(w.input_to_welded[i], next++) << i;
      w_of = w.input_to_welded[i];
      EXPECT_EQ(w.mesh.positions[w_of], q[i]);
    }
    ASSERT_EQ(w.input_to_welded[i], w_of) << i;
  }
  for (std::size_t f = 0; f < tris.size(); ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(w.mesh.triangles[f][k], w.input_to_welded[tris[f][k]]);
}

TEST(Weld, HugeAndTinyTolerancesStayCorrect) {
  // Cell coordinates far beyond 64 bits are clamped: matches are still decided by distance.
  const std::vector<glm::vec3> p = {{0, 0, 0}, {1e30f, 0, 0}, {1e30f, 0, 0}, {-1e-30f, 0, 0}, {1, 1, 1}};
  EXPECT_EQ(weld(p, {}, 1e-38f).mesh.positions.size(), 4u);
  EXPECT_EQ(weld(p, {}, 1e31f).mesh.positions.size(), 1u);
}

TEST(Weld, ManyCopiesOfOnePointWeldToTheFirst) {
  // 200k copies (a degenerate export): every lookup stops at the first copy, so this is linear
  // (quadratic would be 2e10 steps, far past the test's timeout).
  std::vector<glm::vec3> p(200000, glm::vec3(0.5f, -0.25f, 2.0f));
  p.push_back({1, 1, 1});
  p.insert(p.begin() + 7, glm::vec3(0.5f, -0.25f, 2.0f + 5e-7f));
  for (float tol : {0.0f, 1e-6f}) {
    const WeldResult w = weld(p, {}, tol);
    EXPECT_EQ(w.mesh.positions.size(), tol > 0 ? 2u : 3u);
    EXPECT_EQ(w.input_to_welded[199999], 0u);
    EXPECT_EQ(w.input_to_welded[7], tol > 0 ? 0u : 1u);
  }
}

TEST(Weld, NothingMergesGivesTheInputAndTheIdentityMap) {
  // 48^3 lattice points 1 apart, shuffled (the parallel path): with a tolerance of 0.3 every
  // grid cell (16 tolerances) holds ~100 candidates, none close enough (the chains answer);
  // with 0.05 most cells hold one (the table answers); 0 compares bits. Nothing merges, and
  // the input comes back as it is; one copy appended then welds through the general path and
  // leaves every other vertex's number unchanged.
  std::mt19937 rng(5);
  std::vector<glm::vec3> p;
  for (int x = 0; x < 48; ++x)
    for (int y = 0; y < 48; ++y)
      for (int z = 0; z < 48; ++z) p.push_back(glm::vec3(x, y, z) * 1.0f - 20.0f);
  std::shuffle(p.begin(), p.end(), rng);
  const auto n = static_cast<std::uint32_t>(p.size());
  const std::vector<Triangle> tris = {{0, 1, 2}, {n - 1, 5, n + 7}};  // n + 7: out of range, copied
  for (float tol : {0.3f, 0.05f, 0.0f}) {
    SCOPED_TRACE(tol);
    const WeldResult w = weld(p, tris, tol);
    ASSERT_EQ(w.mesh.positions.size(), p.size());
    for (std::uint32_t i = 0; i < n; ++i) {
      ASSERT_EQ(w.input_to_welded[i], i);
      ASSERT_EQ(w.mesh.positions[i], p[i]);
    }
    ASSERT_EQ(w.mesh.triangles.size(), tris.size());
    for (std::size_t f = 0; f < tris.size(); ++f) EXPECT_EQ(w.mesh.triangles[f], tris[f]);

    std::vector<glm::vec3> q = p;
    q.push_back(p[1234] + glm::vec3(0.25f * tol, 0.0f, 0.0f));
    const WeldResult m = weld(q, tris, tol);
    ASSERT_EQ(m.mesh.positions.size(), p.size());
    EXPECT_EQ(m.input_to_welded[n], 1234u);
    for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(m.input_to_welded[i], i);
    EXPECT_EQ(m.mesh.triangles[1], (Triangle{n - 1, 5, n + 7}));  // n + 7 is still out of range
  }
}
