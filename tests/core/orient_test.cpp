// Face orientation (orient_outward): mixed windings made coherent, inside-out solids turned,
// cavities and embedded parts kept, open pieces by their majority, one-sided surfaces left alone.
// Every case starts from a mesh whose right winding is known and checks the faces one by one.
#include "sdfkit/core/orient.hpp"
#include "sdfkit/core/shapes.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace sdfkit;

namespace {

void flip(Triangle& t) { std::swap(t[1], t[2]); }

// Flips each face with probability 1/2 (fixed seed); returns how many.
std::size_t scramble(Mesh& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::size_t n = 0;
  for (Triangle& t : m.triangles)
    if (rng() & 1u) flip(t), ++n;
  return n;
}

double signed_volume(const Mesh& m) {
  double v = 0;
  for (const Triangle& t : m.triangles)
    v += glm::dot(glm::dvec3(m.positions[t[0]]), glm::cross(glm::dvec3(m.positions[t[1]]), glm::dvec3(m.positions[t[2]]))) / 6.0;
  return v;
}

// `b` appended to `a` (indices shifted).
Mesh join(Mesh a, const Mesh& b) {
  const auto base = static_cast<std::uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (Triangle t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

Mesh inverted(Mesh m) {
  for (Triangle& t : m.triangles) flip(t);
  return m;
}

}  // namespace

TEST(Orient, MixedWindingsOfAClosedSolidAreUndoneFaceByFace) {
  for (const Mesh& good : {shapes::icosphere(1.0f, 3), shapes::torus(2.0f, 0.6f, 48, 24), shapes::capsule(0.5f, 3.0f, 32, 12)}) {
    ASSERT_GT(signed_volume(good), 0.0);
    for (unsigned seed : {1u, 2u, 3u}) {
      Mesh m = good;
      const std::size_t scrambled = scramble(m, seed);
      ASSERT_GT(scrambled, m.triangles.size() / 4);
      const OrientReport r = orient_outward(m);
      EXPECT_EQ(m.triangles, good.triangles) << "seed " << seed;
      EXPECT_EQ(r.flipped_faces, scrambled);
      EXPECT_EQ(r.incoherent_pieces, 1u);
      EXPECT_EQ(r.pieces, 1u);
      EXPECT_NE(r.summary().find("mixed windings"), std::string::npos) << r.summary();
    }
    // A coherent, outward mesh is left as it is, and says nothing.
    Mesh same = good;
    const OrientReport r = orient_outward(same);
    EXPECT_EQ(same.triangles, good.triangles);
    EXPECT_EQ(r.flipped_faces, 0u);
    EXPECT_TRUE(r.summary().empty());
  }
}

// Over 2^17 vertices the walk around the vertices runs in parts on the cores (one part per 2^16
// vertices at most); the joins are made afterwards in one walk's order, so the result is the
// same: scrambled windings undone, an inside-out piece turned, face by face.
TEST(Orient, AMeshWalkedInPartsIsOrientedFaceByFace) {
  const Mesh sphere = shapes::icosphere(1.0f, 7);  // 163842 vertices
  ASSERT_GE(sphere.positions.size(), std::size_t{1} << 17);
  Mesh torus = shapes::torus(2.0f, 0.5f, 64, 32);
  for (glm::vec3& p : torus.positions) p.x += 10.0f;
  const Mesh good = join(sphere, torus);
  Mesh m = good;
  const std::size_t scrambled = scramble(m, 7u);
  for (std::size_t f = sphere.triangles.size(); f < m.triangles.size(); ++f) flip(m.triangles[f]);
  std::size_t flipped = 0;  // the faces that now differ from the good winding
  for (std::size_t f = 0; f < m.triangles.size(); ++f) flipped += m.triangles[f] != good.triangles[f];
  ASSERT_GT(scrambled, sphere.triangles.size() / 4);
  const OrientReport r = orient_outward(m);
  EXPECT_EQ(m.triangles, good.triangles);
  EXPECT_EQ(r.flipped_faces, flipped);
  EXPECT_EQ(r.pieces, 2u);
}

TEST(Orient, AnInsideOutSolidIsTurnedAndASecondOneIsNotTouched) {
  const Mesh a = shapes::icosphere(1.0f, 3);
  Mesh b = shapes::torus(2.0f, 0.5f, 32, 16);
  for (glm::vec3& p : b.positions) p.x += 10.0f;  // apart from the sphere
  Mesh m = join(inverted(a), b);
  const OrientReport r = orient_outward(m);
  EXPECT_EQ(m.triangles, join(a, b).triangles);
  EXPECT_EQ(r.pieces, 2u);
  EXPECT_EQ(r.inverted_pieces, 1u);
  EXPECT_EQ(r.flipped_faces, a.triangles.size());
  EXPECT_GT(signed_volume(m), 0.0);
}

TEST(Orient, ACavityIsKeptAndAScrambledCavityIsWoundAsOne) {
  // A hollow ball: the outer shell outward, the inner one wound inward (it bounds the cavity).
  const Mesh outer = shapes::icosphere(2.0f, 3);
  Mesh inner = shapes::icosphere(1.0f, 2);
  const Mesh hollow = join(outer, inverted(inner));
  Mesh m = hollow;
  OrientReport r = orient_outward(m);
  EXPECT_EQ(m.triangles, hollow.triangles);
  EXPECT_EQ(r.flipped_faces, 0u);
  // Inner shell's windings mixed: made coherent as a cavity (its nesting depth is 1).
  Mesh scrambled_inner = inverted(inner);
  scramble(scrambled_inner, 7);
  m = join(outer, scrambled_inner);
  r = orient_outward(m);
  EXPECT_EQ(m.triangles, hollow.triangles);
  EXPECT_EQ(r.incoherent_pieces, 1u);
  // The whole hollow ball inside out: the outer shell (inside nothing) is turned; the inner
  // shell, now wound outward inside another piece, is an embedded part as far as anyone can tell
  // and keeps its winding.
  m = join(inverted(outer), inner);
  r = orient_outward(m);
  EXPECT_EQ(m.triangles, join(outer, inner).triangles);
  EXPECT_EQ(r.inverted_pieces, 1u);
  // An embedded part wound outward (an eye in a head) is kept.
  m = join(outer, inner);
  EXPECT_EQ(orient_outward(m).flipped_faces, 0u);
}

TEST(Orient, AnOpenPieceTakesTheWindingOfMostOfItsArea) {
  // A capsule cut open: its faces with z < 1 (one cap and part of the tube stay).
  const Mesh capsule = shapes::capsule(0.5f, 3.0f, 32, 12);
  Mesh open;
  open.positions = capsule.positions;
  for (const Triangle& t : capsule.triangles)
    if (capsule.positions[t[0]].z < 1.0f && capsule.positions[t[1]].z < 1.0f && capsule.positions[t[2]].z < 1.0f)
      open.triangles.push_back(t);
  ASSERT_GT(open.triangles.size(), 100u);
  ASSERT_LT(open.triangles.size(), capsule.triangles.size());
  // A minority of faces flipped: undone.
  Mesh m = open;
  std::size_t flipped = 0;
  for (std::size_t f = 0; f < m.triangles.size(); f += 5) flip(m.triangles[f]), ++flipped;
  OrientReport r = orient_outward(m);
  EXPECT_EQ(m.triangles, open.triangles);
  EXPECT_EQ(r.flipped_faces, flipped);
  // Wound inward throughout: an open surface has no inside to tell it by, so it is kept.
  m = inverted(open);
  r = orient_outward(m);
  EXPECT_EQ(m.triangles, inverted(open).triangles);
  EXPECT_EQ(r.flipped_faces, 0u);
}

TEST(Orient, AMoebiusStripIsLeftAsGiven) {
  Mesh m;
  constexpr int n = 40;
  for (int i = 0; i < n; ++i) {
    const double u = 6.283185307179586 * i / n;
    for (const double w : {-0.3, 0.3}) {
      const double r = 1.0 + w * std::cos(u / 2);
      m.positions.push_back(glm::vec3(static_cast<float>(r * std::cos(u)), static_cast<float>(r * std::sin(u)),
                                      static_cast<float>(w * std::sin(u / 2))));
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t a = 2 * i, b = 2 * i + 1;
    // The strip closes with a half twist: the last column joins the first one swapped.
    const std::uint32_t c = i + 1 < n ? 2 * (i + 1) : 1, d = i + 1 < n ? 2 * (i + 1) + 1 : 0;
    m.triangles.push_back({a, c, b});
    m.triangles.push_back({b, c, d});
  }
  const Mesh given = m;
  const OrientReport r = orient_outward(m);
  EXPECT_EQ(r.non_orientable_pieces, 1u);
  EXPECT_EQ(r.flipped_faces, 0u);
  EXPECT_EQ(m.triangles, given.triangles);
  EXPECT_NE(r.summary().find("cannot be oriented"), std::string::npos) << r.summary();
}

TEST(Orient, DegenerateFacesAreLeftAloneAndConnectNothing) {
  const Mesh good = shapes::icosphere(1.0f, 2);
  Mesh m = inverted(good);
  m.triangles.push_back({0, 0, 1});
  m.triangles.push_back({2, 2, 2});
  const OrientReport r = orient_outward(m);
  EXPECT_EQ(r.flipped_faces, good.triangles.size());
  EXPECT_EQ(m.triangles.back(), (Triangle{2, 2, 2}));
  EXPECT_EQ(m.triangles[m.triangles.size() - 2], (Triangle{0, 0, 1}));
  EXPECT_GT(signed_volume(m), 0.0);
}
