// Internals of the skeleton library held to independent computations: the BVH against brute
// force, the cotangent Laplacian against its definition.

#include "bvh.hpp"
#include "laplacian.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/weld.hpp"
#include "sdfkit/skeleton/skeleton.hpp"
#include "sdfkit/skeleton/models.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace sdfkit;
namespace detail = sdfkit::skeleton::detail;

namespace {

// Brute-force closest hit along a ray (Möller-Trumbore in double).
float brute_closest(const Mesh& m, const glm::vec3& o, const glm::vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles) {
    const glm::dvec3 a(m.positions[t[0]]), b(m.positions[t[1]]), c(m.positions[t[2]]);
    const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(glm::dvec3(d), e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) continue;
    const glm::dvec3 s = glm::dvec3(o) - a;
    const double u = glm::dot(s, p) / det;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(glm::dvec3(d), q) / det;
    const double tt = glm::dot(e2, q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && tt > 0 && tt < best) best = tt;
  }
  return static_cast<float>(best);
}

}  // namespace

TEST(SkeletonBvh, ClosestHitMatchesBruteForce) {
  const auto plate = skeleton::models::c_shape();
  const Mesh& m = plate.mesh;
  const detail::TriangleBvh bvh(m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> box(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 o(0.8f * box(rng), 0.8f * box(rng), 1.6f * box(rng));
    const glm::vec3 d = glm::normalize(glm::vec3(box(rng), box(rng), box(rng)));
    const float expected = brute_closest(m, o, d);
    const auto h = bvh.closest(o, d, 0.0f, 100.0f);
    if (!std::isfinite(expected)) {
      EXPECT_FALSE(h.found);
      continue;
    }
    ++hits;
    ASSERT_TRUE(h.found) << i;
    EXPECT_NEAR(h.t, expected, 1e-4f) << i;
  }
  EXPECT_GT(hits, 100);
}

TEST(SkeletonBvh, InsideAgreesWithTheImplicitTorus) {
  const Mesh m = shapes::torus(2.0f, 0.6f, 64, 24);
  const detail::TriangleBvh bvh(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> box(-3.0f, 3.0f);
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 p(box(rng), box(rng), 0.3f * box(rng));
    const float f = shapes::torus_sdf(p, 2.0f, 0.6f);
    if (std::abs(f) < 0.05f) continue;  // the tessellation differs from the ideal surface
    EXPECT_EQ(bvh.inside(p), f < 0.0f) << p.x << ' ' << p.y << ' ' << p.z;
  }
}

namespace {

// A closed box of side `size` centred at `centre` (welded), wound outward or, with `inward`,
// inside out (the wall of a cavity).
Mesh closed_box(float size, const glm::vec3& centre, bool inward = false) {
  Mesh m = shapes::box(size, size, size, 2);
  for (glm::vec3& p : m.positions) p += centre;
  if (inward)
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return weld(m.positions, m.triangles, 1e-6f).mesh;
}

Mesh joined(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  const auto offset = static_cast<std::uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  for (const Triangle& t : b.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return m;
}

}  // namespace

// The solid of a mesh of closed pieces is where the winding number is not 0: two boxes that
// overlap are one solid (the overlap is inside, though a ray from it crosses the surface an even
// number of times), a box wound inward inside another is a cavity (outside), and a segment
// leaves the solid only where the winding number falls to 0 along it.
TEST(SkeletonBvh, TheSolidIsTheUnionOfOverlappingPiecesWithoutItsCavities) {
  {
    const Mesh m = joined(closed_box(2.0f, glm::vec3(0.0f)), closed_box(2.0f, glm::vec3(1.0f, 0.1f, 0.2f)));
    const detail::TriangleBvh bvh(m);
    EXPECT_TRUE(bvh.inside(glm::vec3(0.5f, 0.3f, 0.4f)));  // in both boxes (parity: outside)
    EXPECT_TRUE(bvh.inside(glm::vec3(-0.5f, 0.0f, 0.0f)));
    EXPECT_TRUE(bvh.inside(glm::vec3(1.7f, 0.3f, 0.4f)));
    EXPECT_FALSE(bvh.inside(glm::vec3(3.0f, 0.0f, 0.0f)));
    const glm::vec3 a(-0.7f, 0.3f, 0.4f), b(1.8f, 0.3f, 0.4f);
    EXPECT_TRUE(bvh.segment_blocked(a, b));   // it crosses both boxes' walls...
    EXPECT_FALSE(bvh.segment_leaves(a, b));   // ...without leaving their union
    EXPECT_FALSE(bvh.segment_leaves(b, a));
    EXPECT_TRUE(bvh.segment_leaves(a, glm::vec3(3.0f, 0.3f, 0.4f)));
    // Each piece is a component named by its lowest vertex; a segment tested against one
    // piece's faces only is not blocked by the other's walls.
    const auto& component = bvh.component();
    const std::uint32_t first = component.front(), second = component.back();
    EXPECT_EQ(first, 0u);
    EXPECT_NE(second, first);
    EXPECT_EQ(std::count(component.begin(), component.end(), first), static_cast<long>(m.positions.size() / 2));
    const glm::vec3 in_first(-0.5f, 0.3f, 0.4f), in_overlap(0.5f, 0.3f, 0.4f);
    EXPECT_TRUE(bvh.segment_blocked(in_first, in_overlap));
    EXPECT_FALSE(bvh.segment_blocked(in_first, in_overlap, UINT32_MAX, first));
    EXPECT_TRUE(bvh.segment_blocked(in_first, in_overlap, UINT32_MAX, second));
  }
  {
    const Mesh m = joined(closed_box(2.0f, glm::vec3(5.0f, 0.0f, 0.0f)), closed_box(2.0f, glm::vec3(0.0f)));
    const detail::TriangleBvh bvh(m);
    EXPECT_TRUE(bvh.segment_leaves(glm::vec3(0.0f), glm::vec3(5.0f, 0.0f, 0.0f)));  // two apart
  }
  {
    const Mesh m = joined(closed_box(4.0f, glm::vec3(0.0f)), closed_box(2.0f, glm::vec3(0.0f), true));
    const detail::TriangleBvh bvh(m);
    EXPECT_FALSE(bvh.inside(glm::vec3(0.1f, 0.2f, 0.3f)));  // the cavity
    EXPECT_TRUE(bvh.inside(glm::vec3(1.5f, 0.2f, 0.3f)));   // the wall
    EXPECT_TRUE(bvh.segment_leaves(glm::vec3(1.5f, 0.2f, 0.3f), glm::vec3(-1.5f, 0.2f, 0.3f)));
    EXPECT_FALSE(bvh.segment_leaves(glm::vec3(1.5f, 0.2f, 0.3f), glm::vec3(1.5f, -1.5f, 0.3f)));
  }
}

TEST(SkeletonLaplacian, SymmetricNonNegativeWeightsRowsSumToZero) {
  const Mesh m = skeleton::models::five_armed_star().mesh;  // marching-tetrahedra slivers
  const Eigen::SparseMatrix<double> L = detail::cotangent_laplacian(m);
  const Eigen::SparseMatrix<double> Lt = L.transpose();
  EXPECT_NEAR((L - Lt).norm(), 0.0, 1e-9 * L.norm());
  Eigen::VectorXd ones = Eigen::VectorXd::Ones(L.cols());
  EXPECT_LT((L * ones).cwiseAbs().maxCoeff(), 1e-9 * L.norm());
  for (Eigen::Index c = 0; c < L.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, c); it; ++it) {
      ASSERT_TRUE(std::isfinite(it.value()));
      if (it.row() != it.col()) {
        EXPECT_GE(it.value(), 0.0);
      }
      EXPECT_LE(std::abs(it.value()), 2 * 6 * detail::kMaxCotangent * 20);
    }
}

TEST(SkeletonLaplacian, FlatGridIsHarmonicAndASpherePointsInward) {
  // A planar box face: L V vanishes at vertices inside a flat face (cot weights reproduce
  // linear functions), and on a sphere L V points along the inward normal.
  const Mesh box = shapes::box(2.0f, 2.0f, 2.0f, 6);
  const Eigen::SparseMatrix<double> L = detail::cotangent_laplacian(box);
  Eigen::MatrixXd V(box.positions.size(), 3);
  for (std::size_t i = 0; i < box.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) V(static_cast<Eigen::Index>(i), k) = box.positions[i][k];
  const Eigen::MatrixXd LV = L * V;
  int interior = 0;
  for (std::size_t i = 0; i < box.positions.size(); ++i) {
    const glm::vec3 p = glm::abs(box.positions[i]);
    const int on_faces = (p.x > 0.999f) + (p.y > 0.999f) + (p.z > 0.999f);
    if (on_faces != 1) continue;
    ++interior;
    EXPECT_LT(LV.row(static_cast<Eigen::Index>(i)).norm(), 1e-5);
  }
  EXPECT_GT(interior, 50);

  const Mesh sphere = shapes::icosphere(1.0f, 3);
  const Eigen::SparseMatrix<double> Ls = detail::cotangent_laplacian(sphere);
  for (std::size_t i = 0; i < sphere.positions.size(); ++i) {
    glm::dvec3 lv(0.0);
    for (Eigen::SparseMatrix<double>::InnerIterator it(Ls, static_cast<Eigen::Index>(i)); it; ++it)
      lv += it.value() * glm::dvec3(sphere.positions[static_cast<std::size_t>(it.row())]);
    EXPECT_LT(glm::dot(lv, glm::dvec3(sphere.positions[i])), 0.0);
  }
}

TEST(SkeletonContraction, PlainAuContractionShrinksWithoutNaN) {
  const Mesh capsule = shapes::capsule(0.5f, 3.0f, 16, 12);
  skeleton::ContractionOptions o;
  const auto r = skeleton::contract(capsule, nullptr, o);
  EXPECT_GE(r.iterations, 1);
  EXPECT_LE(r.iterations, o.max_iterations);
  EXPECT_LT(r.area_ratio, 0.01);
  EXPECT_TRUE(r.first_sdf.empty());
  EXPECT_EQ(r.contracted.triangles, capsule.triangles);
  for (const glm::vec3& p : r.contracted.positions) {
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    EXPECT_LT(std::hypot(p.x, p.y), 0.1f);  // on the axis
    EXPECT_LT(std::abs(p.z), 2.1f);
  }
}

TEST(SkeletonContraction, IterationCapAndBadOptions) {
  const Mesh capsule = shapes::capsule(0.5f, 3.0f, 16, 12);
  skeleton::ContractionOptions o;
  o.max_iterations = 1;
  const auto r = skeleton::contract(capsule, nullptr, o);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.stop_reason, "iteration cap");
  ASSERT_EQ(r.warnings.size(), 1u);
  using Edit = void (*)(skeleton::ContractionOptions&);
  for (Edit bad : {+[](skeleton::ContractionOptions& x) { x.wl_scale = 0; },
                   +[](skeleton::ContractionOptions& x) { x.sl = 0.5; },
                   +[](skeleton::ContractionOptions& x) { x.max_iterations = 0; },
                   +[](skeleton::ContractionOptions& x) { x.wc = -1; }}) {
    skeleton::ContractionOptions b;
    bad(b);
    EXPECT_THROW(skeleton::contract(capsule, nullptr, b), InputError);
  }
}

TEST(SkeletonWithoutSdf, CapsuleGivesAPathOnItsAxis) {
  // No backend: plain Au contraction, centre points from one inward ray, radii from distances.
  const Mesh capsule = shapes::capsule(0.5f, 4.0f, 24, 24);
  const skeleton::Skeleton s = skeleton::extract(capsule, nullptr, {}, {});
  ASSERT_GE(s.nodes.size(), 2u);
  EXPECT_EQ(s.edges.size(), s.nodes.size() - 1);
  EXPECT_EQ(skeleton::cycle_count(s), 0);
  std::size_t vertices = 0;
  for (const skeleton::Node& n : s.nodes) {
    vertices += n.vertices.size();
    EXPECT_LT(std::hypot(n.position.x, n.position.y), 0.1f);
    EXPECT_GT(n.radius, 0.2f);
    EXPECT_LT(n.radius, 0.8f);
  }
  EXPECT_EQ(vertices, capsule.positions.size());
  EXPECT_DOUBLE_EQ(s.reliability, 1.0);
}
